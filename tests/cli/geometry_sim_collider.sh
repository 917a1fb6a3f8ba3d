# `gale sim` with a mesh collider ([[collider]] type = "mesh"): a sheet dropped on the example
# body's head comes to rest on it, outside the body (its SDF); run.json names the collider
# type; the same mesh shelters the scene's wind; a missing mesh is an error at its key.
source "$(dirname "$0")/lib.bash" "$@"

cp "$SRC/examples/04_shelter/body.obj" body.obj
cat > scene.toml <<'TOML'
[scene]
fps = 24
frames = [1, 10]
substeps = 2

[[field]]
name = "breeze"
source = 'shadow("body.obj", $P, [0, 0, -1], 1.0) * [0, 0, -2]'

[[cloth]]
name = "sheet"
grid = { size = [0.8, 0.5], res = [16, 10], origin = [-0.4, 1.8, -0.25], axes = "xz" }
density = 0.1
stretch = 1000.0

[[collider]]
name = "body"
type = "mesh"
mesh = "body.obj"
voxel = 0.02
thickness = 0.005
TOML
run "$GALE" sim scene.toml -o out
expect_rc 0 "a sheet on the body"
expect_match "$(cat out/run.json)" '"type": "mesh"' "run.json names the collider type"
expect_match "$(grep -o '"contacts": [0-9]*' out/run.json | tail -n 1)" '"contacts": [1-9]' "resting on the head"
# The sheet started 5 cm above the head (top at 1.745 m) and fell onto it; no vertex is inside
# the body, and the lowest one hangs at the head, not below the shoulders.
run "$GALE" eval -e 'sdf("body.obj", $P)' --points out/sheet.0010.obj --precision double
expect_rc 0 "distances of the last frame"
inside=$(tail -n +2 <<< "$OUT" | awk -F, '$4 < 0 { n++ } END { print n + 0 }')
expect_eq "$inside" "0" "no vertex inside the body"
lowest=$(awk '/^v / { print $3 }' out/sheet.0010.obj | sort -n | head -n 1)
awk -v y="$lowest" 'BEGIN { exit !(y > 1.5 && y < 1.75) }' || fail "the sheet rests on the head (lowest y $lowest)"

sed -i 's/mesh = "body.obj"/mesh = "nobody.obj"/' scene.toml
run "$GALE" sim scene.toml -o out2
expect_rc 3 "a missing collider mesh (a missing file: exit 3, spec cli.md)"
expect_match "$ERR" "^scene.toml:19:8: error: \[\[collider\]\] 'body': cannot read 'nobody.obj'" "at the key"

finish
