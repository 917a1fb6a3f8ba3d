# examples/11_character, run in full as shipped, in both winds: make_character.py writes the
# skinned walker (one closed skin, 50 frames with handles), the cape modelled on its bind pose
# and the ponytail; the scene checks clean and simulates the shot 1001-1048 after its pre-roll,
# in the tailwind and in the crosswind (`--set windicator.direction=...`, as the README says).
# Every frame is then measured from the files alone (character_check.py, independent of gale):
# no cape vertex inside the body (winding number), no cape triangle through the body, no cape
# self-intersection, no hair segment through the cape, no cape edge beyond 1.2x its rest length
# and no hair segment beyond 1.2x, the collar's edges within +-5 % of rest. The frame wall times
# are printed, not asserted (speed is for benchmarks). And the control: in the tailwind the
# ponytail lies on the cape, and without collide_cloth it passes through it (the check can fail).
source "$(dirname "$0")/lib.bash" "$@"
PY=$(test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
"$PY" -c 'import numpy' 2> /dev/null || { echo "SKIP: python3 with numpy is not installed (make deps installs python3-numpy)"; exit 0; }
mkdir ex
cp "$SRC/examples/11_character/"{scene.toml,make_character.py} ex/
cd ex || exit 1

run "$PY" make_character.py body
expect_rc 0 "make_character.py ($ERR)"
[ -s body/body.1000.obj ] && [ -s body/body.1049.obj ] && [ -s body/rest.obj ] && [ -s cape.obj ] && [ -s hair.csv ] ||
    fail "body/body.1000.obj ... body.1049.obj, body/rest.obj, cape.obj and hair.csv written"

run "$GALE" check scene.toml
expect_rc 0 "the scene checks clean"
expect_eq "$ERR" "" "no warning from gale check"

# variant NAME [--set ...]: simulates the shot and checks every frame against the goals.
variant() {
    local name=$1
    shift
    run "$GALE" sim scene.toml -o "$name" "$@"
    expect_rc 0 "$name: the shot, 48 frames after a 12-frame pre-roll"
    [ -s "$name/cape.1048.obj" ] && [ -s "$name/ponytail.1048.obj" ] || fail "$name: frame 1048 written"
    [ -e "$name/cape.1000.obj" ] && fail "$name: a pre-roll frame was written"
    expect_no_match "$(cat "$name/run.json")" '"failed": true' "$name: no frame failed"
    run "$PY" "$SRC/tests/cli/character_check.py" --body 'body/body.#.obj' --cloth "$name/cape.#.obj" \
        --rest cape.obj --collar 0-16 --hair "$name/ponytail.#.obj" --hair-rest hair.csv \
        --run "$name/run.json" --frames 1001:1048
    expect_rc 0 "$name: character_check.py ($ERR)"
    echo "$name: $(grep '^summary' <<< "$OUT")"
    local s
    s=$(grep '^summary' <<< "$OUT")
    expect_match "$s" ' frames=48 ' "$name: 48 frames measured"
    expect_match "$s" ' body_closed=True ' "$name: the skin is closed at every frame"
    expect_match "$s" ' inside=0 ' "$name: no cape vertex inside the body at any frame"
    expect_match "$s" ' crossings=0 ' "$name: no cape triangle through the body at any frame"
    expect_match "$s" ' self=0 ' "$name: no cape self-intersection at any frame"
    expect_match "$s" ' hair=0 ' "$name: no hair segment through the cape at any frame"
    grep '^miss:' <<< "$OUT" | grep -v 'worst frame' | sed "s/^/$name: /" >&2
    local stretch collar hair_stretch
    stretch=$(grep -o ' stretch=[0-9.]*' <<< "$s" | cut -d= -f2)
    hair_stretch=$(grep -o ' hair_stretch=[0-9.e-]*' <<< "$s" | cut -d= -f2)
    collar=$(grep -o ' collar=\[[0-9.]*,[0-9.]*\]' <<< "$s" | sed 's/.*\[\(.*\)\]/\1/')
    [ -n "$stretch" ] && [ -n "$hair_stretch" ] && [ -n "$collar" ] || fail "$name: stretch, hair stretch and collar measured"
    awk -v x="${stretch:-9}" 'BEGIN { exit !(x <= 1.2) }' || fail "$name: largest cape stretch $stretch, wanted <= 1.2"
    awk -v x="${hair_stretch:-9}" 'BEGIN { exit !(x <= 0.2) }' ||
        fail "$name: a hair segment $hair_stretch off its rest length, wanted <= 0.2"
    awk -v c="${collar:-0,9}" 'BEGIN { split(c, a, ","); exit !(a[1] >= 0.95 && a[2] <= 1.05) }' ||
        fail "$name: collar edges between $collar of rest, wanted within 5 %"
}
variant tail
variant cross --set 'windicator.direction=[1, 0, 0.15]'

# The control: the same tailwind shot without hair-cloth collision, measured over frames
# 1013-1020 (where the ponytail lies on the cape): strands pass through the cape.
run "$GALE" sim scene.toml -o open --frames 1001:1020 --set hair.ponytail.collide_cloth=false
expect_rc 0 "the tailwind shot without collide_cloth"
run "$PY" "$SRC/tests/cli/character_check.py" --body 'body/body.#.obj' --cloth 'open/cape.#.obj' --rest cape.obj \
    --hair 'open/ponytail.#.obj' --frames 1013:1020
expect_rc 0 "character_check.py on the control ($ERR)"
crossing=$(grep '^summary' <<< "$OUT" | grep -o ' hair=[0-9]*' | cut -d= -f2)
[ "${crossing:-0}" -gt 0 ] || fail "without collide_cloth some hair segment passes through the cape (got ${crossing:-none})"
echo "control (collide_cloth = false): $crossing hair segments through the cape over frames 1013-1020"

run "$GALE" viz scene.toml --sim tail --frames 1030:1030 --plane x=0 --size 320x320 -o 'p.#.png'
expect_rc 0 "a preview"
[ -s p.1030.png ] || fail "p.1030.png written"
finish
