# examples/09_walking_cape, run in full as shipped: make_body.py writes the walking body's OBJ
# sequence, the scene checks clean and simulates all 48 frames; no cape vertex ends inside the
# moving body at any frame, the collar keeps its distance to the shoulders (it is attached), the
# cape travels with the walker, and without the collider the legs pass through the cape.
source "$(dirname "$0")/lib.bash" "$@"
command -v python3 > /dev/null || { echo "SKIP: python3 is not installed (make_body.py needs it)"; exit 0; }
mkdir ex
cp "$SRC/examples/09_walking_cape/"{scene.toml,shelter.se,make_body.py} ex/
cd ex || exit 1

run python3 make_body.py body
expect_rc 0 "make_body.py"
[ -s body/body.0048.obj ] || fail "body/body.0048.obj written"

run "$GALE" check scene.toml
expect_rc 0 "the scene checks clean"
run "$GALE" sim scene.toml -o out
expect_rc 0 "the walking cape, 48 frames"
expect_no_match "$(cat out/run.json)" '"failed": true' "no frame failed"

# depth F DIR: the cape's vertices' signed distances to the body at frame F (negative inside).
depth() {
    run "$GALE" eval -e 'sdf("body/body.#.obj", $P, 0.02)' --frame "$1" --points "$2/cape.$(printf %04d "$1").obj" \
        --precision double
    expect_rc 0 "distances at frame $1"
    tail -n +2 <<< "$OUT" | awk -F, '{ print $4 }'
}
# (The SDF at 2 cm voxels is within about 5 mm of the mesh; the cape keeps 1 cm off it.)
for f in 12 24 36 48; do
    inside=$(depth $f out | awk '$1 < -0.005 { n++ } END { print n + 0 }')
    expect_eq "$inside" "0" "no cape vertex inside the body at frame $f"
done

# The collar (the top row, 13 vertices: the middle 9 attached between the arms) keeps its
# distance to the body: attached points move with the surface.
d1=$(depth 1 out | tail -n 13 | sed -n 3,11p)
d48=$(depth 48 out | tail -n 13 | sed -n 3,11p)
drift=$(paste <(echo "$d1") <(echo "$d48") | awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.4f", m }')
awk -v d="$drift" 'BEGIN { exit !(d < 0.006) }' || fail "the attached collar keeps its distance to the body: drift $drift m"

# The cape went along: its mean position moved about as far as the walker (1.1 m/s for 2 s).
moved=$(awk 'FNR == NR && /^v / { x[++n] = $2; z[n] = $4; next }
             /^v / { m++; sx += $2 - x[m]; sz += $4 - z[m] } END { printf "%.3f", sqrt((sx / m)^2 + (sz / m)^2) }' \
    out/cape.0001.obj out/cape.0048.obj)
awk -v d="$moved" 'BEGIN { exit !(d > 1.2 && d < 2.5) }' || fail "the cape travelled with the body: $moved m"

# Without the collider the swinging legs pass through the cape somewhere.
awk '/^\[\[collider\]\]/ { skip = 1 } /^\[/ && !/^\[\[collider\]\]/ { skip = 0 } !skip' scene.toml > nobody.toml
run "$GALE" sim nobody.toml -o open
expect_rc 0 "the same cape without the collider"
through=0
for f in 24 36 48; do
    through=$((through + $(depth $f open | awk '$1 < -0.005 { n++ } END { print n + 0 }')))
done
[ "$through" -gt 0 ] || fail "without the collider some cape vertex ends inside the body (got $through)"

run "$GALE" viz scene.toml --sim out --frames 30:30 --plane x=0 --size 320x280 -o 'p.#.png'
expect_rc 0 "a preview"
[ -s p.0030.png ] || fail "p.0030.png written"
finish
