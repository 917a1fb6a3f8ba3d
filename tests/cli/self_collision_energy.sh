# Self-collision (issue 16): contact does not create energy. Two sheets in zero wind (no field),
# 0.8 m, 4 substeps, thickness 3 mm, self_collision = true:
#  1. pinned at its centre, horizontal at first: it falls, its sides fold down onto each other
#     (without self-collision they pass through each other, checked). The total energy in
#     run.json (kinetic + potential + elastic) never exceeds its start value by more than 1 %.
#  2. dropped edge-first onto the ground, where it piles up on itself: once it lies still
#     (frames 25-49, kinetic energy < 5 mJ) its total energy does not grow by more than 1 % of
#     the start value. (The whole-run bound is not used here: the edge's impact on the ground
#     collider shows a one-frame elastic spike with or without self-collision.)
source "$(dirname "$0")/lib.bash" "$@"
source "$SRC/tests/cli/self_collision_lib.bash"

pinned() {
    cat <<TOML
[scene]
fps = 24
frames = [1, 49]
substeps = 4

[[cloth]]
name = "sheet"
grid = { size = [0.8, 0.8], res = [25, 25], origin = [-0.4, 1, -0.4], axes = "xz" }
density = 0.1
stretch = 500.0
shear = 50.0
bend = 1e-4
self_collision = $1
thickness = 0.003
pins = { box = [-0.01, 0.99, -0.01, 0.01, 1.01, 0.01] }
TOML
}
dropped() {
    cat <<TOML
[scene]
fps = 24
frames = [1, 49]
substeps = 4

[[cloth]]
name = "sheet"
grid = { size = [0.8, 0.8], res = [24, 24], origin = [-0.4, 0.3, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
bend = 1e-4
self_collision = true
thickness = 0.003

[[collider]]
name = "ground"
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
TOML
}
pinned true > pinned.toml
pinned false > pinned_off.toml
dropped > dropped.toml

# energy DIR FIRST LAST: "START MAX END_START END": the total energy at the first frame, its
# maximum, and at frames FIRST and LAST.
energy() {
    "$PY" - "$1/run.json" "$2" "$3" <<'PY'
import json, sys
frames = json.load(open(sys.argv[1]))['frames']
e = {f['frame']: sum(o['energy']['total'] for o in f['objects']) for f in frames}
k = max(sum(o['energy']['kinetic'] for o in f['objects']) for f in frames if f['frame'] >= int(sys.argv[2]))
print(e[frames[0]['frame']], max(e.values()), e[int(sys.argv[2])], e[int(sys.argv[3])], k)
PY
}

run "$GALE" sim pinned.toml -o pinned
expect_rc 0 "the centre-pinned sheet"
expect_clean pinned sheet "the centre-pinned sheet"
read -r e0 emax _ <<< "$(energy pinned 1 49)"
echo "pinned sheet: total energy at the start $e0 J, at most $emax J" >&2
awk -v a="$e0" -v m="$emax" 'BEGIN { exit !(a > 0 && m <= 1.01 * a) }' ||
    fail "the centre-pinned sheet's total energy rose to $emax J from $e0 J (bound: +1 %)"
run "$GALE" sim pinned_off.toml -o pinned_off
expect_rc 0 "the centre-pinned sheet without self-collision"
expect_dirty pinned_off sheet "the centre-pinned sheet"

run "$GALE" sim dropped.toml -o dropped
expect_rc 0 "the sheet dropped onto the ground"
expect_clean dropped sheet "the sheet dropped onto the ground"
read -r e0 _ e25 e49 k <<< "$(energy dropped 25 49)"
echo "dropped sheet: start $e0 J; resting pile $e25 J at frame 25, $e49 J at frame 49 (kinetic at most $k J)" >&2
awk -v k="$k" 'BEGIN { exit !(k < 5e-3) }' || fail "the pile lies still from frame 25 (kinetic energy up to $k J)"
awk -v a="$e0" -v b="$e25" -v c="$e49" 'BEGIN { exit !(c <= b + 0.01 * a) }' ||
    fail "the resting pile's total energy grew from $e25 J (frame 25) to $e49 J (frame 49), start $e0 J (bound: +1 % of the start)"
finish
