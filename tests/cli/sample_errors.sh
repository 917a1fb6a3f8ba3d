# `gale sample` exit codes: 2 bad flags, 1 bad expression or scene (file:line:col), 3 missing
# input or unwritable output, 4 non-finite velocities (and then no file at all).
source "$(dirname "$0")/lib.bash" "$@"

F='[1, 0, 0]'
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1 --res 2
expect_rc 2 "five bounds"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,one,1 --res 2
expect_rc 2 "non-numeric bound"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,0,1 --res 2
expect_rc 2 "empty box"
expect_match "$ERR" "along y" "names the empty axis"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1
expect_rc 2 "neither --res nor --voxel"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 2 --voxel 0.5
expect_rc 2 "both --res and --voxel"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 0
expect_rc 2 "--res 0"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 1.5
expect_rc 2 "fractional --res"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --voxel -1
expect_rc 2 "negative --voxel"
run "$GALE" sample -e "$F" --bounds 0,0,0,100,100,100 --voxel 0.01
expect_rc 2 "too many cells"
expect_match "$ERR" "limit" "says why"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 2 -o out.txt
expect_rc 2 "unknown output extension"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 2 --format vdb
expect_rc 2 "vdb to stdout"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 2 --format ply
expect_rc 2 "unknown --format"
run "$GALE" sample -e "$F" --res 2
expect_rc 2 "no --bounds"
run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 2 --set 'novalue'
expect_rc 2 "malformed --set"

run "$GALE" sample -e '[1, 0' --bounds 0,0,0,1,1,1 --res 2
expect_rc 1 "syntax error"
expect_match "$ERR" "^<expr>:1:" "expression diagnostics"
run "$GALE" sample -e '[1, 2]' --bounds 0,0,0,1,1,1 --res 2
expect_rc 1 "FP[2] is not a velocity"
printf '$speed = 3;\n[$speed, 0, 0]\n' > p.se
run "$GALE" sample p.se --bounds 0,0,0,1,1,1 --res 2 --set speed=1,2
expect_rc 1 "parameter override of the wrong width"
printf '[scene]\nfps = 24\nbogus = 1\n' > bad.toml
run "$GALE" sample bad.toml --bounds 0,0,0,1,1,1 --res 2
expect_rc 1 "unknown scene key"
expect_match "$ERR" "^bad.toml:3:1: error" "scene diagnostics at file:line:col"
printf '[[field]]\nname = "f"\nsource = "[1, 0"\n' > badexpr.toml
run "$GALE" sample badexpr.toml --bounds 0,0,0,1,1,1 --res 2
expect_rc 1 "bad expression inside a scene"

run "$GALE" sample missing.se --bounds 0,0,0,1,1,1 --res 2
expect_rc 3 "missing expression file"
run "$GALE" sample missing.toml --bounds 0,0,0,1,1,1 --res 2
expect_rc 3 "missing scene file"
for ext in csv npy vdb; do
    run "$GALE" sample -e "$F" --bounds 0,0,0,1,1,1 --res 2 -o "no/such/dir/out.$ext"
    expect_rc 3 "unwritable .$ext"
    expect_match "$ERR" "no/such/dir/out.$ext" "names the file"
done

# A velocity that is not finite anywhere: exit 4, count reported, nothing written.
for ext in csv npy vdb; do
    run "$GALE" sample -e '[1 / ($P[0] - 0.25), 0, 0]' --bounds 0,0,0,1,1,1 --res 2 -o "nan.$ext"
    expect_rc 4 "non-finite .$ext"
    expect_match "$ERR" "4 of 8 cell\(s\)" "non-finite count"
    [ ! -e "nan.$ext" ] || fail "non-finite .$ext was written"
done
# An overflow to infinity counts too.
run "$GALE" sample -e '[1e30 * 1e30, 0, 0]' --bounds 0,0,0,1,1,1 --res 1 -o big.npy
expect_rc 4 "float overflow"
expect_eq "$(ls -a | grep -c tmp)" "0" "no temporary files left"

finish
