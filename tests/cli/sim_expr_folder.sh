# A painted map whose `expr` names no file (empty, so it resolves to the scene's folder) is a
# clear error at its line, not a crash (found by fuzz_scene: the stream threw reading a folder).
source "$(dirname "$0")/lib.bash" "$@"
cat > scene.toml <<'TOML'
[scene]
frames = [1, 2]

[[cloth]]
name = "cape"
grid = { size = [1, 1], res = [4, 4] }
drag = { expr = "" }
TOML
run "$GALE" sim scene.toml -o out
expect_rc 1 "an empty drag expr"
grep -q "scene.toml:7:[0-9]*: error: \[\[cloth\]\] .cape. drag" <<< "$ERR" ||
    fail "the error names the drag map at the scene's line 7: $ERR"
finish
