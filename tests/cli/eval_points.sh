# `gale eval --points`: CSV, PLY (ascii, binary), OBJ and stdin inputs; the input columns kept
# and vx,vy,vz or value added; extra columns as variables; every output format; atomic -o.
source "$(dirname "$0")/lib.bash" "$@"

printf 'x,y,z,u\n1,2,3,0.5\n4,5,6,2\n' > p.csv

run "$GALE" eval -e '$P * $u' --points p.csv
expect_rc 0 "csv points"
expect_eq "$OUT" $'x,y,z,u,vx,vy,vz\n1,2,3,0.5,0.5,1,1.5\n4,5,6,2,8,10,12' "vector result columns"

run "$GALE" eval -e '$u + $id' --points p.csv
expect_eq "$OUT" $'x,y,z,u,value\n1,2,3,0.5,0.5\n4,5,6,2,3' "scalar result column, \$id"

run "$GALE" eval -e '$P[0] * $k' --points p.csv --set k=10 --precision double
expect_eq "$OUT" $'x,y,z,u,value\n1,2,3,0.5,10\n4,5,6,2,40' "--set with points"

run "$GALE" eval -e '$P + $t' --points - --time 1 < p.csv
expect_rc 0 "points from stdin"
expect_eq "$(printf '%s\n' "$OUT" | sed -n 3p)" "4,5,6,2,5,6,7" "stdin points row"

run "$GALE" eval -e '$P' --points p.csv --type float
expect_rc 1 "--type float with a vector"

# PLY ascii with normals and an extra property; faces are kept in PLY output.
cat > n.ply <<'PLY'
ply
format ascii 1.0
comment a quad with normals
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property uchar weight
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 10
1 0 0 0 0 1 20
1 1 0 0 1 0 30
0 1 0 0 1 0 40
4 0 1 2 3
PLY
run "$GALE" eval -e '$N * $weight' --points n.ply
expect_rc 0 "ply ascii points"
expect_eq "$(printf '%s\n' "$OUT" | sed -n 1p)" "x,y,z,nx,ny,nz,weight,vx,vy,vz" "ply columns"
expect_eq "$(printf '%s\n' "$OUT" | sed -n 4p)" "1,1,0,0,1,0,30,0,30,0" "\$N and \$weight"

run "$GALE" eval -e '$N' --points n.ply -o out.ply
expect_rc 0 "ply output"
header=$(head -c 400 out.ply | tr -d '\000' | sed '/end_header/q')
expect_match "$header" "^format binary_little_endian 1.0$" "binary ply"
expect_match "$header" "^property float vx$" "vx property"
expect_match "$header" "^property float vz$" "vz property"
expect_match "$header" "^property float weight$" "input properties kept"
expect_match "$header" "^element face 1$" "faces kept"

# Binary in, ascii out, read back.
run "$GALE" eval -e '$vx * 2' --points out.ply --format ply-ascii -o back.ply
expect_rc 0 "binary ply input"
expect_match "$(cat back.ply)" "^format ascii 1.0$" "ply-ascii output"
expect_match "$(cat back.ply)" "^4 0 1 2 3$" "ascii faces"
expect_match "$(cat back.ply)" "^0 1 0 0 1 0 40 0 1 0 0$" "ascii vertex row"

# OBJ vertices.
printf 'v 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n' > tri.obj
run "$GALE" eval -e '$P[1] + 1' --points tri.obj
expect_rc 0 "obj points"
expect_eq "$OUT" $'x,y,z,value\n0,0,0,1\n1,0,0,1\n0,2,0,3' "obj output"

# JSON and NPY.
run "$GALE" eval -e '$P[0]' --points p.csv --format json
expect_eq "$OUT" $'[\n  {"x": 1, "y": 2, "z": 3, "u": 0.5, "value": 1},\n  {"x": 4, "y": 5, "z": 6, "u": 2, "value": 4}\n]' "json output"
run "$GALE" eval -e 'log($P[0] - 1)' --points p.csv --format json
expect_match "$OUT" '"value": null' "non-finite values are null in json"

run "$GALE" eval -e '$P' --points p.csv -o v.npy
expect_rc 0 "npy output"
magic=$(head -c 6 v.npy | tail -c 5)
expect_eq "$magic" "NUMPY" "npy magic"
npyheader=$(head -c 128 v.npy | tr -d '\000\001\223')
expect_match "$npyheader" "'descr': '<f4'" "npy dtype"
expect_match "$npyheader" "'shape': \(2, 3\)" "npy holds only the result columns"
expect_eq "$(stat -c %s v.npy)" "$((128 + 2 * 3 * 4))" "npy size"
run "$GALE" eval -e '$u' --points p.csv --format npy -o s.npy
expect_match "$(head -c 128 s.npy | tr -d '\000\001\223')" "'shape': \(2,\)" "scalar npy shape"

# -o is atomic: the output appears complete and no temporary file is left behind.
run "$GALE" eval -e '$P' --points p.csv -o out.csv
expect_rc 0 "-o csv"
expect_eq "$(head -n 1 out.csv)" "x,y,z,u,vx,vy,vz" "-o csv content"
leftovers=$(ls -A | grep -c '\.tmp\.' || true)
expect_eq "$leftovers" "0" "no temporary files left"
run "$GALE" eval -e '$P' --points p.csv -o out.csv --format json
expect_eq "$(head -c 1 out.csv)" "[" "--format wins over the extension"
run "$GALE" eval -e '$P' --points p.csv -o -
expect_eq "$(printf '%s\n' "$OUT" | head -n 1)" "x,y,z,u,vx,vy,vz" "-o - is stdout"

# A failed run leaves an existing output untouched.
printf 'keep\n' > keep.csv
run "$GALE" eval -e '$P' --points missing.csv -o keep.csv
expect_eq "$(cat keep.csv)" "keep" "an error does not touch the output"

# Threads do not change results.
awk 'BEGIN { print "x,y,z"; for (i = 0; i < 5000; i++) printf "%d,%g,%g\n", i, i * 0.5, -i }' > big.csv
"$GALE" eval -e 'sin($P) * $id' --points big.csv --threads 1 -o t1.csv 2>/dev/null
"$GALE" eval -e 'sin($P) * $id' --points big.csv --threads 4 -o t4.csv 2>/dev/null
cmp -s t1.csv t4.csv || fail "results depend on --threads"
expect_eq "$(wc -l < t1.csv)" "5001" "5000 points out"

finish
