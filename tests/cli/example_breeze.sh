# The 01_breeze example runs as `make demo` runs it, and gives sane velocities.
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/01_breeze"

run "$GALE" check "$EX/breeze.se"
expect_rc 0 "breeze.se checks"

run "$GALE" eval "$EX/breeze.se" --points "$EX/points.ply" --time 0.5 -o breeze.ply
expect_rc 0 "breeze to ply"
header=$(head -c 600 breeze.ply | tr -d '\000' | sed '/end_header/q')
expect_match "$header" "^element vertex 3231$" "all points"
expect_match "$header" "^property float vx$" "vx"
expect_match "$header" "^element face" "cape faces kept"

run "$GALE" eval "$EX/breeze.se" --points "$EX/points.ply" --time 0.5 -o breeze.csv
expect_rc 0 "breeze to csv"
expect_eq "$(head -n 1 breeze.csv)" "x,y,z,vx,vy,vz" "csv header"
expect_eq "$(wc -l < breeze.csv)" "3232" "csv rows"
# Every velocity is finite, blows along +x, and is between 0.5 and 10 m/s.
bad=$(awk -F, 'NR > 1 { s = sqrt($4*$4 + $5*$5 + $6*$6); if (!(s > 0.5 && s < 10 && $4 > 0)) n++ } END { print n + 0 }' breeze.csv)
expect_eq "$bad" "0" "velocities are sane"

run "$GALE" eval "$EX/breeze.se" --time 0.5 --set speed=8
expect_rc 0 "--set a tunable"
expect_match "$OUT" '^[-0-9.e]+ [-0-9.e]+ [-0-9.e]+$' "one line of three numbers"

finish
