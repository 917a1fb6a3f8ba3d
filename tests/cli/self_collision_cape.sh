# Self-collision (issue 16): the cape of examples/09_walking_cape on its walking body (a moving
# mesh collider, the collar attached to the shoulders) in gusts of 40 m/s (the windicator's
# speed keyed 4 -> 40 -> 8 -> 40 -> 6 -> 40 -> 20 m/s in two seconds), cloth thickness 3 mm. With
# self_collision = true no frame has an intersecting triangle pair (count_intersections.py, not
# gale), gale's count agrees and nothing is left unresolved; with self_collision = false the cape
# passes through itself.
source "$(dirname "$0")/lib.bash" "$@"
source "$SRC/tests/cli/self_collision_lib.bash"
mkdir ex
cp "$SRC/examples/09_walking_cape/"{scene.toml,shelter.se,make_body.py} ex/
cd ex || exit 1
run "$PY" make_body.py body
expect_rc 0 "make_body.py"

# The example's scene with the gusts, and self_collision / thickness set (replacing any the
# example has) right after its cape's drag.
gusty() {
    sed -e '/^self_collision *=/d' -e '/^\[\[cloth\]\]/,/^\[\[collider\]\]/{/^thickness *=/d}' \
        -e 's/^speed = .*/speed = { keys = [[0, 4.0], [0.4, 40.0], [0.7, 8.0], [1.1, 40.0], [1.4, 6.0], [1.8, 40.0], [2.0, 20.0]], interp = "smooth" }/' \
        -e "s/^drag = .*/&\nself_collision = $1\nthickness = 0.003/" scene.toml
}
gusty true > on.toml
gusty false > off.toml
[ "$(grep -c '40.0' on.toml)" -ge 1 ] && [ "$(grep -c '^self_collision = true' on.toml)" = 1 ] ||
    fail "the gusty scene was written (sed on examples/09_walking_cape/scene.toml)"

run "$GALE" sim on.toml -o on
expect_rc 0 "the walking cape in 40 m/s gusts with self-collision"
expect_clean on cape "the walking cape in 40 m/s gusts"
run "$GALE" sim off.toml -o off
expect_rc 0 "the walking cape without self-collision"
expect_dirty off cape "the walking cape in 40 m/s gusts"
finish
