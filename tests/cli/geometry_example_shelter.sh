# examples/04_shelter: the scene checks clean, the probes show free air in front and beside,
# shelter behind the body recovering downwind, and `gale viz` draws it.
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/04_shelter"

run "$GALE" check "$EX/scene.toml"
expect_rc 0 "the example checks clean"
expect_eq "$OUT$ERR" "" "silently"

run "$GALE" eval "$EX/scene.toml" --points "$EX/probes.csv" --precision double
expect_rc 0 "the probes"
speed() { sed -n "$1p" <<< "$OUT" | awk -F, '{ printf "%.3f", sqrt($4 * $4 + $5 * $5 + $6 * $6) }'; }
expect_eq "$(speed 2)" "6.000" "in front: the free stream"
expect_eq "$(speed 3)" "6.000" "beside: the free stream"
expect_eq "$(speed 6)" "6.000" "beyond the shadow: the free stream"
front=$(speed 4); mid=$(speed 5)
awk -v a="$front" -v b="$mid" 'BEGIN { exit !(a < 2.0 && a < b && b < 6.0) }' ||
    fail "sheltered behind the back ($front m/s), recovering downwind ($mid m/s)"

run "$GALE" viz "$EX/scene.toml" --plane y=1.2 --bounds -1.5,-2.5,1.5,1.5 --size 400x400 -o top.png
expect_rc 0 "viz"
expect_eq "$(head -c 4 top.png | tail -c 3)" "PNG" "a PNG"

finish
