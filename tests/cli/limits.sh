# Limits give a diagnostic and a non-zero exit, never a crash, a hang or a huge allocation:
# program size, nesting and tree depth, vector width, numbers of parameters, locals and defs,
# string length, grid and picture sizes, point counts, frame ranges, generated cloth and hair
# grids. The inputs are generated here (some are megabytes). See docs/limits.md.
source "$(dirname "$0")/lib.bash" "$@"

# ---- expressions ----
# 10^5 `$p` parameters and 10^5 locals compile (in linear time: the ctest timeout guards it).
awk 'BEGIN { for (i = 0; i < 100000; i++) printf "$p%d = %d;  # 0, 1000000\n", i, i; print "$p99999 + $p7" }' > params.se
run "$GALE" eval params.se
expect_rc 0 "10^5 parameters"
expect_eq "$OUT" "100006" "their values"
run "$GALE" eval params.se --set p7=1
expect_eq "$OUT" "1e+05" "--set overrides one of them"
awk 'BEGIN { for (i = 0; i < 100000; i++) printf "a%d = %d * $P[0] + 1;\n", i, i; print "a99999 + a3" }' > locals.se
run "$GALE" eval locals.se
expect_eq "$RC $OUT" "0 2" "10^5 locals"
awk 'BEGIN { for (i = 0; i < 100000; i++) printf "def g%d(x) { x + %d }\n", i, i; print "g99999(1)" }' > defs.se
run "$GALE" eval defs.se
expect_eq "$RC $OUT" "0 1e+05" "10^5 defs"

# Vector width: at most FP[16], however wide the literal.
awk 'BEGIN { printf "["; for (i = 0; i < 1000000; i++) printf "%s1", (i ? "," : ""); print "]" }' > wide.se
run "$GALE" check wide.se
expect_rc 1 "a 10^6-element vector literal"
expect_match "$ERR" "^wide.se:1:1: error: vector literal has 1000000 elements; the widest type is FP\[16\]" "its message"

# Source size, syntax nodes, tree depth.
{ printf '#'; head -c $((65 * 1024 * 1024)) /dev/zero | tr '\0' x; printf '\n1\n'; } > huge.se
run "$GALE" check huge.se
expect_rc 1 "a 65 MB source"
expect_match "$ERR" "^huge.se:1:1: error: source too large: [0-9]+ bytes \(the limit is 67108864\)" "its message"
rm -f huge.se
awk 'BEGIN { for (i = 0; i < 700000; i++) print "a = [1, 2];"; print "a" }' > nodes.se
run "$GALE" check nodes.se
expect_rc 1 "more than 2M syntax nodes"
expect_match "$ERR" "^nodes.se:[0-9]+:[0-9]+: error: program too large: more than 2000000 syntax nodes" "its message"
awk 'BEGIN { printf "a = $P[0];\na"; for (i = 0; i < 5000; i++) printf "+a"; print "" }' > chain.se
run "$GALE" check chain.se
expect_rc 1 "a 5000-term chain"
expect_match "$ERR" "^chain.se:2:1: error: expression too complex: its syntax tree is deeper than 1024 levels" "its message"

# A 10 MB string literal is fine; its length is the source size limit.
awk 'BEGIN { printf "\""; for (i = 0; i < 1000000; i++) printf "0123456789"; print "\"" }' > str.se
run "$GALE" check str.se
expect_rc 0 "a 10 MB string"

# printf/sprintf width and precision: at most 1000 (a constant format is checked at compile time).
run "$GALE" eval -e 'sprintf("%999999999d", 1)'
expect_rc 1 "huge printf width"
expect_match "$ERR" "^<expr>:1:9: error: sprintf: format width or precision too large" "its message"

# ---- grids, pictures, points, frames ----
run "$GALE" sample -e '[1, 0, 0]' --bounds 0,0,0,1,1,1 --res 100000 -o g.npy
expect_rc 2 "sample --res 100000"
expect_match "$ERR" "more than the limit of 1073741824" "grid cell limit"
run "$GALE" sample -e '[1, 0, 0]' --bounds 0,0,0,1,1,1 --voxel 1e-9 -o g.npy
expect_rc 2 "sample --voxel 1e-9"
run "$GALE" viz -e '[1, 0, 0]' --plane z=0 --bounds 0,0,1,1 --size 100000x100000 -o v.png
expect_rc 2 "viz --size 100000x100000"
expect_match "$ERR" "from 200x150 to 16384x16384" "picture size limit"
run "$GALE" bench -e '$P' --points 1000000000000
expect_rc 2 "bench --points 10^12"
expect_match "$ERR" "--points must be from 1 to 100000000" "point count limit"
run "$GALE" sample -e '[1, 0, 0]' --bounds 0,0,0,1,1,1 --res 2 --frames 1:1000000000 -o 'f.#.npy'
expect_rc 2 "sample --frames 1:10^9"
expect_match "$ERR" "more than 100000 frames" "frame range limit"
[ -n "$(ls f.*.npy 2>/dev/null)" ] && fail "frames were written"
run "$GALE" eval -e 'fftturb($P, 1, 1, 0, 0, 100000)'
expect_rc 1 "fftturb res 100000"
expect_match "$ERR" "must be 0 \(automatic\) or an even integer from 8 to 512" "fftturb res limit"

# ---- scenes ----
cat > cloth.toml <<'TOML'
[scene]
frames = [1, 2]
[[cloth]]
name = "cape"
grid = { size = [1.0, 1.5], res = [100000, 100000] }
TOML
run "$GALE" sim cloth.toml -o out
expect_rc 1 "cloth grid res 10^5 x 10^5"
expect_match "$ERR" "^cloth.toml:5:35: error: .*grid res must be at most 4096" "at the res array"
sed -i 's/100000, 100000/2000, 2000/' cloth.toml
run "$GALE" sim cloth.toml -o out
expect_rc 1 "cloth grid of 4M vertices"
expect_match "$ERR" "grid res gives 4000000 vertices, more than the limit of 1048576" "vertex limit"
cat > hair.toml <<'TOML'
[scene]
frames = [1, 2]
[[hair]]
name = "fur"
grid = { size = [1, 1], count = [1000, 1000], segments = 12 }
TOML
run "$GALE" sim hair.toml -o out
expect_rc 1 "10^6 strands of 12 segments"
expect_match "$ERR" "^hair.toml:5:8: error: .*13000000 vertices, more than the limit of 1048576" "hair limit"
run "$GALE" sim hair.toml -o out --frames 1:200000
expect_rc 2 "sim --frames beyond 100000 frames"
[ -d out ] && fail "sim wrote output"

# 2x10^5 keyframes are fine.
awk 'BEGIN { printf "[scene]\nframes = [1, 2]\n[windicator]\ndirection = [1, 0, 0]\nspeed = { keys = [";
             for (i = 0; i < 200000; i++) printf "%s[%g, %d]", (i ? ", " : ""), i * 0.001, 3;
             print "] }\n[[field]]\nname = \"w\"\nsource = \"$windDir * $windSpeed\"" }' > keys.toml
run "$GALE" eval keys.toml --time 3.3
expect_rc 0 "2x10^5 keyframes"
expect_eq "$OUT" "3 0 0" "their value"
finish
