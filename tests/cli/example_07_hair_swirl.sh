# examples/07_hair_swirl: the scene checks clean, the whole run (72 frames, as its README runs it)
# writes sane frames that move, and a preview picture of the last one renders.
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/07_hair_swirl"

run "$GALE" check "$EX/scene.toml"
expect_rc 0 "the scene checks clean"
run "$GALE" sim "$EX/scene.toml" -o out
expect_rc 0 "the full run"
for f in 0001 0005 0036 0072; do [ -s "out/hair.$f.obj" ] || fail "out/hair.$f.obj written"; done
expect_match "$(head -c 20 out/run.json)" '"status": "ok"' "run.json says ok"
bad=$(awk '/^v / { for (i = 2; i <= 4; i++) if ($i != $i + 0 || $i > 10 || $i < -10) n++ } END { print n + 0 }' out/hair.0072.obj)
expect_eq "$bad" "0" "finite, sane coordinates"
if cmp -s out/hair.0001.obj out/hair.0072.obj; then fail "the wind moves the hair"; fi
run "$GALE" viz "$EX/scene.toml" --sim out --frames 72:72 -o 'preview.#.png' --size 480x400
expect_rc 0 "a preview picture"
[ -s preview.0072.png ] || fail "preview.0072.png written"
finish
