#!/usr/bin/env python3
"""A skinned character of our own for the CLI tests (issue 27): a closed body of revolution (an
elliptic profile: hips, chest, shoulders, neck, head; 914 vertices, 1,824 triangles) deformed by
linear-blend skinning on three joints — the root (a yaw and a walk), the spine (a bend and a
sway) and the neck (a twist) — written as an OBJ sequence in studio frame numbers, its rest pose,
a cape modelled on the rest pose (15 × 18 vertices, its collar row 1.5 cm off the neck) and a
plume of hair lying 2.5 cm over the cape. At frame 1001 the body already stands 1.5 m from its
rest pose, turned 60° and bent 25° (a shot that needs its pre-roll).

    lbs_character.py OUTDIR FIRSTFILE LASTFILE [PATTERN]     (PATTERN: body.%04d.obj)"""
import sys, os, math
import numpy as np
out = sys.argv[1]; F0 = int(sys.argv[2]); F1 = int(sys.argv[3])
pat = sys.argv[4] if len(sys.argv) > 4 else "body.%04d.obj"
os.makedirs(out, exist_ok=True)
NU = 24
# profile control points: y, a (x half width), b (z half depth)
prof = np.array([
 [0.86, 0.00, 0.00], [0.87, 0.10, 0.07], [0.90, 0.16, 0.105], [1.00, 0.17, 0.11], [1.20, 0.17, 0.11],
 [1.38, 0.17, 0.11], [1.42, 0.15, 0.10], [1.45, 0.11, 0.08], [1.48, 0.065, 0.06], [1.50, 0.055, 0.055],
 [1.58, 0.055, 0.055], [1.62, 0.08, 0.085], [1.66, 0.095, 0.10], [1.72, 0.10, 0.105], [1.78, 0.09, 0.095],
 [1.82, 0.06, 0.065], [1.845, 0.0, 0.0]])
def curve(n):
    # resample profile by arc length
    s = np.linspace(0, 1, 2000)
    seg = np.r_[0, np.cumsum(np.hypot(np.diff(prof[:, 0]), np.diff(np.maximum(prof[:, 1], prof[:, 2]))))]
    seg /= seg[-1]
    y = np.interp(s, seg, prof[:, 0]); a = np.interp(s, seg, prof[:, 1]); b = np.interp(s, seg, prof[:, 2])
    L = np.r_[0, np.cumsum(np.hypot(np.diff(y), np.diff(a)))]; L /= L[-1]
    t = np.linspace(0, 1, n)
    return np.interp(t, L, y), np.interp(t, L, a), np.interp(t, L, b)
ys, As, Bs = curve(40)
V = [[0, ys[0], 0]]
rings = []
for k in range(1, len(ys) - 1):
    rings.append(len(V))
    for i in range(NU):
        th = 2 * math.pi * i / NU
        V.append([As[k] * math.cos(th), ys[k], Bs[k] * math.sin(th)])
top = len(V); V.append([0, ys[-1], 0])
V = np.array(V)
T = []
r0 = rings[0]
for i in range(NU):
    T.append([0, r0 + i, r0 + (i + 1) % NU])
for k in range(len(rings) - 1):
    a, b = rings[k], rings[k + 1]
    for i in range(NU):
        j = (i + 1) % NU
        T.append([a + i, b + i, b + j]); T.append([a + i, b + j, a + j])
rl = rings[-1]
for i in range(NU):
    T.append([top, rl + (i + 1) % NU, rl + i])
T = np.array(T)
# orientation: make outward (signed volume positive)
vol = np.einsum('ij,ij->i', V[T[:, 0]], np.cross(V[T[:, 1]], V[T[:, 2]])).sum() / 6
if vol < 0: T = T[:, ::-1]
def body_a_b(y):
    return np.interp(y, ys, As), np.interp(y, ys, Bs)
# skeleton: root (yaw+translate), spine joint at (0,1.1,0), neck joint at (0,1.5,0)
def smooth(e0, e1, x):
    u = np.clip((x - e0) / (e1 - e0), 0, 1); return u * u * (3 - 2 * u)
def weights(P):
    y = P[:, 1]
    wn = smooth(1.47, 1.60, y)
    ws = smooth(1.00, 1.25, y) * (1 - wn)
    wr = 1 - ws - wn
    return np.stack([wr, ws, wn], 1)
W = weights(V)
def rot(axis, ang):
    axis = np.asarray(axis, float); axis /= np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(ang) * K + (1 - math.cos(ang)) * K @ K
def M(R, t):
    m = np.eye(4); m[:3, :3] = R; m[:3, 3] = t; return m
def about(R, c):  # rotate about point c
    return M(R, np.asarray(c) - R @ np.asarray(c))
def pose_mats(F):
    t = (F - 1001) / 24.0
    yaw = math.radians(60 + 40 * t)
    root = M(rot([0, 1, 0], yaw), [1.5 + 1.2 * t * math.sin(yaw), 0.02 * math.sin(2 * math.pi * 2 * t), 1.0 + 1.2 * t * math.cos(yaw)])
    spine = root @ about(rot([1, 0, 0], math.radians(25 + 10 * math.sin(2 * math.pi * 0.7 * t))) @ rot([0, 0, 1], math.radians(8 * math.sin(2 * math.pi * t))), [0, 1.1, 0])
    neck = spine @ about(rot([0, 1, 0], math.radians(30 * math.sin(2 * math.pi * 0.5 * t))) @ rot([1, 0, 0], math.radians(-15)), [0, 1.5, 0])
    return [root, spine, neck]
def skin(P, Wt, F):
    Ms = pose_mats(F)
    Ph = np.c_[P, np.ones(len(P))]
    out = np.zeros_like(P)
    for k, m in enumerate(Ms):
        out += Wt[:, k:k + 1] * (Ph @ m.T)[:, :3]
    return out
def write_obj(path, P, Tr):
    with open(path, "w") as f:
        for p in P: f.write("v %.7f %.7f %.7f\n" % tuple(p))
        for t in Tr: f.write("f %d %d %d\n" % tuple(t + 1))
write_obj(os.path.join(out, "rest.obj"), V, T)
for F in range(F0, F1 + 1):
    write_obj(os.path.join(out, pat % F), skin(V, W, F), T)
# cape: columns over angles on the back (z<0), rows down from the collar following the profile
NC, NR = 15, 18
ths = np.radians(np.linspace(205, 335, NC))
cy, ca, cb = [], [], []
# collar at y=1.50; then follow outward shoulder offset curve down to y=0.95
yy = np.linspace(1.50, 0.95, 400)
def off(y):
    return 0.015 + 0.02 * smooth(1.50, 1.42, y)
a_, b_ = body_a_b(yy)
# arc length along (y, a+off) at theta=270 roughly
ra = a_ + off(yy); rb = b_ + off(yy)
L = np.r_[0, np.cumsum(np.hypot(np.diff(yy), np.diff(rb)))]
tt = np.linspace(0, L[-1], NR)
ry = np.interp(tt, L, yy)
CV = []
for j in range(NR):
    aa, bb = body_a_b(ry[j]); d = off(ry[j])
    for i in range(NC):
        CV.append([(aa + d) * math.cos(ths[i]), ry[j], (bb + d) * math.sin(ths[i])])
CV = np.array(CV)
CT = []
for j in range(NR - 1):
    for i in range(NC - 1):
        a = j * NC + i
        CT.append([a, a + NC, a + NC + 1]); CT.append([a, a + NC + 1, a + 1])
CT = np.array(CT)
write_obj(os.path.join(out, "cape.obj"), CV, np.array(CT))
# hair plume: roots on the back of the head, lying 2.5 cm off the cape/body going down
NS, NSEG, SEGL = 16, 16, 0.03
rows = []
for s in range(NS):
    th = math.radians(245 + 50 * (s % 8) / 7)
    y0 = 1.70 + 0.04 * (s // 8)
    aa, bb = body_a_b(y0)
    p = np.array([(aa + 0.012) * math.cos(th), y0, (bb + 0.012) * math.sin(th)])
    pts = [p]
    for k in range(NSEG):
        # step down, then push out to keep >= 2.5 cm outside cape/body
        q = pts[-1] + np.array([0, -SEGL, 0])
        for it in range(30):
            aa, bb = body_a_b(q[1])
            d = off(q[1]) if q[1] <= 1.50 else 0.0
            ex = (aa + d + 0.025); ez = (bb + d + 0.025)
            r = math.hypot(q[0] / ex, q[2] / ez)
            if r < 1:
                q[0] /= r; q[2] /= r
            v = q - pts[-1]; q = pts[-1] + v / np.linalg.norm(v) * SEGL
        pts.append(q)
    for p in pts: rows.append((p, s))
with open(os.path.join(out, "hair.csv"), "w") as f:
    f.write("x,y,z,strand\n")
    for p, s in rows: f.write("%.7f,%.7f,%.7f,%d\n" % (p[0], p[1], p[2], s))
print("body", len(V), "verts", len(T), "tris; cape", len(CV), "verts; hair", NS, "x", NSEG + 1)
