# `gale sample`: cell-centred values of an analytic field in CSV (stdout and -o), .npy (header,
# shape, float32 data in x-slowest order) and .vdb (magic, grid name, vector type); --set,
# scene files, --res/--voxel geometry and thread-independence.
source "$(dirname "$0")/lib.bash" "$@"

FIELD='[$P[0], 2*$P[1], -$P[2]]'

# 2 x 1 x 1 m at --res 2: N cells along the longest side (x), so cubic 1 m voxels.
run "$GALE" sample -e "$FIELD" --bounds 0,0,0,2,1,1 --res 2
expect_rc 0 "csv to stdout"
expect_eq "$OUT" $'x,y,z,vx,vy,vz\n0.5,0.5,0.5,0.5,1,-0.5\n1.5,0.5,0.5,1.5,1,-0.5' "cell centres and values"

# --voxel 0.5 over 2 x 1 x 1 m from (-1,0,2): 4 x 2 x 2 cells, x slowest, then y, then z.
run "$GALE" sample -e "$FIELD" --bounds -1,0,2,1,1,3 --voxel 0.5 -o g.csv
expect_rc 0 "csv file"
expect_eq "$(wc -l < g.csv | tr -d ' ')" "17" "16 cells and a header"
expect_eq "$(sed -n 2p g.csv)" "-0.75,0.25,2.25,-0.75,0.5,-2.25" "first cell"
expect_eq "$(sed -n 3p g.csv)" "-0.75,0.25,2.75,-0.75,0.5,-2.75" "z varies fastest"
expect_eq "$(sed -n 4p g.csv)" "-0.75,0.75,2.25,-0.75,1.5,-2.25" "then y"
expect_eq "$(sed -n 17p g.csv)" "0.75,0.75,2.75,0.75,1.5,-2.75" "last cell"

# The same grid as .npy: 128-byte header, then 4*2*2*3 float32 little-endian.
run "$GALE" sample -e "$FIELD" --bounds -1,0,2,1,1,3 --voxel 0.5 -o g.npy
expect_rc 0 "npy file"
expect_eq "$(wc -c < g.npy | tr -d ' ')" "$((128 + 4 * 48))" "npy size"
expect_eq "$(head -c 6 g.npy | od -A n -t x1 | tr -d ' \n')" "934e554d5059" "npy magic"
expect_match "$(head -c 128 g.npy | tr -d '\000')" "'descr': '<f4', 'fortran_order': False, 'shape': \(4, 2, 2, 3\)" "npy header"
# Element [2][1][0][:] (x = 0.25, y = 0.75, z = 2.25) starts at float ((2*2 + 1)*2 + 0)*3 = 30.
vals=$(od -A n -t f4 -j $((128 + 30 * 4)) -N 12 g.npy | awk '{print $1+0, $2+0, $3+0}')
expect_eq "$vals" "0.25 1.5 -2.25" "npy element [2][1][0]"

# .vdb: the OpenVDB magic, one grid named vel, contravariant-relative.
run "$GALE" sample -e "$FIELD" --bounds -1,0,2,1,1,3 --voxel 0.5 -o g.vdb
expect_rc 0 "vdb file"
expect_eq "$(head -c 4 g.vdb | od -A n -t x1 | tr -d ' \n')" "20424456" "vdb magic"
grep -aq "contravariant relative" g.vdb || fail "vdb vector type"
grep -aq "vel" g.vdb || fail "vdb grid name"
expect_eq "$(ls | grep -c tmp)" "0" "no temporary files left"

# --format overrides the extension; --res NX,NY,NZ gives exactly those counts.
run "$GALE" sample -e "$FIELD" --bounds 0,0,0,1,1,1 --res 1,2,3 --format csv
expect_eq "$(printf '%s\n' "$OUT" | wc -l | tr -d ' ')" "7" "--res 1,2,3 is 6 cells"
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.25,0.16666666666666666,0.5,0.5,-0.16666667" "anisotropic cell centre"

# --set: a declared parameter is overridden; any other name is bound as a variable.
printf '$speed = 3; # 0, 10\n[$speed, 0, 0]\n' > p.se
run "$GALE" sample p.se --bounds 0,0,0,1,1,1 --res 1 --set speed=5
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.5,0.5,5,0,0" "--set overrides a parameter"
run "$GALE" sample -e '$k * [1, 2, 3]' --bounds 0,0,0,1,1,1 --res 1 --set k=2
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.5,0.5,2,4,6" "--set binds a variable"
run "$GALE" sample -e '$P[0]' --bounds 0,0,0,1,1,1 --res 1
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.5,0.5,0.5,0.5,0.5" "a scalar is promoted"
run "$GALE" sample -e '[$t, $frame, $fps]' --bounds 0,0,0,1,1,1 --res 1 --time 0.5
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.5,0.5,0.5,12,24" "--time sets \$t and \$frame"

# A scene drives it too: its fields summed, --set by dotted path.
cat > s.toml <<'TOML'
[scene]
fps = 30

[[field]]
name = "a"
source = "[1, 0, 0]"

[[field]]
name = "b"
source = "$g = 2;\n[0, $g, $fps]"
TOML
run "$GALE" sample s.toml --bounds 0,0,0,1,1,1 --res 1
expect_rc 0 "scene"
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.5,0.5,1,2,30" "scene fields summed, scene fps"
run "$GALE" sample s.toml --bounds 0,0,0,1,1,1 --res 1 --set field.b.params.g=5
expect_eq "$(printf '%s\n' "$OUT" | sed -n 2p)" "0.5,0.5,0.5,1,5,30" "scene --set"

# Threads do not change a bit.
"$GALE" sample -e 'sin($P * 3) * cos($P[1] * 5 + $P[2])' --bounds -1,-1,-1,1,1,1 --res 24 -o t1.npy --threads 1
"$GALE" sample -e 'sin($P * 3) * cos($P[1] * 5 + $P[2])' --bounds -1,-1,-1,1,1,1 --res 24 -o t2.npy --threads 2
cmp -s t1.npy t2.npy || fail "--threads 1 and 2 differ"

finish
