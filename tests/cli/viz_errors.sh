# `gale viz` exit codes: 2 bad flags, 1 bad expression or scene, 3 missing input or unwritable
# picture, 4 non-finite velocities (no picture written).
source "$(dirname "$0")/lib.bash" "$@"

F='[1, 0, 0]'
run "$GALE" viz -e "$F" --plane w=0 --bounds 0,0,1,1 -o a.png
expect_rc 2 "bad plane axis"
run "$GALE" viz -e "$F" --plane z --bounds 0,0,1,1 -o a.png
expect_rc 2 "plane without a value"
run "$GALE" viz -e "$F" --bounds 0,0,1 -o a.png
expect_rc 2 "three bounds"
run "$GALE" viz -e "$F" --bounds 0,1,1,0 -o a.png
expect_rc 2 "inverted bounds"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 --size 12x -o a.png
expect_rc 2 "bad size"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 --size 100x100 -o a.png
expect_rc 2 "too small"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 --size 220x160 -o a.png
expect_rc 2 "too small for the axes and legend"
# The refusal names a size that fits (and that size draws).
expect_match "$ERR" "too small for a picture of these bounds with its axes and legend: give --size [0-9]+x[0-9]+ or larger" \
    "too small names the smallest size"
fits=$(printf '%s\n' "$ERR" | grep -oE -- "--size [0-9]+x[0-9]+" | tail -1 | cut -d' ' -f2)
run "$GALE" viz -e "$F" --bounds 0,0,1,1 --size "$fits" -o fits.png
expect_rc 0 "the size the refusal named ($fits)"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 -o a.jpg
expect_rc 2 "unknown picture format"
run "$GALE" viz -e "$F" --bounds 0,0,1,1
expect_rc 2 "no -o"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 --style dots -o a.png
expect_rc 2 "bad style"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 --speed-max -1 -o a.png
expect_rc 2 "negative --speed-max"

run "$GALE" viz -e '[1, 0' --bounds 0,0,1,1 -o a.png
expect_rc 1 "syntax error"
expect_match "$ERR" "^<expr>:1:" "expression diagnostics"
run "$GALE" viz missing.se --bounds 0,0,1,1 -o a.png
expect_rc 3 "missing file"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 -o no/such/dir/a.png
expect_rc 3 "unwritable png"
expect_match "$ERR" "no/such/dir/a.png" "names the file"
run "$GALE" viz -e "$F" --bounds 0,0,1,1 -o no/such/dir/a.svg
expect_rc 3 "unwritable svg"
run "$GALE" viz -e '[1 / ($P[0] - $P[0]), 0, 0]' --bounds -1,-1,1,1 --size 300x300 -o nan.png
expect_rc 4 "non-finite samples"
[ ! -e nan.png ] || fail "a picture was written for a non-finite field"
expect_eq "$(ls -a | grep -c tmp)" "0" "no temporary files left"

finish
