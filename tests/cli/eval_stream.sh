# `gale eval --points` with CSV in and out streams a chunk of 2^20 points at a time: the bytes
# are those of the in-memory path (--checked to stdout still reads everything first), $id counts
# across chunks, and errors found late still leave no output file.
source "$(dirname "$0")/lib.bash" "$@"

# 1,200,000 points (two chunks): point i is (i, 0.25, -1).
N=1200000
{ echo x,y,z; seq -f '%.0f,0.25,-1' 0 $((N - 1)); } > pts.csv
cat > w.se <<'SE'
$k = 2;  # 0, 10
[$id * 0.5 + $P[1] * $k, $P[0] - $id, noise($P * 0.01)]
SE

run "$GALE" eval w.se --points pts.csv --precision double --checked
expect_rc 0 "in memory (--checked to stdout)"
printf '%s\n' "$OUT" > memory.csv
run "$GALE" eval w.se --points pts.csv --precision double -o streamed.csv
expect_rc 0 "streamed to a file"
cmp -s memory.csv streamed.csv || fail "streamed file differs from the in-memory output"
"$GALE" eval w.se --points - --precision double < pts.csv > piped.csv
cmp -s memory.csv piped.csv || fail "stdin to stdout differs from the in-memory output"
"$GALE" eval w.se --points pts.csv --set k=4 > float.csv
"$GALE" eval w.se --points pts.csv --set k=4 --checked > float_memory.csv
cmp -s float.csv float_memory.csv || fail "float precision: streamed output differs"

# Values derived by hand: vx = i/2 + 0.25*2, vy = 0 (in double), around the chunk boundary.
expect_eq "$(wc -l < streamed.csv)" "$((N + 1))" "every point written once"
expect_eq "$(sed -n 1p streamed.csv)" "x,y,z,vx,vy,vz" "header once"
expect_eq "$(sed -n "$((1048576 + 2))p" streamed.csv | cut -d, -f1-5)" "1048576,0.25,-1,524288.5,0" \
    "first point of the second chunk (\$id continues)"
expect_eq "$(tail -n 1 streamed.csv | cut -d, -f1-5)" "1199999,0.25,-1,6e+05,0" "last point (600000, shortest form)"
expect_eq "$(grep -c '^[0-9.e+]*,0.25,-1,[0-9.e+]*,0,' streamed.csv)" "$N" "vy is 0 everywhere"

# A malformed row in the second chunk: reported at its line, no output file, an old one kept.
sed '1100001s/.*/5,oops,1/' pts.csv > bad.csv
echo old > out.csv
run "$GALE" eval w.se --points bad.csv -o out.csv
expect_rc 1 "malformed row late in the file"
expect_match "$ERR" "^bad.csv:1100001:3: error: expected a number, found 'oops'" "file:line:col"
expect_eq "$(cat out.csv)" "old" "the old output is untouched"
expect_eq "$(ls out.csv.tmp.* 2>/dev/null)" "" "no temporary file left"

# --checked: a non-finite result in the second chunk; counted over all points, nothing written.
run "$GALE" eval -e 'log(1100000.5 - $P[0])' --points pts.csv --precision double --checked -o c.csv
expect_rc 4 "non-finite in the second chunk"
expect_match "$ERR" "99999 of 1200000 point\(s\) gave a non-finite result \(first: point 1100001\)" \
    "count and first point over the whole file"
[ -e c.csv ] && fail "--checked left an output file"

# Header only: the header with the result columns, no rows.
echo 'x,y,z' > empty.csv
run "$GALE" eval -e '$P' --points empty.csv
expect_eq "$OUT" "x,y,z,vx,vy,vz" "no points"
run "$GALE" eval -e '$P' --points - < /dev/null
expect_rc 1 "no header on stdin"

# Standard input already partly read (a regular file): reading goes on from there.
printf 'not csv\nx,y,z\n1,2,3\n' > offset.csv
expect_eq "$({ read -r _; "$GALE" eval -e '$P * 2' --points -; } < offset.csv)" \
    $'x,y,z,vx,vy,vz\n1,2,3,2,4,6' "stdin from its current offset"

# A scene's wind streams too.
head -n 3001 pts.csv > small.csv
"$GALE" eval "$SRC/examples/02_gusts/scene.toml" --points small.csv --time 1 -o scene_s.csv
"$GALE" eval "$SRC/examples/02_gusts/scene.toml" --points small.csv --time 1 --checked > scene_m.csv
cmp -s scene_s.csv scene_m.csv || fail "scene: streamed output differs"
expect_eq "$(wc -l < scene_s.csv)" "3001" "scene rows"
finish
