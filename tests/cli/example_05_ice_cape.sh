# examples/05_ice_cape: the scene checks clean, the whole run (72 frames, as the README says to
# run it) ends with exit 0 and sane frames that move, and a preview picture renders. The run
# used to blow up at frame 18: the skew part of the high-lift Jacobian (docs/solver.md).
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/05_ice_cape"

run "$GALE" check "$EX/scene.toml"
expect_rc 0 "the scene checks clean"
run "$GALE" sim "$EX/scene.toml" -o out
expect_rc 0 "the full run"
# C_L = 0.9 > C_D = 0.7: warned about at the lift key's position, once.
expect_match "$ERR" "scene.toml:[0-9]+:[0-9]+: \[\[cloth\]\] 'cape': lift C_L = 0.9 exceeds drag C_D = 0.7" "the lift above the drag is warned about"
expect_eq "$(grep -c 'exceeds drag' <<< "$ERR")" "1" "one warning"
for f in 0001 0005 0036 0072; do [ -s "out/cape.$f.obj" ] || fail "out/cape.$f.obj written"; done
expect_match "$(head -c 20 out/run.json)" '"status": "ok"' "run.json says ok"
for f in 0005 0018 0036 0072; do
    bad=$(awk '/^v / { for (i = 2; i <= 4; i++) if ($i != $i + 0 || $i > 10 || $i < -10) n++ } END { print n + 0 }' out/cape.$f.obj)
    expect_eq "$bad" "0" "finite, sane coordinates in frame $f"
done
# Pinned at the collar, 1.5 m long: no vertex ever further than 1.6 m from the collar line.
far=$(awk '/^v / { d = ($3 - 1.6) ^ 2 + $4 ^ 2; if (d > 1.6 ^ 2) n++ } END { print n + 0 }' out/cape.0072.obj)
expect_eq "$far" "0" "the cape stays within its length of the collar"
if cmp -s out/cape.0001.obj out/cape.0005.obj; then fail "the wind moves the cape"; fi
run "$GALE" sim "$EX/scene.toml" -o calm --frames 1:2 --set cloth.cape.lift=0.7
expect_rc 0 "lift = drag"
if grep -q 'exceeds drag' <<< "$ERR"; then fail "no warning when the lift does not exceed the drag"; fi
run "$GALE" viz "$EX/scene.toml" --sim out --frames 5:5 -o 'preview.#.png' --size 480x400
expect_rc 0 "a preview picture"
[ -s preview.0005.png ] || fail "preview.0005.png written"
finish
