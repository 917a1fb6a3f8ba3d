# Numerical faults under load: 3 × 50 randomised hard scenes (hard_scenes.awk, three fixed seeds:
# wind 0-60 m/s from windicator keys, gusts, presets and expressions; cloth of 0.001-1 kg/m^2 and
# hair; keyframed and rotating pins, parameters and colliders; moving mesh bodies with cloth and
# hair attached to them; self-collision on a third of the cloth) simulated two at a time. Every
# run exits 0 — trouble is recovered (halved substeps, at the smallest one strain limiting) and
# reported in run.json, never a give-up (exit 4), a signal or another code — and no frame
# written holds a NaN or an infinity. GALE_HARD_SEED=N runs one other set. Each scene's largest
# stretch and energy are reported (hard_scenes_report.py).
source "$(dirname "$0")/lib.bash" "$@"

SEEDS=${GALE_HARD_SEED:-20261122 7 8}
COUNT=0
mkdir scenes out
for SEED in $SEEDS; do
    mkdir "scenes.$SEED"
    awk -v seed="$SEED" -v count=50 -v out="scenes.$SEED" -f "$SRC/tests/cli/hard_scenes.awk" ||
        { fail "the scene generator"; finish; }
    for f in "scenes.$SEED"/*.toml; do mv "$f" "scenes/s${SEED}_${f##*/}"; done
    for f in "scenes.$SEED"/*.obj; do [ -e "$f" ] && mv "$f" scenes/; done # moving bodies
    COUNT=$((COUNT + 50))
done
SEED="$SEEDS"
expect_eq "$(ls scenes/*.toml | wc -l)" "$COUNT" "generated scenes"
moving=$(grep -l 'type = "mesh"' scenes/*.toml | wc -l)
attached=$(grep -l '^attach' scenes/*.toml | wc -l)
[ "$moving" -gt 10 ] && [ "$attached" -gt 5 ] || fail "moving bodies in $moving scenes, attachments in $attached"
selfc=$(grep -l '^self_collision = true' scenes/*.toml | wc -l)
[ "$selfc" -gt 10 ] || fail "self-collision in $selfc scenes"

# One run: exit code to NAME.rc, stderr to NAME.err (a signal shows as 128 + its number).
cat > one.sh <<'SH'
name=$(basename "$2" .toml)
"$1" sim "$2" -o "out/$name" > /dev/null 2> "out/$name.err"
echo $? > "out/$name.rc"
SH
start=$(date +%s)
if command -v parallel > /dev/null; then
    parallel -j2 bash one.sh "$GALE" ::: scenes/*.toml
else
    printf '%s\n' scenes/*.toml | xargs -P 2 -n 1 bash one.sh "$GALE"
fi
seconds=$(($(date +%s) - start))

# finite_frame FILE: no NaN or infinity among its coordinates (OBJ text, or the float
# properties of a binary PLY's vertex element).
finite_frame() {
    case $1 in
        *.obj) ! grep -Eiq '^v .*(nan|inf)' "$1" ;;
        *.ply)
            local header n props
            header=$(head -c 4000 "$1" | tr -d '\000' | sed '/^end_header$/q')
            n=$(awk '/^element vertex/ { print $3 }' <<< "$header")
            props=$(awk '/^element vertex/ { v = 1; next } /^element/ { v = 0 } v && /^property float/ { c++ } END { print c + 0 }' <<< "$header")
            [ -n "$n" ] && [ "$props" -gt 0 ] || return 1
            ! od -A n -v -t f4 -j "$(printf '%s\n' "$header" | wc -c)" -N $((4 * n * props)) "$1" | grep -Eiq 'nan|inf' ;;
    esac
}

ok=0 reported=0
for scene in scenes/*.toml; do
    name=$(basename "$scene" .toml)
    rc=$(cat "out/$name.rc" 2> /dev/null || echo missing)
    err=$(cat "out/$name.err" 2> /dev/null)
    case $rc in
        0)
            ok=$((ok + 1))
            expect_match "$(head -c 20 "out/$name/run.json")" '"status": "ok"' "$name: run.json says ok" ;;
        4)
            reported=$((reported + 1))
            fail "$name: exit 4, the run gave up (scene in scenes/$name.toml): $(tail -n 2 <<< "$err")" ;;
        *)
            fail "$name: exit $rc (a crash or an unexpected error; scene in scenes/$name.toml, seed $SEED): $(tail -n 3 <<< "$err")" ;;
    esac
    frames=0
    for f in "out/$name"/*.obj "out/$name"/*.ply; do
        [ -e "$f" ] || continue
        frames=$((frames + 1))
        finite_frame "$f" || fail "$name: ${f##*/} holds NaN or infinite values (exit $rc)"
    done
    [ "$frames" -gt 0 ] || fail "$name: no frame written (exit $rc)"
done
# Self-collision pairs left unresolved by the fail-safe (pins or attachments pulling a zone
# apart) and intersections at frame ends, summed over the scenes: reported, not asserted.
unresolved=$(cat out/*/run.json 2> /dev/null | grep -o '"unresolved": [0-9]*' | awk '{ n += $2 } END { print n + 0 }')
intersecting=$(cat out/*/run.json 2> /dev/null | grep -o '"self_intersections": [0-9]*' | awk '{ n += $2 } END { print n + 0 }')
echo "hard_scenes: self-collision in $selfc scenes: $unresolved pair(s) left unresolved, $intersecting intersecting pair-frames" >&2
# Every scene's largest stretch and energy (run.json), worst first, with what forced it: reported,
# not asserted (issue 25 asks none past 1.5x; see the closing notes for where that stands).
PY=$(test -x /usr/bin/python3 && echo /usr/bin/python3 || command -v python3)
if [ -n "$PY" ]; then
    "$PY" "$SRC/tests/cli/hard_scenes_report.py" out --top 15 | sed 's/^/hard_scenes: /' >&2
fi
echo "hard_scenes: seeds $SEED ($moving with moving bodies, $attached attached): $ok of $COUNT ran to the end (exit 0), $reported gave up (exit 4) in ${seconds}s on 2 workers" >&2
finish
