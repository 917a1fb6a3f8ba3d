# Self-collision (issue 16): a 0.8 x 0.5 m flag (24 x 16) pinned along its top in a wind across
# it that reverses every half second (6 m/s, +z then -z): the flag is thrown back and forth and
# folds onto itself at each reversal. With self_collision = true no frame has an intersecting
# triangle pair (count_intersections.py, not gale), gale's own count agrees and nothing is left
# unresolved; with self_collision = false the same flag passes through itself.
source "$(dirname "$0")/lib.bash" "$@"
source "$SRC/tests/cli/self_collision_lib.bash"

flag() {
    cat <<TOML
[scene]
fps = 24
frames = [1, 49]
substeps = 4

[[field]]
name = "reversing"
source = "[0.5, 0, (fmod(\$t, 1) < 0.5 ? 1 : -1) * 6]"

[[cloth]]
name = "flag"
grid = { size = [0.8, 0.5], res = [24, 16], origin = [0, 0.5, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
bend = 1e-4
self_collision = $1
thickness = 0.003
pins = { box = [-0.01, 0.99, -1, 0.81, 1.01, 1] }
TOML
}
flag true > on.toml
flag false > off.toml

run "$GALE" sim on.toml -o on
expect_rc 0 "the flag with self-collision"
expect_clean on flag "the flag in reversing wind"
run "$GALE" sim off.toml -o off
expect_rc 0 "the flag without self-collision"
expect_dirty off flag "the flag in reversing wind"
finish
