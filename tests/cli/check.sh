# `gale check`: silent success; every diagnostic as file:line:col: error: message, the source
# line and a caret underline; exit 1 on errors, 3 on unreadable files.
source "$(dirname "$0")/lib.bash" "$@"

printf '# fine\nv = $P * 2;\nv + [0, 1, 0]\n' > good.se
run "$GALE" check good.se
expect_rc 0 "a good file"
expect_eq "$OUT$ERR" "" "check is silent on success"

printf 'a = 1;\nb = a + nosuch;\nb\n' > bad.se
run "$GALE" check bad.se
expect_rc 1 "a bad file"
first=$(printf '%s\n' "$ERR" | sed -n 1p)
expect_match "$first" "^bad.se:2:9: error: " "file:line:col: error: line"
expect_match "$first" "nosuch" "the message names the variable"
expect_eq "$(printf '%s\n' "$ERR" | sed -n 2p)" "    b = a + nosuch;" "the source line"
expect_eq "$(printf '%s\n' "$ERR" | sed -n 3p)" "            ^~~~~~" "the caret underline"
expect_no_match "$ERR" $'\033' "no colour when NO_COLOR is set"

run "$GALE" check good.se bad.se
expect_rc 1 "one bad file among good ones"
run "$GALE" check good.se missing.se bad.se
expect_rc 3 "an unreadable file wins"
expect_match "$ERR" "^bad.se:2:9: error" "the other files are still checked"

run "$GALE" check -e '$speed * 2'
expect_rc 1 "undeclared host variable"
run "$GALE" check -e '$speed * 2' --set speed=3
expect_rc 0 "--set declares a variable"
run "$GALE" check -e '[1,2,3]' --type float
expect_rc 1 "--type float rejects a vector"

printf 'x,y,z,u\n0,0,0,1\n' > p.csv
run "$GALE" check -e '$P * $u'
expect_rc 1 "\$u is unknown without points"
run "$GALE" check -e '$P * $u' --points p.csv
expect_rc 0 "--points declares the columns"

run "$GALE" check
expect_rc 2 "nothing to check"

finish
