# `gale sim` killed with SIGKILL part-way, again and again (right after frame k appears, and at
# short delays so some kills land while a file is being written): every frame on disk is whole
# and equal to an uninterrupted run's, killed writes leave no file a resume takes for a frame,
# `--resume` finishes with frames and run.json identical to the uninterrupted run, and a second
# run on a folder that a live run is writing is refused.
source "$(dirname "$0")/lib.bash" "$@"

cat > scene.toml <<'TOML'
[scene]
fps = 24
frames = [1, 30]
substeps = 4

[[field]]
name = "main"
source = "[6 + 3 * sin(4 * $t + $P[1]), 0, 2 * cos(5 * $t)]"

[[cloth]]
name = "flag"
grid = { size = [0.8, 0.6], res = [32, 24], origin = [-0.4, 0.4, 0], axes = "xy" }
density = 0.05
lift = 0.4
drag = 1.0
pins = { box = [-1, 0.99, -1, 1, 1.01, 1] }

[[hair]]
name = "tuft"
grid = { size = [0.2, 0.2], count = [4, 4], length = 0.4, segments = 10, origin = [1, 1.5, 0], direction = [0, -1, 0] }
output = "ply"
TOML

run "$GALE" sim scene.toml -o ref
expect_rc 0 "the uninterrupted reference run"
N_OBJ=$(grep -c '^v ' ref/flag.0030.obj)
expect_eq "$N_OBJ" "768" "reference OBJ has every vertex (32 x 24)"

# strip_times FILE: run.json without its wall-clock times.
strip_times() { sed -E 's/"wall_seconds": [^,]*,//g' "$1"; }

# check_dir DIR WHEN: every frame file in DIR is whole (vertex counts, PLY size) and identical to
# the reference's; no other files look like frames. Differences are listed once per check.
check_dir() {
    local dir=$1 when=$2 f name differ=() states=()
    for f in "$dir"/*.obj "$dir"/*.ply; do
        [ -e "$f" ] || continue
        name=${f##*/}
        if [ ! -f "ref/$name" ]; then
            fail "$when: $name is not a frame of the reference run"
            continue
        fi
        case $name in
            *.obj)
                [ "$(grep -c '^v ' "$f")" = "$N_OBJ" ] || fail "$when: $name has $(grep -c '^v ' "$f") vertices"
                [ -z "$(tail -c 1 "$f")" ] || fail "$when: $name does not end with a whole line" ;;
            *.ply)
                # Binary: the header names the vertex count; the size must match the reference.
                head -c 300 "$f" | tr -d '\000' | grep -q "element vertex 176" || fail "$when: $name header"
                [ "$(stat -c %s "$f")" = "$(stat -c %s "ref/$name")" ] || fail "$when: $name is cut short" ;;
        esac
        cmp -s "$f" "ref/$name" || differ+=("$name")
    done
    for f in "$dir"/.state/[0-9]*.bin; do
        [ -e "$f" ] || continue
        cmp -s "$f" "ref/.state/${f##*/}" || states+=("${f##*/}")
    done
    for f in "$dir"/.state/[0-9]*.json; do
        [ -e "$f" ] || continue
        [ "$(strip_times "$f")" = "$(strip_times "ref/.state/${f##*/}")" ] || states+=("${f##*/}")
    done
    [ ${#differ[@]} -eq 0 ] ||
        fail "$when: ${#differ[@]} frame(s) differ from the uninterrupted run: ${differ[*]:0:4} ..."
    [ ${#states[@]} -eq 0 ] ||
        fail "$when: ${#states[@]} saved state file(s) differ from the reference: ${states[*]:0:4} ..."
}

# kill_after DIR FILE DELAY: starts `gale sim --resume` into DIR, waits until FILE exists (if
# given) and DELAY seconds more, then SIGKILLs it.
KILLS=0
LANDED_MID_WRITE=0
kill_after() {
    local dir=$1 file=$2 delay=$3 pid i
    "$GALE" sim scene.toml -o "$dir" --resume 2>> "$dir.log" &
    pid=$!
    if [ -n "$file" ]; then
        wait_file "$dir/$file" "$pid"
    fi
    sleep "$delay"
    kill -KILL "$pid" 2> /dev/null && KILLS=$((KILLS + 1))
    wait "$pid" 2> /dev/null
    if compgen -G "$dir/*.tmp.*" > /dev/null || compgen -G "$dir/.state/*.tmp.*" > /dev/null; then
        LANDED_MID_WRITE=$((LANDED_MID_WRITE + 1))
    fi
    check_dir "$dir" "killed after ${file:-start} + ${delay}s"
}

# Kills at short fixed delays after the start (loading, the first frames, mid-write), each
# continuing the last (so the run crawls forward).
mkdir run
RANDOM=8 # fixed seed: the same delays every time
for i in 1 2 3 4 5 6; do
    kill_after run "" "0.0$((RANDOM % 10))$((RANDOM % 10))"
done
# Then kills right after frame k appears (at once when the delays already got past it). These
# land whatever the machine's speed; the delayed ones may find the run finished on a fast one.
for k in 0003 0007 0012 0018 0024; do
    kill_after run "flag.$k.obj" 0
done
[ "$KILLS" -ge 5 ] || fail "most runs were killed before they finished ($KILLS kills)"

# A temporary file of a killed writer is not a frame: plant two (a dead process's pid) and see
# the resume remove them.
sleep 0 &
dead=$!
wait "$dead"
printf 'v 1 2' > "run/flag.0029.obj.tmp.$dead"
printf 'junk' > "run/.state/0029.bin.tmp.$dead"
printf 'keep' > "run/notes.tmp.$dead" # not a name gale writes: left alone

run "$GALE" sim scene.toml -o run --resume
expect_rc 0 "the resumed run finishes"
check_dir run "after --resume"
for f in ref/*.obj ref/*.ply; do
    [ -f "run/${f##*/}" ] || fail "after --resume: ${f##*/} missing"
done
expect_eq "$(strip_times run/run.json | md5sum)" "$(strip_times ref/run.json | md5sum)" \
    "run.json equals the reference's (wall times aside)"
expect_eq "$(cd run && find . -name '*.tmp.*' | sort | tr '\n' ' ')" "./notes.tmp.$dead " \
    "the killed writers' temporary files are gone"
echo "crash_sim: $KILLS kills, $LANDED_MID_WRITE left a temporary file behind" >&2

# A damaged saved state (a crash of the machine, not of gale: cut short or emptied) is passed
# over with a warning, and the run resumes from the last state that loads.
head -c 1000 run/.state/0030.bin > cut && mv cut run/.state/0030.bin
: > run/.state/0029.bin
rm run/flag.0030.obj run/tuft.0029.ply
run "$GALE" sim scene.toml -o run --resume
expect_rc 0 "resume past damaged states"
expect_match "$ERR" "warning: run/.state/0030.bin: .*; resuming from an earlier frame" "warns about the damaged state"
expect_match "$ERR" "warning: run/.state/0029.bin: .*; resuming from an earlier frame" "warns about the emptied state"
expect_match "$ERR" "resuming after frame 28" "resumes from the last state that loads"
check_dir run "after resuming past damaged states"
[ -f run/flag.0030.obj ] && [ -f run/tuft.0029.ply ] || fail "the frames after 28 are written again"

# A fresh (not --resume) run throws the old states away: resuming it later must not pick up a
# later frame of the earlier run.
run "$GALE" sim scene.toml -o run --set cloth.flag.drag=2 --resume
expect_rc 1 "resume with changed settings is refused"
"$GALE" sim scene.toml -o run --set cloth.flag.drag=2 2> /dev/null &
pid=$!
for ((i = 0; i < 3000; i++)); do
    [ "$(cat run/.state/lock 2> /dev/null)" = "$pid" ] && break
    sleep 0.005
done
wait_file run/.state/0004.json "$pid"
# While it runs, a second run into the same folder is refused (exit 3), not interleaved.
run "$GALE" sim scene.toml -o run --set cloth.flag.drag=2 --resume
if kill -0 "$pid" 2> /dev/null; then
    expect_rc 3 "a second run on a folder in use"
    expect_match "$ERR" "being written by another gale sim \(pid $pid\)" "names the other run"
fi
kill -KILL "$pid" 2> /dev/null
wait "$pid" 2> /dev/null
if grep -q '"status": "running"' run/run.json; then # killed before its end, as meant
    [ -f run/.state/0030.bin ] && fail "the killed fresh run's folder still has the old run's last state"
    run "$GALE" sim scene.toml -o run --set cloth.flag.drag=2 --resume
    expect_rc 0 "resume of the fresh run"
    expect_match "$ERR" "resuming after frame" "it resumes"
fi
run "$GALE" sim scene.toml -o fresh --set cloth.flag.drag=2
expect_rc 0 "uninterrupted run with drag 2"
differ=()
for f in fresh/*.obj fresh/*.ply; do
    cmp -s "$f" "run/${f##*/}" || differ+=("${f##*/}")
done
[ ${#differ[@]} -eq 0 ] || fail "drag 2 resumed: ${#differ[@]} frame(s) differ from its uninterrupted run: ${differ[*]:0:4} ..."
finish
