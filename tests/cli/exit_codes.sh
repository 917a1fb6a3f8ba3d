# Exit codes: 0 ok, 1 input read but wrong, 2 usage, 3 I/O, 4 numerical (eval --checked).
source "$(dirname "$0")/lib.bash" "$@"

run "$GALE" eval -e '1 +'
expect_rc 1 "syntax error"
expect_match "$ERR" "^<expr>:1:" "-e source is named <expr>"
run "$GALE" eval -e 'nosuchvar * 2'
expect_rc 1 "unknown variable"
run "$GALE" eval -e '[1,2] + [1,2,3]'
expect_rc 1 "type error"

run "$GALE"
expect_rc 2 "no subcommand"
run "$GALE" eval --no-such-flag -e 1
expect_rc 2 "unknown flag"
run "$GALE" frobnicate
expect_rc 2 "unknown subcommand"
run "$GALE" eval
expect_rc 2 "no expression"
printf '1\n' > one.se
run "$GALE" eval one.se -e 1
expect_rc 2 "file and -e together"
run "$GALE" eval -e 1 --set 'no value'
expect_rc 2 "malformed --set"
run "$GALE" eval -e 1 --set x=abc
expect_rc 2 "--set with a non-number"
run "$GALE" eval -e 1 --type scalar
expect_rc 2 "bad --type"
run "$GALE" eval -e 1 --precision half
expect_rc 2 "bad --precision"
run "$GALE" eval -e 1 --time soon
expect_rc 2 "non-numeric --time"
run "$GALE" eval -e 1 --format csv
expect_rc 2 "--format without --points"
printf 'x,y,z\n0,0,0\n' > p.csv
run "$GALE" eval -e '$P' --points p.csv -o out.xyz
expect_rc 2 "unknown output extension"
run "$GALE" eval -e '$P' --points p.xyz
expect_rc 2 "unknown point file type"

run "$GALE" eval missing.se
expect_rc 3 "missing expression file"
expect_eq "$ERR" "gale: cannot read 'missing.se': No such file or directory" "missing file message"
run "$GALE" eval -e '$P' --points missing.csv
expect_rc 3 "missing points file"
expect_match "$ERR" "missing.csv.*No such file or directory" "missing points message"
run "$GALE" eval -e '$P' --points p.csv -o no/such/dir/out.csv
expect_rc 3 "unwritable output"
run "$GALE" eval -e '1' -o no/such/dir/out.txt
expect_rc 3 "unwritable value output"
run "$GALE" check missing.se
expect_rc 3 "check of a missing file"

printf 'x,y,z\n1,2,3\n4,five,6\n' > bad.csv
run "$GALE" eval -e '$P' --points bad.csv
expect_rc 1 "bad number in the points"
expect_eq "$ERR" "bad.csv:3:3: error: expected a number, found 'five'" "points error names file:line:col"
printf 'x,y,z\n1,2,3\n4,5\n' > short.csv
run "$GALE" eval -e '$P' --points short.csv
expect_rc 1 "short row"
expect_match "$ERR" "^short.csv:3:.*row has 2 fields" "short row message"
printf 'x,y\n1,2\n' > xy.csv
run "$GALE" eval -e '$P' --points xy.csv
expect_rc 1 "points without z"
run "$GALE" eval -e '"text"' --points p.csv
expect_rc 1 "a string result cannot go to a point file"

printf 'x,y,z\n1,2,3\n-1,0,0\n' > two.csv
run "$GALE" eval -e 'log($P[0])' --points two.csv --checked -o checked.csv
expect_rc 4 "--checked with a NaN"
expect_match "$ERR" "non-finite" "--checked explains"
[ ! -e checked.csv ] || fail "--checked failure writes no output"
run "$GALE" eval -e 'log($P[0])' --points two.csv --checked --precision double
expect_rc 4 "--checked in double"
run "$GALE" eval -e 'log($P[0] + 2)' --points two.csv --checked
expect_rc 0 "--checked with finite results"

finish
