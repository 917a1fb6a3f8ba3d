# `gale wedge` killed part-way (--jobs 1) and run again: finished variants are not redone (their
# DONE markers and frames keep their times), the interrupted one resumes, all complete at the end,
# and killing the wedge also stops the simulation it was running.
source "$(dirname "$0")/lib.bash" "$@"

cat > tiny.toml <<'TOML'
[scene]
fps = 24
frames = [1, 40]           # about a second per variant
substeps = 4

[[field]]
name = "main"
source = "[4, 0, 2 * sin(6 * $t)]"

[[cloth]]
name = "c"
grid = { size = [0.5, 0.5], res = [20, 20], origin = [-0.25, 0.5, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
lift = 0.3
drag = 1.0
pins = { box = [-1, 0.99, -1, 1, 1.01, 1] }
TOML

# One variant at a time: kill the wedge once the first has finished.
ARGS=(wedge tiny.toml --vary cloth.c.lift=0.1,0.2,0.3,0.4 -o w --jobs 1)
"$GALE" "${ARGS[@]}" 2> wedge1.err &
pid=$!
for _ in $(seq 1 600); do
    [ -f w/v000_lift=0.1/DONE ] && break
    sleep 0.05
done
# The second variant is under way: wait until some of its frames are written (polling, not a
# fixed delay, so a loaded machine cannot kill it before it saved anything to resume from).
for _ in $(seq 1 600); do
    compgen -G 'w/v001_*/c.0004.obj' > /dev/null && break
    sleep 0.05
done
kill -TERM "$pid"
wait "$pid"
rc=$?
[ -f w/v000_lift=0.1/DONE ] || fail "the first variant finished before the kill"
[ "$rc" -ne 0 ] || fail "the wedge was killed (exit $rc)"
[ -f w/v003_lift=0.4/DONE ] && fail "the last variant had not finished when the wedge was killed"
sleep 0.2
if pgrep -f "$TMP/w/v00" > /dev/null; then fail "killing the wedge stops its running simulation"; fi

done_before=()
declare -A stamp
for d in w/v00*/; do
    d=${d%/}
    if [ -f "$d/DONE" ]; then
        done_before+=("$d")
        stamp[$d]="$(stat -c %y "$d/DONE") $(stat -c %y "$d/c.0002.obj")"
    fi
done
interrupted=""
for d in w/v00*/; do [ -f "$d/DONE" ] || { interrupted=${d%/}; break; }; done
run "$GALE" "${ARGS[@]}"
expect_rc 0 "the re-run completes the wedge"
[ -n "$interrupted" ] && expect_match "$(cat "$interrupted/log.txt")" "resuming after frame" \
    "the interrupted variant resumes where it stopped"
expect_match "$ERR" "${#done_before[@]} variant\(s\) already complete, skipped" "re-run skips the finished ones"
for d in "${done_before[@]}"; do
    expect_eq "$(stat -c %y "$d/DONE") $(stat -c %y "$d/c.0002.obj")" "${stamp[$d]}" "$d not redone"
done
for d in w/v00*/; do
    [ -f "$d/DONE" ] || fail "$d complete after the re-run"
    [ -s "$d/c.0003.obj" ] || fail "$d/c.0003.obj"
done
expect_eq "$(grep -c '"status": "done"' w/manifest.jsonl)" "4" "manifest: all done"

# A changed scene starts the variants over instead of resuming a different run.
run "$GALE" "${ARGS[@]}" --set cloth.c.drag=2
expect_rc 0 "changed scene"
expect_match "$ERR" "4 variant\(s\) had a different scene before" "says they start over"
finish
