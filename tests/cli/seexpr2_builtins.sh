#!/usr/bin/env bash
# README's claim that gale has every SeExpr2 built-in: each name in tests/cli/seexpr2_builtins.txt
# (SeExpr2's defineBuiltins(), noise included) must be listed by `gale builtins`.
source "$(dirname "$0")/lib.bash"
export LC_ALL=C # one sort order for sort and comm (getVar)

LIST="$SRC/tests/cli/seexpr2_builtins.txt"
run "$GALE" builtins
expect_rc 0 "gale builtins"
# A built-in's line starts with its result type, then name(parameters); doc lines that wrap
# are indented.
printf '%s\n' "$OUT" | sed -n -E 's/^[^ ]+ ([A-Za-z_][A-Za-z0-9_]*)\(.*/\1/p' | sort -u >"$TMP/gale"
grep -v -E '^[[:space:]]*(#|$)' "$LIST" | sed -E 's/[[:space:]]+$//' >"$TMP/seexpr2"

listed=$(wc -l <"$TMP/seexpr2")
[ "$listed" -ge 99 ] || fail "$LIST lists $listed names; SeExpr2 defines 99"
dups=$(sort "$TMP/seexpr2" | uniq -d)
[ -z "$dups" ] || fail "$LIST names these twice: $dups"
grep -qx abs "$TMP/gale" || fail "could not read the names from 'gale builtins' (no 'abs')"

missing=$(sort -u "$TMP/seexpr2" | comm -23 - "$TMP/gale")
[ -z "$missing" ] || fail "SeExpr2 built-ins missing from 'gale builtins':" $missing

[ "$FAILURES" = 0 ] && echo "seexpr2_builtins: all $listed SeExpr2 built-ins present"
finish
