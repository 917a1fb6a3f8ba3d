# `gale wedge --jobs 2` killed with SIGKILL part-way, with its running simulations (a crashed
# machine) or alone (its simulations live on as orphans): every frame on disk is whole and equal
# to an uninterrupted wedge's, manifest.jsonl stays whole, and re-running the wedge finishes with
# every output identical to the uninterrupted wedge (timings and exit codes of skipped variants
# aside). A re-run while orphans still write is refused per variant, never interleaved.
source "$(dirname "$0")/lib.bash" "$@"

cat > tiny.toml <<'TOML'
[scene]
fps = 24
frames = [1, 24]
substeps = 4

[[field]]
name = "main"
source = "[5, 0, 2 * sin(6 * $t)]"

[[cloth]]
name = "c"
grid = { size = [0.5, 0.5], res = [16, 16], origin = [-0.25, 0.5, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
lift = 0.3
drag = 1.0
# The direct solver keeps this test about the wedge's own bookkeeping; that a resumed PCG cloth
# matches an uninterrupted one is crash_sim.sh's (and sim_cape.sh's) to check.
linear_solver = "direct"
pins = { box = [-1, 0.99, -1, 1, 1.01, 1] }
TOML

ARGS=(wedge tiny.toml --vary cloth.c.lift=0.1,0.2,0.3,0.4 --vary cloth.c.drag=0.8,1.2 -o w --jobs 2)
run "$GALE" "${ARGS[@]}"
expect_rc 0 "the uninterrupted reference wedge"
mv w ref
VARIANTS=$(cd ref && ls -d v0*/ | tr -d / | tr '\n' ' ')
expect_eq "$(echo $VARIANTS | wc -w)" "8" "eight variants"

strip() { sed -E 's/"wall_seconds": [^,]*,//g; s/, "exit_code": [0-9]+//g' "$1"; }

# check_wedge WHEN: frames whole and equal to the reference, manifest lines whole.
check_wedge() {
    local when=$1 v f
    [ -f w/manifest.jsonl ] || return 0
    expect_eq "$(grep -c '^{"id": .*}$' w/manifest.jsonl)" "8" "$when: manifest.jsonl has eight whole lines"
    expect_eq "$(wc -l < w/manifest.jsonl)" "8" "$when: manifest.jsonl has no torn line"
    for v in $VARIANTS; do
        for f in w/"$v"/*.obj; do
            [ -e "$f" ] || continue
            [ "$(grep -c "^v " "$f")" = 256 ] || fail "$when: $f has $(grep -c '^v ' "$f") vertices"
            cmp -s "$f" "ref/$v/${f##*/}" || fail "$when: $f differs from the uninterrupted wedge"
        done
        [ ! -f "w/$v/DONE" ] || [ -f "w/$v/c.0024.obj" ] || fail "$when: $v is DONE without its last frame"
    done
}

# descendants PID: every process below PID.
descendants() {
    local c
    for c in $(pgrep -P "$1"); do
        echo "$c"
        descendants "$c"
    done
}

# crash WAIT_FOR DELAY: runs the wedge, waits for the file WAIT_FOR (if given) plus DELAY seconds,
# then SIGKILLs the wedge and every process under it at once, as a crashed machine would.
crash() {
    local pid procs i
    "$GALE" "${ARGS[@]}" 2>> wedge.log &
    pid=$!
    if [ -n "$1" ]; then
        wait_file "$1" "$pid"
    fi
    sleep "$2"
    # Freeze the tree top down (no process starts another meanwhile), then kill it at once.
    kill -STOP "$pid" 2> /dev/null
    procs=$(descendants "$pid")
    kill -STOP $procs 2> /dev/null
    procs=$(descendants "$pid")
    kill -KILL "$pid" $procs 2> /dev/null
    wait "$pid" 2> /dev/null
    check_wedge "killed at ${1:-start} + $2 s"
}

crash "w/v000_lift=0.1_drag=0.8/c.0006.obj" 0
crash "w/v001_lift=0.1_drag=1.2/c.0020.obj" 0
crash "w/v003_lift=0.2_drag=1.2/DONE" 0
crash "" 0.05
crash "" 0.13
crash "w/v005_lift=0.3_drag=1.2/c.0012.obj" 0.01

# Kill the wedge alone: its running simulations carry on as orphans. A re-run at once either
# finds them finished or is refused for the variants they still write (exit 3, said in the log).
"$GALE" "${ARGS[@]}" 2>> wedge.log &
pid=$!
wait_file "w/v006_lift=0.4_drag=0.8/c.0004.obj" "$pid"
kill -KILL "$pid"
wait "$pid" 2> /dev/null
run "$GALE" "${ARGS[@]}"
echo "crash_wedge: the re-run beside the orphans exited $RC" >&2
if [ "$RC" != 0 ]; then
    expect_rc 3 "a re-run while the orphans write"
    expect_match "$(cat w/v00*/log.txt)" "being written by another gale sim" "the refused variant says why"
fi
for ((i = 0; i < 3000; i++)); do
    pgrep -f "$TMP/w/v0" > /dev/null || break
    sleep 0.01
done
check_wedge "after the orphans"

run "$GALE" "${ARGS[@]}"
expect_rc 0 "the re-run finishes the wedge"
check_wedge "after the re-run"
expect_eq "$(strip w/manifest.jsonl)" "$(strip ref/manifest.jsonl)" \
    "manifest.jsonl equals the reference's (exit codes of skipped variants aside)"
cmp -s w/tasks.txt ref/tasks.txt || fail "tasks.txt equals the reference's"
for v in $VARIANTS; do
    [ -f "w/$v/DONE" ] || fail "$v has DONE"
    for f in ref/"$v"/*.obj ref/"$v"/scene.toml; do
        cmp -s "$f" "w/$v/${f##*/}" || fail "$v/${f##*/} differs from the uninterrupted wedge"
    done
    expect_eq "$(strip "w/$v/run.json" | md5sum)" "$(strip "ref/$v/run.json" | md5sum)" "$v/run.json"
    [ -z "$(find "w/$v" -name '*.tmp.*')" ] || fail "$v: temporary files left: $(find "w/$v" -name '*.tmp.*')"
done
finish
