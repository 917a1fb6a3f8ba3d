#!/usr/bin/env python3
"""examples/10_hair_turn: a head that turns left and right and nods, and the hair grown on it.

Plain python3 (standard library only). The head is an ellipsoid (0.16 m wide, 0.22 m tall,
0.20 m deep) on a neck (a capsule, r = 4.5 cm, down to shoulder height), one fixed topology, posed rigidly each frame
about a pivot at the base of the neck: it turns (yaw about +y) 70 degrees to its left, back
and 70 degrees to its right once every 2 s, and nods (pitch about +x) 12 degrees twice as
often; both start from rest (frame 1 is the rest pose, facing +z). Hair: strands rooted on the
back and top of the scalp, 5 mm off it (the roots are attached there), that run out from the
scalp, along it 1.2 cm off the surface over the back of the head, and then hang straight down
(a combed, shoulder-length style; the strand's polyline is its rest shape).

    python3 make_head.py [folder] [--frames N] [--fps F]     (default: head/, 48 frames, 24 fps)

writes folder/head.0001.obj ... head.00NN.obj and hair.csv (x, y, z, strand) beside this script's
output folder (in the current directory).
"""
import math
import os
import sys

CENTER = (0.0, 1.66, 0.0)   # the head's centre, m
AXES = (0.08, 0.11, 0.10)   # semi-axes x, y, z, m
PIVOT = (0.0, 1.45, 0.0)    # the base of the neck: the head and neck turn about it
NECK_TOP, NECK_BOTTOM, NECK_R = 1.60, 1.30, 0.045
LAT, LON = 24, 40           # ellipsoid rings and segments (1,872 triangles)

TURN_DEG, TURN_PERIOD = 70.0, 2.0  # yaw amplitude, s per left-right cycle
NOD_DEG = 12.0                     # pitch amplitude, nodding twice per cycle
RAMP = 0.25                        # s: the motion eases in from rest

HAIR_LENGTH, HAIR_SEGMENTS = 0.34, 14
ROOT_OFFSET, DRAPE_OFFSET = 0.005, 0.012


def ellipsoid():
    """A UV ellipsoid: poles and LAT-1 rings of LON vertices; outward-facing triangles."""
    verts = [(CENTER[0], CENTER[1] + AXES[1], CENTER[2])]
    for i in range(1, LAT):
        th = math.pi * i / LAT
        for j in range(LON):
            ph = 2.0 * math.pi * j / LON
            verts.append((CENTER[0] + AXES[0] * math.sin(th) * math.sin(ph),
                          CENTER[1] + AXES[1] * math.cos(th),
                          CENTER[2] + AXES[2] * math.sin(th) * math.cos(ph)))
    verts.append((CENTER[0], CENTER[1] - AXES[1], CENTER[2]))
    return verts, uv_faces(0, LAT - 1, LON, len(verts) - 1)


def uv_faces(top, rings, segments, bottom):
    """Triangles of a closed UV surface: vertex `top`, `rings` rings from top + 1, `bottom`."""
    ring = lambda i, j: top + 1 + i * segments + (j % segments)
    tris = [(top, ring(0, j), ring(0, j + 1)) for j in range(segments)]
    for i in range(rings - 1):
        for j in range(segments):
            tris.append((ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)))
            tris.append((ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)))
    tris += [(bottom, ring(rings - 1, j + 1), ring(rings - 1, j)) for j in range(segments)]
    return tris


def neck(base):
    """A capsule along y from NECK_TOP to NECK_BOTTOM: hemispherical caps, 16 segments."""
    seg, caps = 16, 4
    profile = []  # (y, r) from the top pole down
    for k in range(1, caps + 1):
        a = 0.5 * math.pi * k / caps
        profile.append((NECK_TOP + NECK_R * math.cos(a), NECK_R * math.sin(a)))
    for k in range(caps, 0, -1):
        a = 0.5 * math.pi * k / caps
        profile.append((NECK_BOTTOM - NECK_R * math.cos(a), NECK_R * math.sin(a)))
    verts = [(0.0, NECK_TOP + NECK_R, 0.0)]
    for (y, r) in profile:
        for j in range(seg):
            ph = 2.0 * math.pi * j / seg
            verts.append((r * math.sin(ph), y, r * math.cos(ph)))
    verts.append((0.0, NECK_BOTTOM - NECK_R, 0.0))
    tris = uv_faces(0, len(profile), seg, len(verts) - 1)
    return verts, [(a + base, b + base, c + base) for (a, b, c) in tris]


def smooth(x):
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


def pose(t):
    """(yaw, pitch) in radians at time t (s from the rest pose)."""
    ease = smooth(t / RAMP)
    yaw = math.radians(TURN_DEG) * math.sin(2.0 * math.pi * t / TURN_PERIOD) * ease
    pitch = math.radians(NOD_DEG) * math.sin(4.0 * math.pi * t / TURN_PERIOD) * ease
    return yaw, pitch


def transform(t):
    """The rigid motion at time t as a function of a rest-pose point: about PIVOT, Ry(yaw) Rx(pitch)."""
    yaw, pitch = pose(t)
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)

    def apply(p):
        x, y, z = p[0] - PIVOT[0], p[1] - PIVOT[1], p[2] - PIVOT[2]
        y, z = cp * y - sp * z, sp * y + cp * z           # pitch about x (positive: chin down)
        x, z = cy * x + sy * z, -sy * x + cy * z           # yaw about y (positive: to its left)
        return (x + PIVOT[0], y + PIVOT[1], z + PIVOT[2])

    return apply


def scalp(th, ph, offset):
    """A point `offset` m outside the ellipsoid (axes grown by it) at polar th, azimuth ph."""
    return (CENTER[0] + (AXES[0] + offset) * math.sin(th) * math.sin(ph),
            CENTER[1] + (AXES[1] + offset) * math.cos(th),
            CENTER[2] + (AXES[2] + offset) * math.sin(th) * math.cos(ph))


def strand(th0, ph):
    """One strand from the root at (th0, ph): out from the scalp, along it to the side of the
    head (th = 90 degrees, where the surface is vertical), then straight down; resampled into
    HAIR_SEGMENTS equal segments of HAIR_LENGTH / HAIR_SEGMENTS."""
    dense = [scalp(th0, ph, ROOT_OFFSET)]
    for k in range(1, 21):
        dense.append(scalp(th0, ph, ROOT_OFFSET + (DRAPE_OFFSET - ROOT_OFFSET) * k / 20))
    steps = 400
    for k in range(1, steps + 1):
        dense.append(scalp(th0 + (0.5 * math.pi - th0) * k / steps, ph, DRAPE_OFFSET))
    end = dense[-1]
    for k in range(1, 401):
        dense.append((end[0], end[1] - HAIR_LENGTH * k / 400, end[2]))
    # Equal arc-length samples.
    cum = [0.0]
    for a, b in zip(dense, dense[1:]):
        cum.append(cum[-1] + math.dist(a, b))
    out, j = [], 0
    for s in range(HAIR_SEGMENTS + 1):
        want = HAIR_LENGTH * s / HAIR_SEGMENTS
        while j < len(cum) - 2 and cum[j + 1] < want:
            j += 1
        f = (want - cum[j]) / (cum[j + 1] - cum[j])
        out.append(tuple(dense[j][c] + f * (dense[j + 1][c] - dense[j][c]) for c in range(3)))
    return out


def hair():
    """Roots on the back and top of the scalp: polar angles 12-80 degrees from the crown,
    azimuths within 105 degrees of the back (-z), spaced about evenly over the surface."""
    strands = []
    for i in range(11):
        th = math.radians(12.0 + (80.0 - 12.0) * i / 10)
        count = max(4, round(22 * math.sin(th) / math.sin(math.radians(80.0))))
        for j in range(count):
            off = math.radians(-105.0 + 210.0 * (j + 0.5) / count)
            strands.append(strand(th, math.pi + off))  # azimuth pi is the back (-z)
    return strands


def main(argv):
    folder, frames, fps = "head", 48, 24.0
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--frames":
            frames = int(args.pop(0))
        elif a == "--fps":
            fps = float(args.pop(0))
        else:
            folder = a
    os.makedirs(folder, exist_ok=True)
    hv, ht = ellipsoid()
    nv, nt = neck(len(hv))
    verts, tris = hv + nv, ht + nt
    for f in range(1, frames + 1):
        move = transform((f - 1) / fps)  # frame F at t = F / fps; frame 1 is the rest pose
        with open(os.path.join(folder, "head.%04d.obj" % f), "w") as out:
            out.write("# examples/10_hair_turn/make_head.py: frame %d (yaw %.2f, pitch %.2f deg)\n"
                      % ((f,) + tuple(math.degrees(a) for a in pose((f - 1) / fps))))
            for v in verts:
                out.write("v %.6f %.6f %.6f\n" % move(v))
            for (a, b, c) in tris:
                out.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    strands = hair()
    with open("hair.csv", "w") as out:
        out.write("x,y,z,strand\n")
        for s, pts in enumerate(strands):
            for p in pts:
                out.write("%.6f,%.6f,%.6f,%d\n" % (p + (s,)))
    print("wrote %d frames of %d vertices and %d triangles to %s/, %d strands of %d vertices to hair.csv"
          % (frames, len(verts), len(tris), folder, len(strands), HAIR_SEGMENTS + 1))


if __name__ == "__main__":
    main(sys.argv[1:])
