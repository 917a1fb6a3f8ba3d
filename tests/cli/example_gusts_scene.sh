# examples/02_gusts: the scene checks clean, evaluates at the origin and at points, and its
# gust fronts arrive on time (closed form with spread and turbulence switched off).
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/02_gusts"

run "$GALE" check "$EX/scene.toml"
expect_rc 0 "the example scene checks clean"
expect_eq "$OUT$ERR" "" "silently"

run "$GALE" eval "$EX/scene.toml" --time 1
expect_rc 0 "the example at the origin"
expect_match "$OUT" '^[0-9.e+-]+ [0-9.e+-]+ [0-9.e+-]+$' "three numbers"

run "$GALE" eval "$EX/scene.toml" --points "$SRC/examples/01_breeze/points.ply" --frame 60 -o cape.ply
expect_rc 0 "the example on the breeze points"
expect_match "$(head -c 600 cape.ply | tr -d '\0')" "element vertex 3231" "every point written"

# t = 1.8 s, along +x: windicator speed 3 + 3 * smooth(0.9) = 5.916; the first gust (start
# 0.5, 8 m/s; attack 0.3, hold 0.4, decay 0.8) has local time 1.3 - x/8 at x.
run "$GALE" eval "$EX/scene.toml" --points "$EX/line.csv" --time 1.8 --precision double \
    --set field.main.params.turbulence=0 --set field.main.params.spread=0 \
    --set windicator.direction=1,0,0
expect_rc 0 "closed-form run"
want="0 6.69725
4 10.70115625
8 10.916
12 5.916
16 5.916
20 5.916
24 5.916"
got=$(printf '%s\n' "$OUT" | tail -n +2 | awk -F, '{ print $1, $4, $5, $6 }')
bad=$(paste -d' ' <(printf '%s\n' "$got") <(printf '%s\n' "$want") | awk '
    { if ($1 != $5) { print "x " $1 " vs " $5; next }
      d = $2 - $6; if (d < 0) d = -d; if (d > 1e-9 || $3 != 0 || $4 != 0) print $0 }')
expect_eq "$bad" "" "gust arrival along the line (x vx vy vz | x want)"

# The second gust (start 2, 12 m/s) reaches x = 24 two seconds after it starts.
run "$GALE" eval "$EX/scene.toml" --points "$EX/line.csv" --time 4 --precision double \
    --set field.main.params.turbulence=0 --set field.main.params.spread=0 \
    --set windicator.direction=1,0,0 --set gust.first.strength=0
before=$(printf '%s\n' "$OUT" | tail -n 1 | awk -F, '{ print $4 }')
run "$GALE" eval "$EX/scene.toml" --points "$EX/line.csv" --time 4.1 --precision double \
    --set field.main.params.turbulence=0 --set field.main.params.spread=0 \
    --set windicator.direction=1,0,0 --set gust.first.strength=0
after=$(printf '%s\n' "$OUT" | tail -n 1 | awk -F, '{ print $4 }')
expect_eq "$before" "5" "just arriving at x = 24 at t = 4 (speed 5 at the last key)"
expect_match "$after" '^[6-9]\.' "arrived by t = 4.1"

finish
