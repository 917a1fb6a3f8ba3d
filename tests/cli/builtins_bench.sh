# `gale builtins` (text and JSON) and `gale bench` (text and JSON).
source "$(dirname "$0")/lib.bash" "$@"

run "$GALE" builtins
expect_rc 0 "builtins"
expect_match "$OUT" "^FP\[n\] sin\(" "builtins lists sin"
expect_match "$OUT" "curve\(" "builtins lists curve"

run "$GALE" builtins --json
expect_rc 0 "builtins --json"
expect_match "$OUT" '"name": "sin", "signature": "FP\[n\] sin\(' "json entry for sin"
expect_match "$OUT" '"foldable": (true|false)' "json foldable"
if command -v python3 >/dev/null; then
    printf '%s' "$OUT" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert any(e["name"]=="sin" for e in d)' \
        || fail "builtins --json is valid JSON"
fi

run "$GALE" bench -e 'sin($P) * 2' --points 2000 --repeat 2
expect_rc 0 "bench"
expect_match "$OUT" '^ns/point: [0-9.e+-]+  \(points 2000, threads 1, precision float, best of 2\)$' "bench text"

run "$GALE" bench -e '$P * 2' --points 1000 --repeat 2 --json --precision double --threads 2
expect_rc 0 "bench --json"
expect_match "$OUT" '^\{"ns_per_point": [0-9.e+-]+, "points": 1000, "threads": 2, "precision": "double", "runs": 2\}$' "bench json"
if command -v python3 >/dev/null; then
    printf '%s' "$OUT" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["points"]==1000 and d["ns_per_point"]>0' \
        || fail "bench --json is valid JSON"
fi

run "$GALE" bench -e 'nosuch' --points 10
expect_rc 1 "bench of a bad expression"
run "$GALE" bench -e '1' --points 0
expect_rc 2 "bench with no points"

finish
