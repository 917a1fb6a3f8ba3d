# --resume continues only the same run: a changed wind (the scene's text, an expression file, a
# --set of the windicator) is refused, while another thread count (which changes no result) is
# accepted and gives the same frames.
source "$(dirname "$0")/lib.bash" "$@"

cat > breeze.se <<'SE'
$speed = 4; # 0, 20
[0, 0, 1] * $speed
SE
cat > scene.toml <<'TOML'
[scene]
frames = [1, 8]
substeps = 2

[windicator]
speed = 3

[[field]]
name = "breeze"
expr = "breeze.se"

[[cloth]]
name = "sheet"
grid = { size = [0.5, 0.5], res = [8, 8], origin = [-0.25, 1, 0], axes = "xy" }
pins = { box = [-0.26, 1.49, -0.01, 0.26, 1.51, 0.01] }
TOML

run "$GALE" sim scene.toml -o full --threads 1
expect_rc 0 "the full run"
# A run cut after frame 4: its state is saved per frame, so drop frames 5-8 as a kill would.
cp -r full cut
rm -f cut/sheet.000[5-8].obj cut/.state/000[5-8].*
run "$GALE" sim scene.toml -o cut --resume --threads 2
expect_rc 0 "resumed on two threads"
for f in 5 6 7 8; do cmp -s cut/sheet.000$f.obj full/sheet.000$f.obj || fail "frame $f resumed on 2 threads is the same"; done

rm -f cut/sheet.000[5-8].obj cut/.state/000[5-8].*
run "$GALE" sim scene.toml -o cut --resume --set windicator.speed=12
expect_rc 1 "a --set of the windicator is another run"
expect_match "$ERR" "different settings|inputs changed since the saved run" "it says why ($ERR)"

sed -i 's/\$speed = 4;/$speed = 9;/' breeze.se
run "$GALE" sim scene.toml -o cut --resume
expect_rc 1 "an edited expression is another run"
sed -i 's/\$speed = 9;/$speed = 4;/' breeze.se

sed -i 's/^speed = 3$/speed = 5/' scene.toml
run "$GALE" sim scene.toml -o cut --resume
expect_rc 1 "an edited scene is another run"
[ -e cut/sheet.0005.obj ] && fail "no frame written by a refused resume"
finish
