# Hair against cloth (issue 27.7): five free strands (0.4 m, 10 segments each) dropped from 0.3 m
# above a self-colliding hammock (0.6 m square, pinned along two opposite edges) land on it at
# 2.4 m/s (5 cm a substep: ten thicknesses) and lie on it as it sags, 24 frames. Counted here from
# the output files, independently of gale: no strand segment crosses a cloth triangle in any
# frame, and every strand vertex ends above the sheet under it. With collide_cloth = false the
# strands fall through (the check can fail).
source "$(dirname "$0")/lib.bash" "$@"
PY=$(test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
"$PY" -c 'import numpy' 2> /dev/null || { echo "SKIP: python3 with numpy is not installed (make deps installs python3-numpy)"; exit 0; }

"$PY" - <<'PY'
with open("plume.csv", "w") as f:
    f.write("x,y,z,strand\n")
    for s in range(5):
        for k in range(11):
            f.write("%.6f,%.6f,%.6f,%d\n" % (-0.2 + 0.04 * k, 1.3, -0.1 + 0.05 * s, s))
pins = [j * 13 + i for j in range(13) for i in (0, 12)]
open("pins.txt", "w").write(", ".join(map(str, pins)))
PY
scene() { # COLLIDE_CLOTH
    cat <<EOF2
[scene]
fps = 24
frames = [1, 24]
substeps = 2
[[cloth]]
name = "sheet"
grid = { size = [0.6, 0.6], res = [13, 13], origin = [-0.3, 1.0, -0.3], axes = "xz" }
density = 0.1
pins = { vertices = [$(cat pins.txt)] }
self_collision = true
thickness = 0.005
[[hair]]
name = "plume"
strands = "plume.csv"
root_pinned = false
collide_cloth = $1
EOF2
}

check() { # OUTDIR: crossings over all frames, and the lowest strand vertex's height over the sheet
    "$PY" - "$1" <<'PY'
import sys
import numpy as np
out = sys.argv[1]
def read(path):
    v, f, l = [], [], []
    for line in open(path):
        w = line.split()
        if not w: continue
        if w[0] == "v": v.append(tuple(map(float, w[1:4])))
        elif w[0] == "f": f.append(tuple(int(x.split("/")[0]) - 1 for x in w[1:4]))
        elif w[0] == "l": l.append([int(x) - 1 for x in w[1:]])
    return np.array(v), f, l
crossings, lowest = 0, 1e9
for F in range(1, 25):
    cv, cf, _ = read("%s/sheet.%04d.obj" % (out, F))
    hv, _, hl = read("%s/plume.%04d.obj" % (out, F))
    segs = [(a, b) for line in hl for a, b in zip(line, line[1:])]
    T = np.array([[cv[i] for i in t] for t in cf])           # (nt, 3, 3)
    for a, b in segs:
        p, q = hv[a], hv[b]
        # Segment against each triangle (Möller–Trumbore, both ways along the segment).
        d = q - p
        e1, e2 = T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]
        h = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, h)
        ok = np.abs(det) > 1e-14
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = p - T[:, 0]
        u = inv * np.einsum("ij,ij->i", s, h)
        qq = np.cross(s, e1)
        v = inv * (qq @ d)
        t = inv * np.einsum("ij,ij->i", e2, qq)
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)
        crossings += int(hit.sum())
    if F == 24:
        # Height of each strand vertex over the sheet below it (the triangle its xz falls in).
        for x in hv:
            for tri in T:
                a, b, c = tri[:, [0, 2]]
                m = np.array([b - a, c - a]).T
                if abs(np.linalg.det(m)) < 1e-14: continue
                w = np.linalg.solve(m, x[[0, 2]] - a)
                if w[0] >= -1e-9 and w[1] >= -1e-9 and w.sum() <= 1 + 1e-9:
                    y = tri[0, 1] + w[0] * (tri[1, 1] - tri[0, 1]) + w[1] * (tri[2, 1] - tri[0, 1])
                    lowest = min(lowest, x[1] - y)
                    break
print("crossings %d, lowest strand vertex %.4f m over the sheet" % (crossings, lowest))
sys.exit(0 if crossings == 0 and lowest > 0.0 else 1)
PY
}

scene true > on.toml
run "$GALE" sim on.toml -o on
expect_rc 0 "the plume on the hammock"
run check on
echo "collide_cloth = true: $OUT"
expect_rc 0 "no strand crosses the sheet and all lie on it ($OUT)"
scene false > off.toml
run "$GALE" sim off.toml -o off
expect_rc 0 "the plume without cloth collision"
run check off
echo "collide_cloth = false: $OUT"
expect_rc 1 "without collide_cloth the strands fall through ($OUT)"

# Strands that start through the sheet: `gale check` warns at the [[hair]] line, counting the
# segments that cross it (five vertical strands through five cells, off their diagonals); the
# plume above it says nothing.
run "$GALE" check on.toml
expect_no_match "$ERR" "starts through" "the plume above the sheet ($ERR)"
"$PY" - <<'PY'
with open("through.csv", "w") as f:
    f.write("x,y,z,strand\n")
    for s in range(5):
        for k in range(11):
            f.write("%.6f,%.6f,%.6f,%d\n" % (-0.3 + 0.05 * (2 * s + 1) + 0.013, 1.21 - 0.04 * k,
                                            -0.3 + 0.05 * 5 + 0.031, s))
PY
sed 's/plume.csv/through.csv/' on.toml > through.toml
run "$GALE" check through.toml
expect_rc 0 "strands through the sheet still check"
expect_match "$ERR" "through.toml:12:1: warning: \\[\\[hair\\]\\] 'plume' starts through \\[\\[cloth\\]\\] 'sheet': 5 segment\\(s\\) cross it" "strands through the sheet ($ERR)"
finish
