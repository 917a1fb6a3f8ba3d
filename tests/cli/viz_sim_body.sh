# gale viz --sim draws what the run used: the moving body (a mesh-sequence collider) at each
# frame's time, grey, and the scene with the run's own --set overrides (recorded in run.json).
source "$(dirname "$0")/lib.bash" "$@"

mkdir -p cache
for ((f = 0; f <= 8; f++)); do
    awk -v x=$(awk -v k=$f 'BEGIN { printf "%.6f", k * 0.05 }') 'BEGIN {
        split("-0.2 0.2", X); split("0.2 0.5", Y); split("-0.2 0.2", Z)
        for (i = 1; i <= 2; i++) for (j = 1; j <= 2; j++) for (k = 1; k <= 2; k++)
            printf "v %.6f %.6f %.6f\n", X[i] + x, Y[j], Z[k]
        print "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4" }' > cache/body.$(printf %04d $f).obj
done
cat > scene.toml <<'EOF2'
[scene]
frames = [0, 8]
substeps = 2

[windicator]
direction = [0, 0, 1]
speed = 2

[[cloth]]
name = "sheet"
grid = { size = [0.6, 0.6], res = [8, 8], origin = [-0.3, 0.6, -0.3], axes = "xz" }
pins = { box = [-0.31, 0.59, -0.31, 0.31, 0.61, -0.29] }

[[collider]]
name = "box"
type = "mesh"
mesh = "cache/body.####.obj"
EOF2
run "$GALE" sim scene.toml -o out --set windicator.speed=6
expect_rc 0 "the run"
expect_match "$(head -c 300 out/run.json)" '"sets": \["windicator.speed=6"\]' "run.json records the overrides"

run "$GALE" viz scene.toml --sim out --frames 2,8 --plane y=1 --style none --no-field -o 'p.#.svg' --size 320x320
expect_rc 0 "pictures of two frames"
expect_match "$ERR" "with the run's overrides: --set windicator.speed=6" "the run's overrides are applied again ($ERR)"
# The same key given here wins, and the message says so (it does not claim the run's value).
run "$GALE" viz scene.toml --sim out --frames 2 --plane y=1 --style none --no-field -o 'q.#.svg' --size 320x320 \
    --set windicator.speed=2
expect_rc 0 "a picture with the wind speed given again"
expect_no_match "$ERR" "with the run's overrides" "no claim that the run's speed is drawn ($ERR)"
expect_match "$ERR" "the run's --set windicator.speed=6 replaced by this command's --set" "the replaced override is said"
# The same entry spelled by name in one command and by index in the other is the same key.
run "$GALE" sim scene.toml -o named --frames 1:2 --set cloth.sheet.drag=0.5
expect_rc 0 "a run with an override by name"
run "$GALE" viz scene.toml --sim named --frames 2 --plane y=1 --style none --no-field -o 'r.#.svg' --size 320x320 \
    --set cloth.0.drag=2
expect_rc 0 "a picture with the override by index"
expect_no_match "$ERR" "with the run's overrides" "no claim that the run's drag is drawn ($ERR)"
expect_match "$ERR" "the run's --set cloth.sheet.drag=0.5 replaced by this command's --set" "the replaced override is said, by index ($ERR)"
# The body's fills are grey: red = green, blue a little below (cloth is blue, text and frame
# are blue-grey). Their leftmost x in the picture follows the body, which moved 0.3 m along +x.
body_left() {
    sed -E -n 's/.*fill:rgb\(([0-9.]+)%,([0-9.]+)%,([0-9.]+)%\).* d="M ([0-9.]+) .*/\1 \2 \3 \4/p' "$1" |
        awk '$1 == $2 && $3 < $1 { n++; if (n == 1 || $4 < x) x = $4 }
             END { if (n) printf "%d %.1f", n, x; else print "0 0" }'
}
read n2 x2 <<< "$(body_left p.0002.svg)"
read n8 x8 <<< "$(body_left p.0008.svg)"
[ "$n2" -gt 0 ] || fail "frame 2 draws the body"
[ "$n8" -gt 0 ] || fail "frame 8 draws the body"
awk -v a="$x2" -v b="$x8" 'BEGIN { exit !(b > a + 10) }' || fail "the body is drawn where it is at each frame (left edge at x = $x2 px, then $x8 px)"
finish
