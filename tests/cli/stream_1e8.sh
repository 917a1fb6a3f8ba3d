#!/usr/bin/env bash
# `gale eval --points - -o -` streams: 10^8 CSV points from a pipe (GNU seq, no file on disk)
# are evaluated and written to a pipe with peak resident memory under 500 MB. Labelled heavy
# (about 1.5 minutes of CPU on one core). STREAM_POINTS overrides the count for a quick run.
source "$(dirname "$0")/lib.bash" "$@"

N=${STREAM_POINTS:-100000000}
if [ ! -x /usr/bin/time ]; then
    apt-get install -y -qq time >/dev/null 2>&1 || { echo "skipped: /usr/bin/time missing"; exit 0; }
fi

# Point i is (i, 0.5, 2): in double, $P[0] - $id is exactly 0, so every output line is
# "i,0.5,2,0,2,3" and the values are checked without a second evaluator.
{ echo x,y,z; seq -f '%.0f,0.5,2' 0 $((N - 1)); } |
    /usr/bin/time -v -o "$TMP/time.txt" "$GALE" eval -e '[$P[0] - $id, $P[1] * 4, 3]' \
        --precision double --points - -o - 2>"$TMP/err.txt" |
    tee -p >(head -n 2 >"$TMP/head.txt") >(grep -c ',0\.5,2,0,2,3$' >"$TMP/count.txt") |
    tail -n 1 >"$TMP/tail.txt"
# The process substitutions may still be writing.
for _ in $(seq 100); do [ -s "$TMP/count.txt" ] && [ -s "$TMP/head.txt" ] && break; sleep 0.2; done
expect_eq "$(cat "$TMP/count.txt")" "$N" "every point evaluated, with the expected values"
expect_eq "$(cat "$TMP/head.txt")" "$(printf 'x,y,z,vx,vy,vz\n0,0.5,2,0,2,3')" "header and first point"
expect_eq "$(cat "$TMP/tail.txt")" "$((N - 1)),0.5,2,0,2,3" "last point (its \$id is N-1)"
expect_eq "$(cat "$TMP/err.txt")" "" "no messages"
rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$TMP/time.txt")
wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$TMP/time.txt")
echo "points: $N  peak RSS: ${rss} kB  wall: $wall"
[ -n "$rss" ] && [ "$rss" -lt 512000 ] || fail "peak RSS ${rss} kB, wanted under 500 MB"
finish
