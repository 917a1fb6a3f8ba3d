# scene.preroll (spec cli.md, "Shots"): a studio shot, frames 1001-1024 with time_zero = 1001, whose
# body (a box, an OBJ sequence body.1001.obj ...) is already 2 m from its rest pose and turned 45°
# at the first frame and walks on at 1 m/s while turning 90°/s. The cape was modelled on the rest
# pose (body_rest.obj, the collider's rest_mesh) and attached along its top row. With 24 frames of
# pre-roll the body is eased from its rest pose to its pose and velocity at frame 1001, the cape
# riding along: every attached vertex is within 2 mm of where the body's motion takes it in every
# written frame (computed here from the motion), no edge past 1.2× rest, no cape vertex inside the
# box, and only frames 1001-1024 are written. Without the pre-roll the same scene binds the cape
# against the body 2 m away (the check fails: it can). --frames 1010:1015 pre-rolls and runs up
# from the shot's start; without rest_mesh the sequence's first file is the rest pose.
source "$(dirname "$0")/lib.bash" "$@"
command -v python3 > /dev/null || { echo "SKIP: python3 is not installed"; exit 0; }

cat > make.py <<'PY'
import math, os, sys
cape_pose = sys.argv[1]            # "rest": the cape modelled on the rest pose; else a frame number
os.makedirs("body", exist_ok=True)
fps = 24.0
def pose(F):                       # rest point -> world at frame F: turn about y, then walk +x
    t = (F - 1001) / fps
    a = math.radians(45.0 + 90.0 * t)
    c, s = math.cos(a), math.sin(a)
    return lambda p: (c * p[0] + s * p[2] + 2.0 + 1.0 * t, p[1], -s * p[0] + c * p[2])
ident = lambda p: p
X, Y0, Y1, Z = 0.15, 0.8, 1.4, 0.1
corners = [(x, y, z) for x in (-X, X) for y in (Y0, Y1) for z in (-Z, Z)]
quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
def write(path, T):
    with open(path, "w") as f:
        for p in corners:
            f.write("v %.9f %.9f %.9f\n" % T(p))
        for q in quads:
            f.write("f %d %d %d %d\n" % tuple(i + 1 for i in q))
for F in range(1001, 1026):
    write("body/body.%04d.obj" % F, pose(F))
write("body_rest.obj", ident)
write("body_bad.obj", ident)
with open("body_bad.obj", "a") as f:
    f.write("v 0 0 0\n")
T = ident if cape_pose == "rest" else pose(int(cape_pose))
nx, ny, W, H = 6, 11, 0.26, 0.5
with open("cape.obj", "w") as f:
    for j in range(ny):
        for i in range(nx):
            f.write("v %.9f %.9f %.9f\n" % T((-W / 2 + W * i / (nx - 1), 1.38 - H * (ny - 1 - j) / (ny - 1), -Z - 0.01)))
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = j * nx + i + 1
            f.write("f %d %d %d\nf %d %d %d\n" % (a, a + 1, a + nx + 1, a, a + nx + 1, a + nx))
top = [T((-W / 2 + W * i / (nx - 1), 1.38, -Z - 0.01)) for i in range(nx)]
lo = [min(p[k] for p in top) - 0.005 for k in range(3)]
hi = [max(p[k] for p in top) + 0.005 for k in range(3)]
print("%.9f, %.9f, %.9f, %.9f, %.9f, %.9f" % tuple(lo + hi))
PY

# check CAPE_POSE FIRST LAST OUTDIR: the attached row within 2 mm of the body's motion, every edge
# within 1.2× its rest length (the cape as loaded), no vertex inside the box (1 mm tolerance).
# Prints the worst attachment error, stretch and depth.
check() {
    python3 - "$@" <<'PY'
import math, sys
cape_pose, first, last, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
fps = 24.0
def pose(F, inverse=False):
    t = (F - 1001) / fps
    a = math.radians(45.0 + 90.0 * t)
    c, s = math.cos(a), math.sin(a)
    if inverse:
        return lambda p: (c * (p[0] - 2.0 - t) - s * p[2], p[1], s * (p[0] - 2.0 - t) + c * p[2])
    return lambda p: (c * p[0] + s * p[2] + 2.0 + t, p[1], -s * p[0] + c * p[2])
def obj(path):
    v = [tuple(map(float, l.split()[1:4])) for l in open(path) if l.startswith("v ")]
    f = [tuple(int(w.split("/")[0]) - 1 for w in l.split()[1:]) for l in open(path) if l.startswith("f ")]
    return v, f
start, faces = obj("cape.obj")
edges = {tuple(sorted((f[i], f[(i + 1) % 3]))) for f in faces for i in range(3)}
rest_len = {e: math.dist(start[e[0]], start[e[1]]) for e in edges}
attached = list(range(10 * 6, 11 * 6))
to_rest = (lambda p: p) if cape_pose == "rest" else pose(int(cape_pose), True)
rest = {k: to_rest(start[k]) for k in attached}
worst = stretch = depth = 0.0
for F in range(first, last + 1):
    x, _ = obj("%s/cape.%04d.obj" % (out, F))
    for k in attached:
        worst = max(worst, math.dist(x[k], pose(F)(rest[k])))
    for e in edges:
        stretch = max(stretch, math.dist(x[e[0]], x[e[1]]) / rest_len[e])
    inv = pose(F, True)
    for p in x:
        q = inv(p)     # in the box's frame: inside when within all three slabs
        d = min(0.15 - abs(q[0]), min(q[1] - 0.8, 1.4 - q[1]), 0.1 - abs(q[2]))
        depth = max(depth, d)
print("attach %.6f m, stretch %.4f, depth %.6f m" % (worst, stretch, depth))
sys.exit(0 if worst <= 0.002 and stretch <= 1.2 and depth <= 0.001 else 1)
PY
}

scene() { # PREROLL REST_MESH_LINE BOX
    cat <<EOF2
[scene]
fps = 24
frames = [1001, 1024]
time_zero = 1001
preroll = $1
substeps = 2
[[cloth]]
name = "cape"
mesh = "cape.obj"
lift = 0.0
drag = 0.0
attach = { mesh = "body/body.\$F4.obj", box = [$3] }
[[collider]]
name = "body"
type = "mesh"
mesh = "body/body.%04d.obj"
$2
thickness = 0.005
friction = 0.3
EOF2
}

box=$(python3 make.py rest)
scene 24 'rest_mesh = "body_rest.obj"' "$box" > shot.toml
run "$GALE" sim shot.toml -o out
expect_rc 0 "the pre-rolled shot"
expect_match "$ERR" "frames 977-1001 are simulated first, frames 977-1000 not written \(24 of pre-roll" \
    "stderr says the pre-roll frames are simulated and not written"
run check rest 1001 1024 out
echo "check: $OUT"
expect_rc 0 "pre-roll from the rest pose: the cape rides the body ($OUT)"
expect_eq "$(ls out | grep -c '^cape\..*\.obj$')" 24 "frames 1001-1024 written, nothing of the pre-roll"
[ -e out/cape.1001.obj ] && [ -e out/cape.1024.obj ] || fail "cape.1001.obj and cape.1024.obj are written"
run python3 -c "import json; print(json.load(open('out/run.json'))['settings']['preroll'])"
expect_eq "$OUT" 24 "run.json settings record the pre-roll"

# --frames inside the shot: pre-roll, then the run-up from 1001.
run "$GALE" sim shot.toml --frames 1010:1015 -o mid
expect_rc 0 "--frames 1010:1015 of the pre-rolled shot"
expect_match "$ERR" "frames 977-1010 are simulated first" "the range runs up through the pre-roll"
run check rest 1010 1015 mid
echo "check: $OUT"
expect_rc 0 "--frames 1010:1015: the cape rides the body ($OUT)"
expect_eq "$(ls mid | grep -c '^cape\..*\.obj$')" 6 "only frames 1010-1015 are written"

# Without the pre-roll, the cape modelled on the rest pose binds 2 m from where it hangs.
scene 0 'rest_mesh = "body_rest.obj"' "$box" > nopre.toml
run "$GALE" sim nopre.toml -o nopre
run check rest 1001 1024 nopre
echo "check: $OUT"
expect_rc 1 "without the pre-roll the cape does not follow the body from its rest pose ($OUT)"

# No rest_mesh: the sequence's first file is the rest pose (the cape modelled on frame 1001); the
# pre-roll then only brings the body up to speed.
box=$(python3 make.py 1001)
scene 24 '' "$box" > first.toml
run "$GALE" sim first.toml -o first
expect_rc 0 "the pre-roll from the sequence's first file"
run check 1001 1001 1024 first
echo "check: $OUT"
expect_rc 0 "pre-roll from the first file: the cape rides the body ($OUT)"

# Mistakes: a rest pose of another topology, a negative pre-roll, rest_mesh on a static mesh.
scene 24 'rest_mesh = "body_bad.obj"' "$box" > bad.toml
run "$GALE" sim bad.toml -o bad
expect_rc 1 "a rest_mesh of another topology"
expect_match "$ERR" "bad.toml:17:[0-9]+: .*rest_mesh 'body_bad.obj' has 9 vertices .* the sequence 8" \
    "the error names the key's line and both vertex counts"
scene -3 'rest_mesh = "body_rest.obj"' "$box" > neg.toml
run "$GALE" check neg.toml
expect_rc 1 "a negative pre-roll"
expect_match "$ERR" "neg.toml:5:[0-9]+: .*scene.preroll must be between 0 and 100000" \
    "the error names scene.preroll's line"
sed 's|mesh = "body/body.%04d.obj"|mesh = "body_rest.obj"|' shot.toml > static.toml
run "$GALE" check static.toml
expect_rc 1 "rest_mesh on a static mesh collider"
expect_match "$ERR" "static.toml:17:[0-9]+: .*rest_mesh is the rest pose of a mesh sequence" \
    "the error says rest_mesh is for sequences"
finish
