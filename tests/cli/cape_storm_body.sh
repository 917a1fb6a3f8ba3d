# A cape on a skinned character in a 12 m/s crosswind, with self-collision, as a TD would run it:
# studio frames 1001-1072 (time_zero), a body sequence with a frame of handle on each side
# (files 1000-1073), 16 frames of pre-roll, four substeps (lbs_character.py: the character, its
# walk and its cape). Measured from the output OBJs each frame, independently of gale: cape
# vertices inside the body (winding number), cape edges through body triangles and body edges
# through cape triangles (a segment-triangle test), and the largest edge stretch. Before, the
# self-collision pass pushed a fold of the cape into the head at the jaw (its corrections moved
# vertices no collider saw again): from frame 1019 to the end 821 vertex-frames inside, 6,923
# crossings, stretch 3.0, and nothing reported. The pass that pushes cloth through a moving body
# is now redone at half the step (docs/solver.md, "Self-collision").
source "$(dirname "$0")/lib.bash" "$@"
PY=$(test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
"$PY" -c 'import numpy' 2> /dev/null || { echo "SKIP: python3 with numpy is not installed (make deps installs python3-numpy)"; exit 0; }
run "$PY" "$SRC/tests/cli/lbs_character.py" . 1000 1073
expect_rc 0 "lbs_character.py"
cat > storm.toml <<'TOML'
[scene]
fps = 24
frames = [1001, 1072]
time_zero = 1001
preroll = 16
substeps = 4
gravity = [0, -9.81, 0]
air_density = 1.225

[windicator]
direction = [1, 0.3, -0.4]
speed = 12

[[field]]
name = "wind"
preset = "wind"
params = { spread = 8, turbulence = 0.2, turbulenceScale = 0.5 }

[[cloth]]
name = "cape"
mesh = "cape.obj"
self_collision = true
thickness = 0.006
density = 0.3
stretch = 4000.0
shear = 200.0
bend = 0.001
damping = 0.005
attach = { mesh = "body.%04d.obj", vertices = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14] }

[[collider]]
name = "body"
type = "mesh"
mesh = "body.####.obj"
rest_mesh = "rest.obj"
thickness = 0.01
friction = 0.3
TOML
run "$GALE" sim storm.toml -o out
expect_rc 0 "the cape in the storm, 72 frames and 16 of pre-roll"
expect_match "$(head -c 20 out/run.json)" '"status": "ok"' "run.json says ok"

cat > measure.py <<'PY'
import json, statistics, sys
import numpy as np
out = sys.argv[1]
def load(path):
    V, F = [], []
    for line in open(path):
        w = line.split()
        if w and w[0] == "v":
            V.append([float(x) for x in w[1:4]])
        elif w and w[0] == "f":
            idx = [int(x.split("/")[0]) - 1 for x in w[1:]]
            F += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
    return np.array(V), np.array(F, int)
def winding(P, V, T):  # generalised winding number of each point (Jacobson et al. 2013)
    a, b, c = (V[T[:, k]][None] - P[:, None] for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
    det = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
    dot = lambda x, y: np.einsum("ijk,ijk->ij", x, y)
    den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb
    return (2 * np.arctan2(det, den)).sum(1) / (4 * np.pi)
def crossings(P0, P1, A, B, C):  # segments P0P1 through triangles ABC (Möller–Trumbore)
    smin, smax = np.minimum(P0, P1), np.maximum(P0, P1)
    tmin, tmax = np.minimum(np.minimum(A, B), C), np.maximum(np.maximum(A, B), C)
    n = 0
    for s0 in range(0, len(P0), 256):
        ov = np.all((smin[s0:s0 + 256, None] <= tmax[None]) & (smax[s0:s0 + 256, None] >= tmin[None]), axis=2)
        I, J = np.nonzero(ov)
        I = I + s0
        d = P1[I] - P0[I]
        e1, e2 = B[J] - A[J], C[J] - A[J]
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-14
        inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
        s = P0[I] - A[J]
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = np.einsum("ij,ij->i", d, q) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        n += int((ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)).sum())
    return n
def edges(T):
    return np.unique(np.sort(np.r_[T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]], 1), axis=0)
R, CT = load("cape.obj")
CE = edges(CT)
rest = np.linalg.norm(R[CE[:, 0]] - R[CE[:, 1]], axis=1)
inside = cross = 0
stretch = 0.0
for F in range(1001, 1073):
    BV, BT = load("body.%04d.obj" % F)
    X, _ = load("%s/cape.%d.obj" % (out, F))
    inside += int((np.abs(winding(X, BV, BT)) > 0.5).sum())
    BE = edges(BT)
    cross += crossings(X[CE[:, 0]], X[CE[:, 1]], BV[BT[:, 0]], BV[BT[:, 1]], BV[BT[:, 2]])
    cross += crossings(BV[BE[:, 0]], BV[BE[:, 1]], X[CT[:, 0]], X[CT[:, 1]], X[CT[:, 2]])
    stretch = max(stretch, float((np.linalg.norm(X[CE[:, 0]] - X[CE[:, 1]], axis=1) / rest).max()))
# The frames' work, a count from run.json: substeps taken and rejected, all bodies; the worst
# frame's over the median frame's (the first frame is the start, no step).
frames = json.load(open(out + "/run.json"))["frames"][1:]
work = [sum(o["substeps"] + o["rejected_substeps"] for o in f["objects"]) for f in frames]
print(inside, cross, "%.3f" % stretch, "%.2f" % (max(work) / statistics.median(work)))
PY
check_shot() { # OUTDIR WHAT
    run "$PY" measure.py "$1"
    expect_rc 0 "the measurement of $2 ($ERR)"
    read -r inside cross stretch work <<< "$OUT"
    expect_eq "$inside" "0" "$2: cape vertex-frames inside the body"
    expect_eq "$cross" "0" "$2: cape-body crossings over the 72 frames"
    awk -v s="$stretch" 'BEGIN { exit !(s < 1.5) }' || fail "$2: the cape's largest stretch below 1.5 (got $stretch)"
    # Halving a pass that halving does not help (docs/solver.md, "Self-collision") made one
    # frame take 9.5× the median's substeps here, and the plume's shot 8.25×; now 2.75× and
    # 1.0× (with the portable kernels, another chaotic path through the same shot, 5.5× and
    # 2.5×: halvings that helped).
    awk -v w="$work" 'BEGIN { exit !(w <= 6) }' ||
        fail "$2: the worst frame's substeps (taken and rejected) within 6× the median frame's (got ${work}×)"
}
check_shot out "the storm"

# The plume on the cape as well, in a gusting tailwind: the hair lies between the cape and the
# body, which the cape does not feel; the pass pushing it out stretched it as much at every
# halved step (three halvings in frame 1005, hair 1.18×).
sed -e 's/^direction = .*/direction = [1, 0, 0.2]/' \
    -e 's/^speed = 12$/speed = { keys = [[0, 3.0], [1.0, 7.0], [2.0, 4.0], [2.9, 6.0]], interp = "smooth" }/' \
    storm.toml > plume.toml
cat >> plume.toml <<'TOML'

[[hair]]
name = "plume"
strands = "hair.csv"
radius = 4e-5
density = 1300.0
stretch = 500.0
bend = 2e-6
damping = 0.01
attach = { mesh = "body.$F4.obj" }
collide_cloth = true
TOML
run "$GALE" sim plume.toml -o plume
expect_rc 0 "the cape and the plume, 72 frames and 16 of pre-roll"
expect_match "$(head -c 20 plume/run.json)" '"status": "ok"' "run.json says ok (plume)"
check_shot plume "the plume's shot"
hair=$("$PY" -c 'import json; print(max(o["max_stretch"] for f in json.load(open("plume/run.json"))["frames"] for o in f["objects"] if o["name"] == "plume"))')
# (1.09 here; 1.33 with the portable kernels, where the pass pushing it out of the cape, which
# does not feel it, stretched it over four intervals of frame 1003: not an over-stretch.)
awk -v s="$hair" 'BEGIN { exit !(s < 1.5) }' || fail "the plume's largest stretch below 1.5× (got $hair)"
finish
