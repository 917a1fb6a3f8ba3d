# Wind volumes in and out: `gale sample -o x.vdb` read back by vdb() gives the sampled floats at
# the cell centres; `#` sequences follow --frame (blending between frames); clear errors for
# missing, truncated and wrong-grid files.
source "$(dirname "$0")/lib.bash" "$@"

F='[sin($P[0] * 3) + $P[2], $P[1] * $P[2], cos($P[0] + 2 * $P[1])]'
run "$GALE" sample -e "$F" --bounds -1,0,0.5,1,0.6,1.3 --voxel 0.1 -o x.vdb
expect_rc 0 "sample to .vdb"
run "$GALE" sample -e "$F" --bounds -1,0,0.5,1,0.6,1.3 --voxel 0.1 -o x.csv
expect_rc 0 "sample to .csv"
run "$GALE" eval -e 'vdb("x.vdb", "vel", $P)' --points x.csv -o back.csv
expect_rc 0 "eval vdb() at the cell centres"
expect_eq "$(wc -l < back.csv)" "$(wc -l < x.csv)" "one row per cell"
expect_eq "$(cmp back.csv x.csv && echo same)" "same" "the round trip gives the same floats"
run "$GALE" eval -e 'vdb("x.vdb", "vel", $P, 2)' --points x.csv -o quad.csv
expect_rc 0 "quadratic"
expect_eq "$(cmp quad.csv x.csv && echo same)" "same" "quadratic interpolation too"

# A sequence: frame 1 and frame 3 on disk; frame 2 blends them, outside the range holds.
run "$GALE" sample -e '[$frame, 0, -$frame]' --bounds -1,-1,-1,1,1,1 --res 2 --frames 1:1 -o 'w.#.vdb'
run "$GALE" sample -e '[$frame, 0, -$frame]' --bounds -1,-1,-1,1,1,1 --res 2 --frames 3:3 -o 'w.#.vdb'
expect_eq "$(ls w.*.vdb | tr '\n' ' ')" "w.0001.vdb w.0003.vdb " "two frames"
run "$GALE" eval -e 'vdb("w.#.vdb", "vel", $P)' --frame 2
expect_eq "$OUT" "2 0 -2" "frame 2 blends frames 1 and 3"
run "$GALE" eval -e 'vdb("w.#.vdb", "vel", $P)' --frame 3
expect_eq "$OUT" "3 0 -3" "frame 3"
run "$GALE" eval -e 'vdb("w.#.vdb", "vel", $P)' --frame 10
expect_eq "$OUT" "3 0 -3" "after the last frame: held"

# Errors name the file, at the argument's line and column (exit 1: the expression is wrong).
run "$GALE" eval -e 'vdb("missing.vdb", "vel", $P)'
expect_rc 1 "missing file"
expect_match "$ERR" "^<expr>:1:5: error: cannot read 'missing.vdb'" "missing file message"
head -c 200 x.vdb > trunc.vdb
run "$GALE" eval -e 'vdb("trunc.vdb", "vel", $P)'
expect_rc 1 "truncated file"
expect_match "$ERR" "cannot load 'trunc.vdb'.*truncated or corrupt" "truncated file message"
echo "not a vdb" > text.vdb
run "$GALE" check -e 'vdb("text.vdb", "vel", $P)'
expect_rc 1 "garbage file"
expect_match "$ERR" "cannot load 'text.vdb'" "garbage file message"
run "$GALE" eval -e 'vdb("x.vdb", "density", $P)'
expect_rc 1 "missing grid"
expect_match "$ERR" "no grid named 'density' \(its grids: vel \(vec3s\)\)" "lists the grids"
run "$GALE" eval -e 'vdb("x.vdb", "vel", $P, 5)'
expect_rc 1 "bad interp"
expect_match "$ERR" "<expr>:1:25: error: 'interp' of 'vdb' must be a constant" "interp message"
run "$GALE" eval -e 'vdb("no.#.vdb", "vel", $P)'
expect_rc 1 "empty sequence"
expect_match "$ERR" "no files of the sequence 'no.#.vdb'" "sequence message"

finish
