#!/usr/bin/env python3
"""examples/11_character: a skinned character that walks and turns, its cape and its ponytail.

python3 and numpy only, no downloaded assets. The body is ONE closed skin: a low-poly cage
(a torso of 10-vertex rings with the legs, the arms and the neck and head extruded from its
faces, as a modeller box-models a body) smoothed by two levels of Catmull-Clark subdivision
and triangulated (2,818 vertices, 5,632 triangles). Every cage vertex carries
linear-blend-skinning weights on a skeleton of 19 joints (pelvis, spine, chest, neck, head;
clavicles, upper arms, forearms and hands; thighs, shins and feet), 50/50 across each elbow, wrist, knee and ankle ring and
blended round the shoulders and hips; subdividing the weights with the positions spreads them
smoothly across every joint, so the skin bends and stretches there as a rigged character's
does (v = sum_j w_j M_j v_rest, M_j the joint's world transform from the rest pose).

The walk: 1.0 stride/s at 1.2 m/s, thighs swinging +-24 degrees with the knees flexing in
the swing, arms swinging +-22 degrees against the legs with the elbows bending, the pelvis
bobbing 2 cm, swaying 2.5 cm and twisting against the chest, the head nodding; and a 50 degree
turn to the character's left (towards +x) between 0.5 s and 1.4 s. It faces +z at first, feet
at y = 0, 1.84 m tall.

Shot frames as a cache has them: frame F is at t = (F - 1001) / fps, written for 1000 ... 1049
(the shot is 1001-1048, one frame of handle on each side), plus body/rest.obj: the same skin in
its rest (bind) pose at the origin, which the scene's pre-roll eases the body from.

The cape (cape.obj) is modelled on the rest pose: a 17 x 25 vertex sheet whose top row runs
round the back of the neck from one side of it to the other (the collar, 1.5 cm off the skin),
over the shoulders and down the back to mid-thigh, kept at least 2 cm off the skin everywhere.
The ponytail (hair.csv, x,y,z,strand, root first): 30 strands of 16 segments (0.36 m) rooted
1.5 cm off the back of the head (at its tie), combed back and hanging down (the polyline is
the rest shape).

    python3 make_character.py [folder]      (default: body/; writes cape.obj and hair.csv in the
                                             current directory)
"""
import math
import os
import sys

import numpy as np

FPS = 24.0
FIRST, LAST = 1000, 1049        # written frames: the shot 1001-1048 and a frame of handle each side
TIME_ZERO = 1001

# ---------------------------------------------------------------------------------------------
# Skeleton: (name, parent, rest position of the joint, m). Facing +z, y up, feet at y = 0.
JOINTS = [
    ("pelvis", -1, (0.0, 0.95, 0.0)),
    ("spine", 0, (0.0, 1.08, 0.0)),
    ("chest", 1, (0.0, 1.25, 0.0)),
    ("neck", 2, (0.0, 1.46, 0.0)),
    ("head", 3, (0.0, 1.58, 0.0)),
    ("clavicle_l", 2, (0.05, 1.40, 0.0)),
    ("upperarm_l", 5, (0.20, 1.39, 0.0)),
    ("forearm_l", 6, (0.275, 1.13, 0.0)),
    ("hand_l", 7, (0.34, 0.89, 0.0)),
    ("clavicle_r", 2, (-0.05, 1.40, 0.0)),
    ("upperarm_r", 9, (-0.20, 1.39, 0.0)),
    ("forearm_r", 10, (-0.275, 1.13, 0.0)),
    ("hand_r", 11, (-0.34, 0.89, 0.0)),
    ("thigh_l", 0, (0.095, 0.88, 0.0)),
    ("shin_l", 13, (0.10, 0.50, 0.0)),
    ("foot_l", 14, (0.10, 0.09, 0.0)),
    ("thigh_r", 0, (-0.095, 0.88, 0.0)),
    ("shin_r", 16, (-0.10, 0.50, 0.0)),
    ("foot_r", 17, (-0.10, 0.09, 0.0)),
]
J = {name: k for k, (name, _, _) in enumerate(JOINTS)}
NJ = len(JOINTS)


def weight(**parts):
    w = np.zeros(NJ)
    for name, value in parts.items():
        w[J[name]] = value
    return w / w.sum()


# ---------------------------------------------------------------------------------------------
# The cage: a polygon mesh (faces of any size, outward by the right-hand rule) whose vertices
# carry a position and skinning weights.
class Cage:
    def __init__(self):
        self.pos, self.wts, self.faces = [], [], []

    def vertex(self, p, w):
        self.pos.append(np.asarray(p, float))
        self.wts.append(w)
        return len(self.pos) - 1

    def extrude(self, face, stations, hint):
        """Replaces `face` by a tube through `stations` (centre, direction, (ru, rw), weights)
        and a cap: every ring is the face's outline, normalised per axis to a unit profile and
        carried to the station by the rotation taking the face's normal to the station's
        direction, scaled by (ru, rw) along the carried axes (u from `hint`)."""
        loop = self.faces[face]
        P = np.array([self.pos[i] for i in loop])
        c = P.mean(0)
        n = np.zeros(3)
        for k in range(len(loop)):
            n += np.cross(P[k] - c, P[(k + 1) % len(loop)] - c)
        n /= np.linalg.norm(n)
        u = np.asarray(hint, float) - np.dot(hint, n) * n
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        a, b = (P - c) @ u, (P - c) @ w
        a /= np.abs(a).max()
        b /= np.abs(b).max()
        prev = list(loop)
        for (centre, direction, (ru, rw), wt) in stations:
            d = np.asarray(direction, float)
            d /= np.linalg.norm(d)
            R = rotation_between(n, d)
            us, ws = R @ u, R @ w
            ring = [self.vertex(np.asarray(centre) + ru * a[k] * us + rw * b[k] * ws, wt)
                    for k in range(len(loop))]
            m = len(loop)
            for k in range(m):
                self.faces.append([prev[k], prev[(k + 1) % m], ring[(k + 1) % m], ring[k]])
            prev = ring
        self.faces[face] = prev  # the cap, same orientation as the face it replaces


def rotation_between(a, b):
    """The smallest rotation taking unit vector a to unit vector b (Rodrigues)."""
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3) if c > 0 else -np.eye(3)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1.0 + c)


def build_cage():
    cage = Cage()
    # Torso rings of 10 (x, z) points: three across the front and back, one on each side.
    def ring_points(w, d, m):
        return [(w, d), (m, d), (-m, d), (-w, d), (-w, 0), (-w, -d), (-m, -d), (m, -d), (w, -d), (w, 0)]
    torso = [  # y, half width, half depth, inner x, weights (middle, sides)
        (0.80, 0.165, 0.115, 0.05, weight(pelvis=1), weight(pelvis=1)),
        (0.97, 0.170, 0.115, 0.06, weight(pelvis=0.6, spine=0.4), weight(pelvis=0.6, spine=0.4)),
        (1.14, 0.155, 0.105, 0.06, weight(spine=0.5, chest=0.5), weight(spine=0.5, chest=0.5)),
        (1.30, 0.175, 0.115, 0.07, weight(chest=1), weight(chest=0.8, clavicle_l=0.2)),
        (1.45, 0.165, 0.090, 0.06, weight(chest=0.7, neck=0.3), weight(chest=0.5, clavicle_l=0.5)),
    ]
    rings = []
    for (y, w, d, m, wm, ws) in torso:
        ids = []
        for k, (x, z) in enumerate(ring_points(w, d, m)):
            wt = wm
            if k in (3, 4, 5, 8, 9, 0) and ws is not wm:
                wt = ws.copy()
                if x < 0:  # mirror the clavicle weight to the right side
                    wt[J["clavicle_r"]], wt[J["clavicle_l"]] = wt[J["clavicle_l"]], 0.0
            if y < 0.9 and k in (0, 3, 4, 5, 8, 9):
                wt = weight(pelvis=0.75, thigh_l=0.25) if x > 0 else weight(pelvis=0.75, thigh_r=0.25)
            ids.append(cage.vertex((x, y, z), wt))
        rings.append(ids)
    # Walls between rings; the top band's sides (where the arms go) are hexagons.
    arm_faces = {}
    for r in range(len(rings) - 1):
        a, b = rings[r], rings[r + 1]
        if r == len(rings) - 2:
            arm_faces["r"] = len(cage.faces)
            cage.faces.append([a[3], b[3], b[4], b[5], a[5], a[4]])
            arm_faces["l"] = len(cage.faces)
            cage.faces.append([a[8], b[8], b[9], b[0], a[0], a[9]])
            skip = {3, 4, 8, 9}
        else:
            skip = set()
        for k in range(10):
            if k not in skip:
                cage.faces.append([a[k], b[k], b[(k + 1) % 10], a[(k + 1) % 10]])
    bot, top = rings[0], rings[-1]
    leg_faces = {"r": len(cage.faces)}
    cage.faces.append([bot[2], bot[3], bot[4], bot[5], bot[6]])
    cage.faces.append([bot[1], bot[2], bot[6], bot[7]])          # the crotch
    leg_faces["l"] = len(cage.faces)
    cage.faces.append([bot[7], bot[8], bot[9], bot[0], bot[1]])
    cage.faces.append([top[6], top[5], top[4], top[3], top[2]])  # shoulder tops
    neck_face = len(cage.faces)
    cage.faces.append([top[7], top[6], top[2], top[1]])
    cage.faces.append([top[1], top[0], top[9], top[8], top[7]])

    for side, s in (("l", 1.0), ("r", -1.0)):
        W = lambda **k: weight(**{(n + "_" + side if n not in ("pelvis", "chest") else n): v for n, v in k.items()})
        cage.extrude(arm_faces[side], [
            ((s * 0.215, 1.36, 0.0), (s * 0.55, -0.83, 0), (0.060, 0.065), W(clavicle=0.3, upperarm=0.7)),
            ((s * 0.280, 1.13, 0.0), (s * 0.26, -0.97, 0), (0.046, 0.050), W(upperarm=0.5, forearm=0.5)),
            ((s * 0.320, 0.99, 0.0), (s * 0.26, -0.97, 0), (0.042, 0.045), W(forearm=1)),
            ((s * 0.345, 0.89, 0.0), (s * 0.26, -0.97, 0), (0.036, 0.040), W(forearm=0.5, hand=0.5)),
            ((s * 0.365, 0.79, 0.0), (s * 0.20, -0.98, 0), (0.040, 0.050), W(hand=1)),
        ], hint=(0, 0, 1))
        cage.extrude(leg_faces[side], [
            ((s * 0.10, 0.70, 0.0), (0, -1, 0), (0.095, 0.100), W(pelvis=0.3, thigh=0.7)),
            ((s * 0.10, 0.50, 0.0), (0, -1, 0), (0.070, 0.075), W(thigh=0.5, shin=0.5)),
            ((s * 0.10, 0.10, -0.01), (0, -1, 0), (0.048, 0.052), W(shin=0.5, foot=0.5)),
            ((s * 0.10, 0.04, 0.06), (0, -0.5, 1), (0.052, 0.045), W(foot=1)),
            ((s * 0.10, 0.035, 0.15), (0, 0, 1), (0.048, 0.030), W(foot=1)),
        ], hint=(1, 0, 0))
    cage.extrude(neck_face, [
        ((0.0, 1.52, 0.0), (0, 1, 0), (0.062, 0.062), weight(neck=1)),
        ((0.0, 1.58, 0.015), (0, 1, 0.1), (0.070, 0.085), weight(neck=0.5, head=0.5)),
        ((0.0, 1.68, 0.010), (0, 1, 0), (0.105, 0.125), weight(head=1)),
        ((0.0, 1.79, 0.0), (0, 1, 0), (0.085, 0.100), weight(head=1)),
        ((0.0, 1.84, 0.0), (0, 1, 0), (0.045, 0.055), weight(head=1)),
    ], hint=(1, 0, 0))
    return cage


def catmull_clark(X, faces):
    """One level of Catmull-Clark on a closed polygon mesh; X carries any affine attributes
    (positions and skinning weights alike). Returns the new attributes and quads."""
    n = len(X)
    fp = np.array([X[f].mean(0) for f in faces])
    edges = {}
    for fi, f in enumerate(faces):
        for k in range(len(f)):
            e = (min(f[k], f[(k + 1) % len(f)]), max(f[k], f[(k + 1) % len(f)]))
            edges.setdefault(e, []).append(fi)
    eid = {}
    ep = []
    for e, fs in edges.items():
        assert len(fs) == 2, "the cage is not closed"
        eid[e] = n + len(fp) + len(ep)
        ep.append((X[e[0]] + X[e[1]] + fp[fs[0]] + fp[fs[1]]) / 4.0)
    Fsum = np.zeros_like(X)
    Rsum = np.zeros_like(X)
    val = np.zeros(n)
    fcount = np.zeros(n)
    for fi, f in enumerate(faces):
        for v in f:
            Fsum[v] += fp[fi]
            fcount[v] += 1
    for (a, b) in edges:
        mid = (X[a] + X[b]) / 2.0
        Rsum[a] += mid
        Rsum[b] += mid
        val[a] += 1
        val[b] += 1
    vp = (Fsum / fcount[:, None] + 2 * Rsum / val[:, None] + (val[:, None] - 3) * X) / val[:, None]
    Y = np.vstack([vp, fp, np.array(ep)])
    quads = []
    for fi, f in enumerate(faces):
        m = len(f)
        for k in range(m):
            e_next = eid[(min(f[k], f[(k + 1) % m]), max(f[k], f[(k + 1) % m]))]
            e_prev = eid[(min(f[k - 1], f[k]), max(f[k - 1], f[k]))]
            quads.append([f[k], e_next, n + fi, e_prev])
    return Y, quads


def build_skin():
    cage = build_cage()
    X = np.hstack([np.array(cage.pos), np.array(cage.wts)])
    faces = cage.faces
    for _ in range(2):
        X, faces = catmull_clark(X, faces)
    tris = []
    for (a, b, c, d) in faces:
        tris += [(a, b, c), (a, c, d)]
    V, W = X[:, :3], X[:, 3:]
    W = np.clip(W, 0, None)
    W /= W.sum(1, keepdims=True)
    return V, W, np.array(tris)


def check_closed(T):
    """Every directed edge once and its reverse once: closed, manifold, consistently oriented."""
    directed = {}
    for t in T:
        for k in range(3):
            e = (int(t[k]), int(t[(k + 1) % 3]))
            directed[e] = directed.get(e, 0) + 1
    bad = [e for e, c in directed.items() if c != 1 or directed.get((e[1], e[0]), 0) != 1]
    return not bad


# ---------------------------------------------------------------------------------------------
# The walk.
STRIDE_HZ, SPEED = 1.0, 1.2
TURN_DEG, TURN_T0, TURN_T1 = 50.0, 0.5, 1.4


def rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def heading(t):
    s = min(max((t - TURN_T0) / (TURN_T1 - TURN_T0), 0.0), 1.0)
    return math.radians(TURN_DEG) * (3 * s * s - 2 * s * s * s)


def path(t, step=1e-3):
    """(x, z) walked by time t (from 0; negative t walks backwards along the first heading)."""
    n = max(1, int(abs(t) / step))
    ts = (np.arange(n) + 0.5) * (t / n)
    yaw = np.array([heading(x) for x in ts])
    return SPEED * (t / n) * np.sin(yaw).sum(), SPEED * (t / n) * np.cos(yaw).sum()


def local_rotations(t):
    """Each joint's rotation about its rest position, in its parent's (rest-aligned) frame."""
    ph = 2.0 * math.pi * STRIDE_HZ * t
    d = math.radians
    R = [np.eye(3) for _ in JOINTS]
    R[J["pelvis"]] = ry(d(6) * math.sin(ph)) @ rz(d(3) * math.sin(ph))
    R[J["spine"]] = ry(d(-3) * math.sin(ph))
    R[J["chest"]] = ry(d(-5) * math.sin(ph)) @ rx(d(4))
    R[J["neck"]] = ry(d(2) * math.sin(ph))
    R[J["head"]] = rx(d(4) * math.sin(2 * ph)) @ ry(d(3) * math.sin(ph))
    for side, s in (("l", 1.0), ("r", -1.0)):
        swing = s * math.sin(ph)                      # +1: this leg forward
        knee = 6 + 50 * max(0.0, s * math.cos(ph)) ** 1.5
        R[J["thigh_" + side]] = rx(-d(24) * swing)    # rx(-a) moves the foot to +z
        R[J["shin_" + side]] = rx(d(knee))
        R[J["foot_" + side]] = rx(d(-8 * swing))
        R[J["clavicle_" + side]] = rx(d(3) * swing)
        R[J["upperarm_" + side]] = rx(d(22) * swing)  # the arm swings against its leg
        R[J["forearm_" + side]] = rx(-d(18 + 12 * max(0.0, -swing)))
        R[J["hand_" + side]] = rx(-d(6))
    return R


def skinning_matrices(t, rest=False):
    """World transforms (4x4) of the joints relative to the rest pose."""
    M = []
    R = local_rotations(t)
    for k, (name, parent, p) in enumerate(JOINTS):
        p = np.asarray(p)
        L = np.eye(4)
        L[:3, :3] = R[k]
        L[:3, 3] = p - R[k] @ p                     # rotate about the joint's rest position
        if parent < 0:
            ph = 2.0 * math.pi * STRIDE_HZ * t
            x, z = path(t)
            G = np.eye(4)
            G[:3, :3] = ry(heading(t))
            G[:3, 3] = (x, 0.02 * math.cos(2 * ph) - 0.02, z)
            sway = np.eye(4)
            sway[0, 3] = 0.025 * math.sin(ph)
            M.append(G @ sway @ L)
        else:
            M.append(M[parent] @ L)
    return M


def pose(V, W, t):
    Vh = np.hstack([V, np.ones((len(V), 1))])
    out = np.zeros_like(V)
    for k, M in enumerate(skinning_matrices(t)):
        out += W[:, k:k + 1] * (Vh @ M.T)[:, :3]
    return out


def write_obj(path, V, T, comment):
    with open(path, "w") as f:
        f.write("# %s\n" % comment)
        f.write("".join("v %.6f %.6f %.6f\n" % tuple(v) for v in V))
        f.write("".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in T))


# ---------------------------------------------------------------------------------------------
# Distances to the skin (brute force: a few hundred points against a few thousand triangles).
def closest_points(P, V, T):
    A, B, C = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    best_d = np.full(len(P), np.inf)
    best_q = np.zeros_like(P)
    for i, p in enumerate(P):
        q = closest_on_triangles(p, A, B, C)
        dd = np.linalg.norm(q - p, axis=1)
        k = int(dd.argmin())
        best_d[i], best_q[i] = dd[k], q[k]
    return best_d, best_q


def closest_on_triangles(p, A, B, C):
    """Ericson, Real-Time Collision Detection 5.1.5, vectorised over triangles."""
    ab, ac, ap = B - A, C - A, p - A
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp = p - B
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    cp = p - C
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    den = np.where(va + vb + vc == 0, 1e-300, va + vb + vc)
    v, w = vb / den, vc / den
    q = A + v[:, None] * ab + w[:, None] * ac
    # Edge and vertex regions.
    safe = lambda x: np.where(x == 0, 1e-300, x)
    e_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    q = np.where(e_ab[:, None], A + (d1 / safe(d1 - d3))[:, None] * ab, q)
    e_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    q = np.where(e_ac[:, None], A + (d2 / safe(d2 - d6))[:, None] * ac, q)
    e_bc = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
    q = np.where(e_bc[:, None], B + ((d4 - d3) / safe((d4 - d3) + (d5 - d6)))[:, None] * (C - B), q)
    q = np.where(((d1 <= 0) & (d2 <= 0))[:, None], A, q)
    q = np.where(((d3 >= 0) & (d4 <= d3))[:, None], B, q)
    q = np.where(((d6 >= 0) & (d5 <= d6))[:, None], C, q)
    return q


def winding(P, V, T):
    """Generalised winding numbers (Jacobson et al. 2013) of points P about the closed mesh."""
    A, B, C = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    out = np.zeros(len(P))
    for i, p in enumerate(P):
        a, b, c = A - p, B - p, C - p
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        num = (a * np.cross(b, c)).sum(1)
        den = la * lb * lc + (a * b).sum(1) * lc + (b * c).sum(1) * la + (c * a).sum(1) * lb
        out[i] = np.arctan2(num, den).sum() / (2 * math.pi)
    return out


def push_out(P, V, T, clearance, iterations=6):
    """Moves points closer than `clearance` to the skin (or inside it) out to `clearance`."""
    P = P.copy()
    for _ in range(iterations):
        d, q = closest_points(P, V, T)
        inside = winding(P, V, T) > 0.5
        near = (d < clearance) | inside
        if not near.any():
            break
        n = P - q
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
        n[inside] *= -1
        P[near] = q[near] + clearance * n[near]
    return P


# ---------------------------------------------------------------------------------------------
# The cape and the ponytail, on the rest pose.
CAPE_COLS, CAPE_ROWS = 16, 24
CLEARANCE = 0.02     # m: the cape hangs at least this far off the bind-pose skin
ROOT_OFFSET = 0.015   # m: the ponytail starts at its tie, 1.5 cm off the scalp (outside the body collider's 1 cm)


def cape_surface(s, j):
    """The cape's shape before it is kept off the skin: at parameter s (0 the collar, 1 the hem)
    and column j, a point on an ellipse round the body (angle 0 straight behind) that opens over
    the shoulders (s < 0.12) and flares towards the hem."""
    top = min(s / 0.12, 1.0)
    ease = 3 * top * top - 2 * top ** 3
    low = max(s - 0.12, 0) / 0.88
    y = 1.47 - 0.08 * ease - 0.68 * low
    rx_ = 0.085 + (0.245 - 0.085) * ease + 0.07 * low
    rz_ = 0.085 + (0.150 - 0.085) * ease + 0.07 * low
    th = math.radians(95 - 27 * ease) * (2.0 * j / CAPE_COLS - 1.0)
    return (rx_ * math.sin(th), y, -rz_ * math.cos(th))


def cape(V, T):
    """The cape's rows at even steps of length down the cape (the mean over its columns), so
    the shoulders, where the shape turns, get as many rows as their length needs."""
    fine = np.linspace(0, 1, 2001)
    G = np.array([[cape_surface(s, j) for j in range(CAPE_COLS + 1)] for s in fine])
    arc = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(G, axis=0), axis=2).mean(1))])
    rows = np.interp(np.linspace(0, arc[-1], CAPE_ROWS + 1), arc, fine)
    P = np.array([cape_surface(s, j) for s in rows for j in range(CAPE_COLS + 1)])
    collar = np.arange(CAPE_COLS + 1)
    P[collar] = push_out(P[collar], V, T, 0.015)
    rest = np.setdiff1d(np.arange(len(P)), collar)
    P[rest] = push_out(P[rest], V, T, CLEARANCE)
    F = []
    for i in range(CAPE_ROWS):
        for j in range(CAPE_COLS):
            a = i * (CAPE_COLS + 1) + j
            b, c, d = a + 1, a + CAPE_COLS + 2, a + CAPE_COLS + 1
            # Outward (away from the body): alternate diagonals for a symmetric sheet.
            F += [(a, d, c), (a, c, b)] if (i + j) % 2 == 0 else [(a, d, b), (b, d, c)]
    return P, np.array(F), collar


def ponytail(V, T, strands=30, segments=16, length=0.36, root_offset=ROOT_OFFSET):
    """Roots on the back of the head round (0, 1.73, back), root_offset off the skin, combed
    back over the first third and then hanging down behind the neck onto the cape."""
    pts = []
    for s in range(strands):
        ring, k = divmod(s, 10)
        ang = 2 * math.pi * (k + 0.5 * ring) / 10
        r = 0.012 + 0.012 * ring
        pts.append((r * math.cos(ang), 1.73 + r * math.sin(ang), -0.2))
    seeds = np.array(pts)
    d, q = closest_points(seeds, V, T)
    n = seeds - q
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    roots = q + root_offset * n
    out = []
    step = length / segments
    for s in range(strands):
        p = roots[s].copy()
        line = [p.copy()]
        spread = np.array([roots[s][0] * 0.8, 0, 0])
        for k in range(segments):
            u = (k + 0.5) / segments
            back = np.array([0.0, 0.25, -1.0]) * max(0.0, 1.0 - 3.0 * u) ** 2
            down = np.array([0.0, -1.0, -0.25]) * min(1.0, 3.0 * u)
            dirn = back + down + spread
            dirn /= np.linalg.norm(dirn)
            p = p + step * dirn
            line.append(p.copy())
        out.append(np.array(line))
    return out


def main(argv):
    # --root-offset M: the ponytail's roots M metres off the scalp (tests: roots within the body
    # collider's 1 cm thickness, as a groom rooted on the skin has them).
    root_offset = ROOT_OFFSET
    if "--root-offset" in argv:
        k = argv.index("--root-offset")
        if k + 1 >= len(argv):
            sys.exit("make_character.py: --root-offset needs a distance in metres")
        try:
            root_offset = float(argv[k + 1])
        except ValueError:
            sys.exit("make_character.py: --root-offset needs a distance in metres, not %r" % argv[k + 1])
        argv = argv[:k] + argv[k + 2:]
    folder = argv[0] if argv else "body"
    V, W, T = build_skin()
    if not check_closed(T):
        sys.exit("make_character.py: the skin is not closed (a bug in the cage)")
    os.makedirs(folder, exist_ok=True)
    write_obj(os.path.join(folder, "rest.obj"), V, T, "examples/11_character/make_character.py: rest (bind) pose")
    for F in range(FIRST, LAST + 1):
        t = (F - TIME_ZERO) / FPS
        write_obj(os.path.join(folder, "body.%04d.obj" % F), pose(V, W, t), T,
                  "examples/11_character/make_character.py: frame %d (t = %.4f s)" % (F, t))
    P, CF, collar = cape(V, T)
    write_obj("cape.obj", P, CF, "examples/11_character/make_character.py: the cape on the rest pose, "
              "row 0 (vertices 0-%d) is the collar" % CAPE_COLS)
    strands = ponytail(V, T, root_offset=root_offset)
    with open("hair.csv", "w") as f:
        f.write("x,y,z,strand\n")
        for s, line in enumerate(strands):
            f.write("".join("%.6f,%.6f,%.6f,%d\n" % (x, y, z, s) for x, y, z in line))
    inside = winding(np.vstack(strands), V, T) > 0.5
    if inside.any() or (winding(P, V, T) > 0.5).any():
        sys.exit("make_character.py: the cape or the hair starts inside the body")
    print("wrote %d frames (%d-%d) of %d vertices and %d triangles to %s/ (and rest.obj), cape.obj "
          "(%d vertices, %d triangles), hair.csv (%d strands of %d vertices)"
          % (LAST - FIRST + 1, FIRST, LAST, len(V), len(T), folder, len(P), len(CF), len(strands),
             len(strands[0])))


if __name__ == "__main__":
    main(sys.argv[1:])
