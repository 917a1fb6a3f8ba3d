# `gale sim` on the 03_cape example: per-frame OBJ files and run.json, --resume identical to an
# uninterrupted run, any thread count the same, --set overrides, and the exit codes.
source "$(dirname "$0")/lib.bash" "$@"
SCENE="$SRC/examples/03_cape/scene.toml"

run "$GALE" sim "$SCENE" -o full --frames 1:6
expect_rc 0 "six frames of the cape"
for f in 0001 0002 0006; do
    [ -f "full/cape.$f.obj" ] || fail "full/cape.$f.obj written"
done
expect_eq "$(grep -c '^v ' full/cape.0006.obj)" "768" "every vertex written"
expect_eq "$(grep -c '^f ' full/cape.0006.obj)" "1426" "every triangle written"
expect_match "$(head -c 20 full/run.json)" '^\{"status": "ok"' "run.json says ok"
expect_eq "$(grep -o '"frame": [0-9]*' full/run.json | wc -l)" "6" "run.json has six frames"
expect_match "$(cat full/run.json)" '"solver_iterations": [1-9]' "per-frame solver stats"
bad=$(awk '/^v / { for (i = 2; i <= 4; i++) if ($i != $i + 0 || $i > 10 || $i < -10) n++ } END { print n + 0 }' full/cape.0006.obj)
expect_eq "$bad" "0" "finite, sane coordinates"
# The cape moved, and the collar stayed pinned at y = 1.6.
if cmp -s full/cape.0001.obj full/cape.0006.obj; then fail "the cape moved"; fi
expect_eq "$(grep '^v ' full/cape.0006.obj | tail -n 1 | awk '{ printf "%.3f", $3 }')" "1.600" "collar pinned"

# --resume after an interruption gives the same frames, bit for bit.
cp -r full resumed
rm -f resumed/cape.0005.obj resumed/cape.0006.obj resumed/.state/0005.* resumed/.state/0006.*
run "$GALE" sim "$SCENE" -o resumed --frames 1:6 --resume
expect_rc 0 "resume"
expect_match "$ERR" "resuming after frame 4" "resumes where it stopped"
cmp -s full/cape.0006.obj resumed/cape.0006.obj || fail "resumed frame 6 differs from the uninterrupted run"
expect_eq "$(grep -o '"frame": [0-9]*' resumed/run.json | wc -l)" "6" "resumed run.json has every frame"
# A changed scene is not resumed silently.
run "$GALE" sim "$SCENE" -o resumed --frames 1:6 --resume --set cloth.cape.drag=0.5
expect_rc 1 "resume with other settings"

# Threads do not change results.
run "$GALE" sim "$SCENE" -o threaded --frames 1:3 --threads 2
expect_rc 0 "two threads"
cmp -s full/cape.0003.obj threaded/cape.0003.obj || fail "--threads 2 differs from --threads 1"

# --set by dotted path, --json on stdout, PLY output.
run "$GALE" sim "$SCENE" -o still --frames 1:3 --set windicator.speed=0 --set cloth.cape.output=ply --json
expect_rc 0 "--set and --json"
expect_match "$OUT" '"status": "ok"' "--json prints run.json"
expect_match "$(head -c 200 still/cape.0003.ply | tr -d '\000')" "element vertex 768" "PLY output"

# Errors: a scene mistake at file:line:col (1), bad flags (2), a missing file (3), a
# numerical failure (4).
cat > bad.toml <<'TOML'
[[cloth]]
name = "c"
grid = { size = [1, 1], res = [4, 4] }
stretchh = 10
TOML
run "$GALE" sim bad.toml -o bad
expect_rc 1 "unknown key"
expect_match "$ERR" "bad.toml:4:1: error: unknown key 'stretchh' in \[\[cloth\]\]" "file:line:col"
run "$GALE" sim "$SCENE" --frames 5
expect_rc 2 "malformed --frames"
run "$GALE" sim missing.toml
expect_rc 3 "missing scene"
# Forces that overflow: every substep is non-finite down to the smallest one, where the world
# recovers (speeds capped, strain limited) instead of giving up, and says so.
run "$GALE" sim "$SCENE" -o nan --frames 1:3 --set "scene.gravity=[0,-1e308,0]"
expect_rc 0 "a non-finite run is recovered"
expect_match "$ERR" "non-finite state" "says what went wrong"
expect_match "$(cat nan/run.json)" 'recovered by strain limiting' "run.json names the recovery"
bad=$(grep -Eic '^v .*(nan|inf)' nan/*.obj | awk -F: '{ s += $2 } END { print s + 0 }')
expect_eq "$bad" "0" "no NaN or infinity in the frames"

finish
