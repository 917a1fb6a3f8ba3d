# Attachments bind at the shot's first frame (issue 25): a box body walks 1 m/s along +x and
# turns 90°/s about +y; its OBJ sequence has one frame of handle on each side (files 0–50 for a
# scene of frames 1–49, as caches usually do). A grid cape hangs behind it, its top row attached
# by a box selection, and collides with the same body. Every attached vertex stays within 2 mm
# of where the body's rigid motion takes it, at every frame (computed here from the motion), also
# with --frames 10:30 (which runs up from the scene's first frame, where the cape starts and
# binds); binding against the sequence's first file (frame 0) put them one frame of motion
# (~4 cm) off.
source "$(dirname "$0")/lib.bash" "$@"
command -v python3 > /dev/null || { echo "SKIP: python3 is not installed"; exit 0; }

cat > make.py <<'PY'
import math, os, sys
first = int(sys.argv[1])           # the shot's first frame: the cape is built at the body there
os.makedirs("body", exist_ok=True)
fps = 24.0
def pose(F):                       # rest point -> world at frame F: turn about y, then walk +x
    t = F / fps
    a = math.radians(90.0 * t)
    c, s = math.cos(a), math.sin(a)
    return lambda p: (c * p[0] + s * p[2] + 1.0 * t, p[1], -s * p[0] + c * p[2])
# a box 0.3 × 0.6 × 0.2 m (x, y, z), its back face at z = -0.1, from y = 0.8 to 1.4
X, Y0, Y1, Z = 0.15, 0.8, 1.4, 0.1
corners = [(x, y, z) for x in (-X, X) for y in (Y0, Y1) for z in (-Z, Z)]
quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
for F in range(0, 51):
    T = pose(F)
    with open("body/body.%04d.obj" % F, "w") as f:
        for p in corners:
            f.write("v %.9f %.9f %.9f\n" % T(p))
        for q in quads:
            f.write("f %d %d %d %d\n" % tuple(i + 1 for i in q))
# the cape: 0.26 × 0.5 m, 6 × 11 vertices, 1 cm behind the back face, its top row at y = 1.38
T = pose(first)
nx, ny, W, H = 6, 11, 0.26, 0.5
with open("cape_%d.obj" % first, "w") as f:
    for j in range(ny):
        for i in range(nx):
            f.write("v %.9f %.9f %.9f\n" % T((-W / 2 + W * i / (nx - 1), 1.38 - H * (ny - 1 - j) / (ny - 1), -Z - 0.01)))
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = j * nx + i + 1
            f.write("f %d %d %d\nf %d %d %d\n" % (a, a + 1, a + nx + 1, a, a + nx + 1, a + nx))
# the attach box around the top row at the first frame (world space)
top = [T((-W / 2 + W * i / (nx - 1), 1.38, -Z - 0.01)) for i in range(nx)]
lo = [min(p[k] for p in top) - 0.005 for k in range(3)]
hi = [max(p[k] for p in top) + 0.005 for k in range(3)]
print("%.9f, %.9f, %.9f, %.9f, %.9f, %.9f" % tuple(lo + hi))
PY

check() { # START FIRST LAST OUTDIR: every attached vertex within 2 mm of the body's motion
    python3 - "$1" "$2" "$3" "$4" <<'PY'
import math, sys
start_frame, first, last, out = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
fps = 24.0
def pose(F, inverse=False):
    t = F / fps
    a = math.radians(90.0 * t)
    c, s = math.cos(a), math.sin(a)
    if inverse:
        return lambda p: (c * (p[0] - t) - s * p[2], p[1], s * (p[0] - t) + c * p[2])
    return lambda p: (c * p[0] + s * p[2] + t, p[1], -s * p[0] + c * p[2])
def obj(path):
    return [tuple(map(float, l.split()[1:4])) for l in open(path) if l.startswith("v ")]
start = obj("cape_%d.obj" % start_frame)
attached = list(range(10 * 6, 11 * 6))            # the top row
rest = {k: pose(start_frame, True)(start[k]) for k in attached}
worst = 0.0
for F in range(first, last + 1):
    x = obj("%s/cape.%04d.obj" % (out, F))
    for k in attached:
        want = pose(F)(rest[k])
        worst = max(worst, math.dist(x[k], want))
print("%.6f" % worst)
sys.exit(0 if worst <= 0.002 else 1)
PY
}

box=$(python3 make.py 1)   # the cape at the body's pose at the scene's first frame
cat > scene.toml <<EOF2
[scene]
fps = 24
frames = [1, 49]
substeps = 2
[[cloth]]
name = "cape"
mesh = "cape_1.obj"
lift = 0.0
drag = 0.0
attach = { mesh = "body/body.#.obj", box = [$box] }
[[collider]]
name = "body"
type = "mesh"
mesh = "body/body.#.obj"
thickness = 0.005
friction = 0.3
EOF2
for range in "1:49" "10:30"; do
    first=${range%:*}; last=${range#*:}
    run "$GALE" sim scene.toml --frames "$range" -o "out_$first"
    expect_rc 0 "the cape attached to the walking, turning box, frames $range"
    run check 1 "$first" "$last" "out_$first"
    expect_rc 0 "frames $range: every attached vertex within 2 mm of the body's motion (largest $OUT m)"
done
finish
