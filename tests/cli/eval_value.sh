# `gale eval` without --points: one line, components separated by single spaces, shortest
# round-trip numbers, strings raw; time, frame, fps, --set and --type.
source "$(dirname "$0")/lib.bash" "$@"

run "$GALE" eval -e '[1,2,3]'
expect_rc 0 "vector"
expect_eq "$OUT" "1 2 3" "vector output"

run "$GALE" eval -e 7
expect_eq "$OUT" "7" "integer prints without .0"

run "$GALE" eval -e '1/3' --precision double
expect_eq "$OUT" "0.3333333333333333" "1/3 in double round-trips"
run "$GALE" eval -e '1/3' --precision float
expect_eq "$OUT" "0.33333334" "1/3 in float: the shortest text of the float"
# A single value defaults to double (SeExpr2's numbers): sin(1) to 17 significant digits.
run "$GALE" eval -e 'sin(1)'
expect_eq "$OUT" "$(printf '%s' 0.8414709848078965)" "a single value is evaluated in double by default"

run "$GALE" eval -e '0.1' --precision double
expect_eq "$OUT" "0.1" "0.1"
run "$GALE" eval -e '1e-7' --precision double
expect_eq "$OUT" "1e-07" "1e-7"

run "$GALE" eval -e '"hi"'
expect_rc 0 "string"
expect_eq "$OUT" "hi" "a string prints raw"

run "$GALE" eval -e '$P'
expect_eq "$OUT" "0 0 0" "\$P is the origin without points"

run "$GALE" eval -e '[$t, $frame, $fps]' --time 0.5
expect_eq "$OUT" "0.5 12 24" "--time gives \$frame = t * fps"
run "$GALE" eval -e '[$t, $frame, $fps]' --frame 12 --fps 48
expect_eq "$OUT" "0.25 12 48" "--frame gives \$t = frame / fps"
run "$GALE" eval -e '[$t, $frame]' --frame 3 --time 7
expect_eq "$OUT" "7 3" "both given: both used as is"

run "$GALE" eval -e '$a * $b' --set a=2 --set b=1,2,3
expect_eq "$OUT" "2 4 6" "--set scalar and vector"
run "$GALE" eval -e '$name + "!"' --set "name='wind'"
expect_eq "$OUT" "wind!" "--set quoted string"
run "$GALE" eval -e 'getVar("speed", 4)'
expect_eq "$OUT" "4" "getVar default"
run "$GALE" eval -e 'getVar("speed", 4)' --set speed=6
expect_eq "$OUT" "6" "getVar of a --set variable"

run "$GALE" eval -e '2' --type vector
expect_eq "$OUT" "2 2 2" "--type vector promotes a scalar"
run "$GALE" eval -e '[1,2,3]' --type float
expect_rc 1 "--type float with a vector result is an error"

printf '# a comment\n$P + 1\n' > e.se
run "$GALE" eval e.se
expect_eq "$OUT" "1 1 1" "expression file"
run "$GALE" eval - < e.se
expect_eq "$OUT" "1 1 1" "expression from stdin"

run "$GALE" eval -e '[1,2]' -o value.txt
expect_rc 0 "-o without points"
expect_eq "$OUT" "" "nothing on stdout with -o"
expect_eq "$(cat value.txt)" "1 2" "-o writes the value line"

run "$GALE" eval -e 'a = printf("t=%g\n", $t); 5' --time 2
expect_eq "$OUT" "5" "printf does not go to stdout"
expect_match "$ERR" "t=2" "printf goes to stderr"

run "$GALE" eval -e '$P * 2' --disasm
expect_rc 0 "--disasm"
[ -n "$OUT" ] || fail "--disasm prints the bytecode"

run "$GALE" --version
expect_rc 0 "--version"
expect_match "$OUT" "^gale [0-9]+\.[0-9]+" "--version prints the version"

run "$GALE" --help
expect_rc 0 "--help"
for cmd in check eval bench builtins; do expect_match "$OUT" "^  $cmd " "--help lists $cmd"; done
run "$GALE" eval --help
expect_rc 0 "eval --help"
for flag in --points --time --frame --fps --set --type --precision --threads --output --format --disasm --checked; do
    expect_match "$OUT" "$flag" "eval --help documents $flag"
done

finish
