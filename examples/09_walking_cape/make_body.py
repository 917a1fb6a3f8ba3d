#!/usr/bin/env python3
"""examples/09_walking_cape: a mannequin that walks and turns, written as an OBJ sequence.

Plain python3 (standard library only). The body is seven capsules (torso, neck, head, two
arms, two legs) with one fixed topology; every frame poses them: the legs and arms swing with
the walk cycle, the pelvis bobs, and the whole body walks at 1.1 m/s along a heading that
turns 90 degrees to its left between 0.6 s and 1.8 s. It faces +z at frame 1, feet at y = 0,
1.75 m tall (as examples/04_shelter/body.obj).

    python3 make_body.py [folder] [--frames N] [--fps F]     (default: body/, 48 frames, 24 fps)

Frame 1 is the rest pose (the walk's time 0), as in examples/04_shelter.

writes folder/body.0001.obj ... body.00NN.obj.
"""
import math
import os
import sys

SEGMENTS = 14  # around each capsule
RINGS = 5      # per hemispherical cap (plus the two rings of the tube)


def capsule(length, radius, sx=1.0, sz=1.0):
    """A capsule along -y from the origin (its top) to y = -length: vertices, triangles."""
    verts, rings = [], []
    # Rings from the top pole down: top cap, the tube, bottom cap.
    profile = []  # (y, r)
    for k in range(1, RINGS + 1):
        a = 0.5 * math.pi * k / RINGS
        profile.append((radius * math.cos(a), radius * math.sin(a)))
    for k in range(RINGS, 0, -1):
        a = 0.5 * math.pi * (k - 1) / RINGS
        profile.append((-length - radius * math.cos(a) + 0.0, radius * math.sin(a)))
    profile = [(y, r) for (y, r) in profile if r > 1e-9]
    top = len(verts)
    verts.append((0.0, radius, 0.0))
    for (y, r) in profile:
        ring = []
        for j in range(SEGMENTS):
            p = 2.0 * math.pi * j / SEGMENTS
            ring.append(len(verts))
            verts.append((sx * r * math.cos(p), y, sz * r * math.sin(p)))
        rings.append(ring)
    bottom = len(verts)
    verts.append((0.0, -length - radius, 0.0))
    tris = []
    for j in range(SEGMENTS):
        tris.append((top, rings[0][(j + 1) % SEGMENTS], rings[0][j]))
    for a, b in zip(rings, rings[1:]):
        for j in range(SEGMENTS):
            j1 = (j + 1) % SEGMENTS
            tris.append((a[j], a[j1], b[j1]))
            tris.append((a[j], b[j1], b[j]))
    last = rings[-1]
    for j in range(SEGMENTS):
        tris.append((bottom, last[j], last[(j + 1) % SEGMENTS]))
    return verts, tris


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return ((1, 0, 0), (0, c, -s), (0, s, c))


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, 0, s), (0, 1, 0), (-s, 0, c))


def apply(m, v):
    return tuple(sum(m[r][k] * v[k] for k in range(3)) for r in range(3))


def heading(t):
    """Yaw (radians, about +y) at time t: straight, then a 90 degree left turn, then straight."""
    t0, t1 = 0.6, 1.8
    if t <= t0:
        return 0.0
    if t >= t1:
        return 0.5 * math.pi
    s = (t - t0) / (t1 - t0)
    return 0.5 * math.pi * (3 * s * s - 2 * s * s * s)


def position(t, speed=1.1, steps=2000):
    """The walked path (x, z): the integral of speed * (sin yaw, cos yaw)."""
    x = z = 0.0
    if t <= 0:
        return 0.0, 0.0
    dt = t / steps
    for k in range(steps):
        yaw = heading((k + 0.5) * dt)
        x += speed * math.sin(yaw) * dt
        z += speed * math.cos(yaw) * dt
    return x, z


# The parts: (name, pivot in the body frame, length, radius, x scale, z scale, swing).
# swing: the phase factor of the rotation about x at the pivot (legs and arms swing in opposition).
PARTS = [
    ("torso", (0.0, 1.38, 0.0), 0.42, 0.15, 1.2, 0.75, 0.0),
    ("neck", (0.0, 1.52, 0.0), 0.08, 0.05, 1.0, 1.0, 0.0),
    ("head", (0.0, 1.66, 0.0), 0.02, 0.105, 0.9, 1.0, 0.0),
    ("arm_l", (0.23, 1.40, 0.0), 0.55, 0.045, 1.0, 1.0, -1.0),
    ("arm_r", (-0.23, 1.40, 0.0), 0.55, 0.045, 1.0, 1.0, 1.0),
    ("leg_l", (0.095, 0.86, 0.0), 0.72, 0.07, 1.0, 1.0, 1.0),
    ("leg_r", (-0.095, 0.86, 0.0), 0.72, 0.07, 1.0, 1.0, -1.0),
]


def frame(t):
    verts, tris = [], []
    phase = 2.0 * math.pi * 0.9 * t  # 0.9 strides per second
    bob = 0.015 * math.cos(2.0 * phase)
    yaw = heading(t)
    px, pz = position(t)
    for (_, pivot, length, radius, sx, sz, swing) in PARTS:
        v, f = capsule(length, radius, sx, sz)
        amp = 0.45 if abs(swing) > 0 and pivot[1] < 1.0 else 0.35  # legs a little more
        m = rot_x(swing * amp * math.sin(phase)) if swing else ((1, 0, 0), (0, 1, 0), (0, 0, 1))
        base = len(verts)
        for p in v:
            q = apply(m, p)
            q = (q[0] + pivot[0], q[1] + pivot[1] + bob, q[2] + pivot[2])
            q = apply(rot_y(yaw), q)
            verts.append((q[0] + px, q[1], q[2] + pz))
        tris.extend((a + base, b + base, c + base) for (a, b, c) in f)
    return verts, tris


def main(argv):
    folder, frames, fps = "body", 48, 24.0
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
    for f in range(1, frames + 1):
        t = f / fps  # frame F is at t = F / fps, as in gale; the walk starts at frame 1
        verts, tris = frame(t - 1.0 / fps)
        with open(os.path.join(folder, "body.%04d.obj" % f), "w") as out:
            out.write("# examples/09_walking_cape/make_body.py: frame %d (t = %.4f s)\n" % (f, t))
            for v in verts:
                out.write("v %.5f %.5f %.5f\n" % v)
            for (a, b, c) in tris:
                out.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    print("wrote %d frames of %d vertices and %d triangles to %s/" % (frames, len(verts), len(tris), folder))


if __name__ == "__main__":
    main(sys.argv[1:])
