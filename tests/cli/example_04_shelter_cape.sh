# examples/04_shelter/cape.toml: a cape on the mannequin's back. In the body's wind shadow it
# moves much less than the same cape with the shelter switched off ($calm = 1: full wind behind
# the body), no vertex ends inside the body (a mesh collider), and a preview renders.
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/04_shelter"

run "$GALE" check "$EX/cape.toml"
expect_rc 0 "the cape scene checks clean"

# Half a second: the windicator rises from 2 to about 5 m/s.
run "$GALE" sim "$EX/cape.toml" -o sheltered --frames 1:12
expect_rc 0 "the sheltered cape"
run "$GALE" sim "$EX/cape.toml" -o open --frames 1:12 --set field.shelter.params.calm=1
expect_rc 0 "the same cape without the shelter"

# Mean distance of the vertices from the rest pose (frame 1), in metres.
moved() {
    awk 'FNR == NR && /^v / { x[++n] = $2; y[n] = $3; z[n] = $4; next }
         /^v / { m++; s += sqrt(($2 - x[m])^2 + ($3 - y[m])^2 + ($4 - z[m])^2) }
         END { printf "%.4f", s / m }' "$1/cape.0001.obj" "$1/cape.0012.obj"
}
a=$(moved sheltered); b=$(moved open)
awk -v a="$a" -v b="$b" 'BEGIN { exit !(a > 0.01 && a < 0.6 * b) }' ||
    fail "the shelter calms the cape: moved $a m sheltered against $b m in the open"

# The collider keeps the cape outside the body (the SDF is negative inside).
run "$GALE" eval -e "sdf(\"$EX/body.obj\", \$P, 0.02)" --points sheltered/cape.0012.obj \
    --allow-path "$EX" --precision double
expect_rc 0 "distances of the last frame"
inside=$(tail -n +2 <<< "$OUT" | awk -F, '$4 < -0.02 { n++ } END { print n + 0 }')
expect_eq "$inside" "0" "no vertex inside the body"

run "$GALE" viz "$EX/cape.toml" --sim sheltered --frames 12:12 --plane x=0 \
    --bounds -1.6,-0.1,0.8,2.1 --size 320x280 -o 'p.#.png'
expect_rc 0 "a preview"
[ -s p.0012.png ] || fail "p.0012.png written"
finish
