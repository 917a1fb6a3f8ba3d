# examples/10_hair_turn, run in full as shipped: make_head.py writes the turning, nodding head's
# OBJ sequence and the strands; the scene checks clean and simulates all 48 frames without a
# halved substep; every hair root stays within 1 mm of where the head's rigid motion carries it
# (measured from the OBJ sequence itself: three head vertices give its frame at every frame), no
# hair vertex is inside the head, the strands keep their lengths (contact does not fight the
# springs), the hair swings with the head, and without the collider hair passes through it.
source "$(dirname "$0")/lib.bash" "$@"
command -v python3 > /dev/null || { echo "SKIP: python3 is not installed (make_head.py needs it)"; exit 0; }
mkdir ex
cp "$SRC/examples/10_hair_turn/"{scene.toml,make_head.py} ex/
cd ex || exit 1

run python3 make_head.py head
expect_rc 0 "make_head.py"
[ -s head/head.0048.obj ] && [ -s hair.csv ] || fail "head/head.0048.obj and hair.csv written"

run "$GALE" check scene.toml
expect_rc 0 "the scene checks clean"
run "$GALE" sim scene.toml -o out
expect_rc 0 "the hair on the turning head, 48 frames"
expect_no_match "$(cat out/run.json)" '"failed": true' "no frame failed"
expect_no_match "$(cat out/run.json)" '"(rejected_substeps|deepest_halving)": [1-9]' "no substep halved"

# Roots, lengths and the swing, from the head OBJs and the rest strands (hair.csv).
cat > measure.py <<'PY'
import math, sys
head, out, csv = sys.argv[1:4]
def obj(path):
    v = []
    for line in open(path):
        p = line.split()
        if p and p[0] == "v":
            v.append(tuple(map(float, p[1:4])))
    return v
sub = lambda a, b: tuple(x - y for x, y in zip(a, b))
dot = lambda a, b: sum(x * y for x, y in zip(a, b))
def unit(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a)
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
rest = [tuple(map(float, l.split(","))) for l in open(csv).read().split("\n")[1:] if l]
ids = [int(r[3]) for r in rest]
roots = [k for k in range(len(ids)) if k == 0 or ids[k] != ids[k - 1]]
ends = roots[1:] + [len(ids)]
b1 = obj("%s/head.0001.obj" % head)
# The head's frame from three of its vertices (the crown, the left- and front-most at frame 1):
# the sequence is rigid, so a rest-pose point p goes to o(F) + R(F) R(1)ᵀ (p − o(1)).
I = [max(range(len(b1)), key=lambda n: b1[n][c]) for c in (1, 0, 2)]
def frame(v):
    e1 = unit(sub(v[I[1]], v[I[0]]))
    e3 = unit(cross(e1, sub(v[I[2]], v[I[0]])))
    return v[I[0]], (e1, cross(e3, e1), e3)
o1, R1 = frame(b1)
local = {r: [dot(sub(rest[r][:3], o1), e) for e in R1] for r in roots}
root_err = stretch = 0.0
tips = {}
for F in range(1, 49):
    o, R = frame(obj("%s/head.%04d.obj" % (head, F)))
    h = obj("%s/hair.%04d.obj" % (out, F))
    if len(h) != len(rest):
        sys.exit("frame %d: %d hair vertices, wanted %d" % (F, len(h), len(rest)))
    for r in roots:
        want = tuple(o[c] + sum(local[r][m] * R[m][c] for m in range(3)) for c in range(3))
        root_err = max(root_err, math.dist(want, h[r]))
    for r, e in zip(roots, ends):
        for k in range(r, e - 1):
            stretch = max(stretch, abs(math.dist(h[k], h[k + 1]) / math.dist(rest[k][:3], rest[k + 1][:3]) - 1))
    # The mean tip's direction about the neck (x, z), to see the hair swing with the head.
    tx = sum(h[e - 1][0] for e in ends) / len(ends)
    tz = sum(h[e - 1][2] for e in ends) / len(ends)
    tips[F] = math.degrees(math.atan2(tx, -tz))
print("%.3e %.4f %.1f %.1f" % (root_err, stretch, max(tips.values()), min(tips.values())))
PY
run python3 measure.py head out hair.csv
expect_rc 0 "the root and length check ($ERR)"
read -r root_err stretch tip_max tip_min <<< "$OUT"
awk -v e="$root_err" 'BEGIN { exit !(e < 0.001) }' || fail "hair roots follow the scalp within 1 mm: $root_err m"
# (Measured 4.9% with the shipped friction μ = 0.3, where strands slip into the crease under the
# jaw; before friction was implicit in the solve, μ = 0.3 stretched them 2.9×: see README.md.)
awk -v s="$stretch" 'BEGIN { exit !(s < 0.05) }' || fail "no hair segment stretched or squashed 5% or more: $stretch"
# The head turns ±70°: the hanging ends swing round the neck with it (the side wind holds them
# to one side; measured 55° of swing).
awk -v a="$tip_max" -v b="$tip_min" 'BEGIN { exit !(a - b > 30) }' ||
    fail "the hair swings with the head: tips between $tip_min and $tip_max degrees about the neck"

# inside F DIR: hair vertices inside the head at frame F (signed distance below -1 mm at 5 mm
# voxels; the collider keeps them 4 mm off the surface).
inside() {
    run "$GALE" eval -e 'sdf("head/head.#.obj", $P, 0.005)' --frame "$1" --points "$2/hair.$(printf %04d "$1").obj" \
        --precision double
    expect_rc 0 "distances at frame $1"
    tail -n +2 <<< "$OUT" | awk -F, '$4 < -0.001 { n++ } END { print n + 0 }'
}
for f in 6 12 18 24 30 36 42 48; do
    expect_eq "$(inside $f out)" "0" "no hair vertex inside the head at frame $f"
done

# At one substep a frame (a quarter of the shipped four): the same bounds. The head's sweep after
# the solve catches tips the solve did not see coming; before their segments were given back
# (Body::relaxSwept) a tip was left 10.3 % long and another segment 10 % short.
run "$GALE" sim scene.toml -o one --set scene.substeps=1
expect_rc 0 "the hair on the turning head at one substep a frame"
expect_no_match "$(cat one/run.json)" '"failed": true' "no frame failed at one substep a frame"
run python3 measure.py head one hair.csv
expect_rc 0 "the root and length check at one substep a frame ($ERR)"
read -r root_err stretch tip_max tip_min <<< "$OUT"
awk -v e="$root_err" 'BEGIN { exit !(e < 0.001) }' || fail "one substep: roots within 1 mm: $root_err m"
awk -v s="$stretch" 'BEGIN { exit !(s < 0.05) }' ||
    fail "one substep: no hair segment stretched or squashed 5% or more: $stretch"
for f in 6 12 18 24 30 36 42 48; do
    expect_eq "$(inside $f one)" "0" "no hair vertex inside the head at frame $f, one substep a frame"
done

# Without the collider the turning head sweeps through its own hair.
awk '/^\[\[collider\]\]/ { skip = 1 } /^\[/ && !/^\[\[collider\]\]/ { skip = 0 } !skip' scene.toml > nohead.toml
run "$GALE" sim nohead.toml -o open
expect_rc 0 "the same hair without the collider"
through=0
for f in 12 24 36 48; do through=$((through + $(inside $f open))); done
[ "$through" -gt 0 ] || fail "without the collider some hair vertex ends inside the head (got $through)"

run "$GALE" viz scene.toml --sim out --frames 24:24 --plane y=1.6 --size 320x320 -o 'p.#.png'
expect_rc 0 "a preview"
[ -s p.0024.png ] || fail "p.0024.png written"
finish
