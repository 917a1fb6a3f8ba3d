#!/usr/bin/env python3
"""Counts intersecting triangle pairs in OBJ frames independently of gale's code (numpy: box broad
phase, edge/plane crossings tested against the other triangle by barycentric coordinates), and
optionally the minimum distance between vertex-triangle pairs that share no vertex.

Usage: count_intersections.py [--json] [--min-distance] [--reach=METRES] FRAME.obj...
       count_intersections.py --pairs [--json] A.obj B.obj [A.obj B.obj...]
Prints one line per frame (`FILE PAIRS [MIN_DISTANCE]`) and a total; --json prints one object
{"frames": [{"file", "pairs", "min_distance"?}], "frames_with_intersections", "pairs"} instead.
--pairs takes the files two at a time (one object's frame and another's at the same time, e.g. a
cloth and a collider) and counts only pairs of a triangle of A and a triangle of B; the frame is
named `A+B`.
Pairs counted: triangles sharing no vertex whose edges cross the other's interior, and triangles
sharing one vertex whose opposite edge crosses the other (neighbours sharing an edge never count).
--min-distance looks at pairs within --reach (default: a tenth of the mean edge length); a
value above the reach is an upper bound of the minimum, not the minimum.
Exit status 0 when every file was read; 2 on a bad argument or an unreadable or malformed file.
"""
import json
import sys

import numpy as np


def load(path):
    """Vertices (n x 3) and triangles (m x 3, 0-based) of an OBJ; polygons are fanned."""
    vertices, faces = [], []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            try:
                if line.startswith('v '):
                    xyz = [float(x) for x in line.split()[1:4]]
                    if len(xyz) != 3:
                        raise ValueError
                    vertices.append(xyz)
                    continue
                if not line.startswith('f '):
                    continue
                ids = [int(x.split('/')[0]) for x in line.split()[1:]]
            except ValueError:
                raise ValueError(f'{path}:{number}: not a vertex or face line of numbers: {line.strip()[:60]}')
            ids = [i - 1 if i > 0 else len(vertices) + i for i in ids]
            if len(ids) < 3 or min(ids) < 0 or max(ids) >= len(vertices):
                raise ValueError(f'{path}:{number}: bad face (vertex index out of range)')
            for k in range(1, len(ids) - 1):
                faces.append([ids[0], ids[k], ids[k + 1]])
    return np.array(vertices, float).reshape(-1, 3), np.array(faces, int).reshape(-1, 3)


def dot(a, b):
    return np.einsum('ij,ij->i', a, b)


def segmentHitsTriangle(p, q, a, b, c):
    """For rows of segments pq and triangles abc: does the segment cross the triangle's plane
    strictly (endpoints on opposite sides) at a point inside the triangle?"""
    n = np.cross(b - a, c - a)
    dp, dq = dot(p - a, n), dot(q - a, n)
    crosses = dp * dq < 0
    t = np.where(crosses, dp / np.where(crosses, dp - dq, 1), 0)
    x = p + t[:, None] * (q - p)
    v0, v1, v2 = b - a, c - a, x - a
    d00, d01, d11 = dot(v0, v0), dot(v0, v1), dot(v1, v1)
    d20, d21 = dot(v2, v0), dot(v2, v1)
    den = d00 * d11 - d01 * d01
    den = np.where(den == 0, 1, den)
    b1 = (d11 * d20 - d01 * d21) / den
    b2 = (d00 * d21 - d01 * d20) / den
    return crosses & (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1)


def overlappingBoxes(lo, hi):
    """Index pairs i < j of boxes that overlap (sweep along x after sorting)."""
    order = np.argsort(lo[:, 0], kind='stable')
    I, J = [], []
    for k, i in enumerate(order):
        rest = order[k + 1:]
        rest = rest[lo[rest, 0] <= hi[i, 0]]
        if len(rest) == 0:
            continue
        m = np.all(lo[rest] <= hi[i], 1) & np.all(hi[rest] >= lo[i], 1)
        j = rest[m]
        I.append(np.minimum(i, j))
        J.append(np.maximum(i, j))
    if not I:
        return np.zeros(0, int), np.zeros(0, int)
    return np.concatenate(I), np.concatenate(J)


def countIntersections(V, F, split=None):
    """Intersecting pairs among the triangles F; with `split`, only pairs of a triangle below
    index `split` and one from it on (two objects concatenated)."""
    T = V[F]
    I, J = overlappingBoxes(T.min(1), T.max(1))
    if split is not None:
        keep = (I < split) & (J >= split)
        I, J = I[keep], J[keep]
    shared = F[I][:, :, None] == F[J][:, None, :]
    ns = shared.sum((1, 2))
    hit = np.zeros(len(I), bool)
    # No shared vertex: any edge of one through the other.
    k = ns == 0
    a, b = I[k], J[k]
    h = np.zeros(len(a), bool)
    for x, y in ((a, b), (b, a)):
        for e in range(3):
            h |= segmentHitsTriangle(T[x][:, e], T[x][:, (e + 1) % 3], T[y][:, 0], T[y][:, 1], T[y][:, 2])
    hit[k] = h
    # One shared vertex: the edge opposite it in one triangle through the other.
    k1 = np.nonzero(ns == 1)[0]
    if len(k1):
        sh = shared[k1]
        si, sj = sh.any(2).argmax(1), sh.any(1).argmax(1)
        a, b = I[k1], J[k1]
        r = np.arange(len(k1))
        h = segmentHitsTriangle(T[a][r, (si + 1) % 3], T[a][r, (si + 2) % 3], T[b][:, 0], T[b][:, 1], T[b][:, 2])
        h |= segmentHitsTriangle(T[b][r, (sj + 1) % 3], T[b][r, (sj + 2) % 3], T[a][:, 0], T[a][:, 1], T[a][:, 2])
        hit[k1] = h
    return int(hit.sum())


def pointSegmentDistance(p, a, b):
    ab = b - a
    t = np.clip(dot(p - a, ab) / np.maximum(dot(ab, ab), 1e-300), 0, 1)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


def pointTriangleDistance(p, a, b, c):
    """Rows: the distance from p to triangle abc (the plane when the foot falls inside, else the
    nearest edge)."""
    n = np.cross(b - a, c - a)
    nn = np.maximum(dot(n, n), 1e-300)
    s = dot(p - a, n) / nn
    x = p - s[:, None] * n
    # Barycentric coordinates of the foot by signed sub-areas.
    wa = dot(np.cross(b - x, c - x), n) / nn
    wb = dot(np.cross(c - x, a - x), n) / nn
    inside = (wa >= 0) & (wb >= 0) & (1 - wa - wb >= 0)
    edge = np.minimum(np.minimum(pointSegmentDistance(p, a, b), pointSegmentDistance(p, b, c)),
                      pointSegmentDistance(p, c, a))
    return np.where(inside, np.abs(s) * np.sqrt(nn), edge)


def minimumDistance(V, F, reach):
    """The smallest distance between a vertex and a triangle not containing it, among pairs
    closer than `reach` (infinity when there are none)."""
    T = V[F]
    lo, hi = T.min(1) - reach, T.max(1) + reach
    best = np.inf
    for start in range(0, len(V), 512):
        P = V[start:start + 512]
        m = np.all(P[:, None, :] >= lo[None], 2) & np.all(P[:, None, :] <= hi[None], 2)
        pi, ti = np.nonzero(m)
        pi = pi + start
        keep = np.all(F[ti] != pi[:, None], 1)
        pi, ti = pi[keep], ti[keep]
        if len(pi):
            d = pointTriangleDistance(V[pi], T[ti, 0], T[ti, 1], T[ti, 2])
            best = min(best, float(d.min()))
    return best


def main(argv):
    args = [a for a in argv if not a.startswith('--')]
    flags = {a for a in argv if a.startswith('--') and not a.startswith('--reach=')}
    reaches = [a[len('--reach='):] for a in argv if a.startswith('--reach=')]
    unknown = flags - {'--json', '--min-distance', '--pairs'}
    pairs = '--pairs' in flags
    if pairs and ('--min-distance' in flags or len(args) % 2):
        unknown.add('--pairs (with an odd number of files or --min-distance)')
    try:
        reachArg = float(reaches[-1]) if reaches else None
    except ValueError:
        unknown.add('--reach=' + reaches[-1])
    if unknown or not args:
        sys.stderr.write(f'count_intersections.py: {"unknown option " + min(unknown) if unknown else "no OBJ files"}\n'
                         'usage: count_intersections.py [--json] [--min-distance] [--reach=METRES] FRAME.obj...\n'
                         '       count_intersections.py --pairs [--json] A.obj B.obj [A.obj B.obj...]\n')
        return 2
    frames = []
    for k, path in enumerate(args):
        if pairs and k % 2:
            continue
        try:
            V, F = load(path)
            split = None
            if pairs:
                VB, FB = load(args[k + 1])
                split = len(F)
                F = np.concatenate([F, FB + len(V)])
                V = np.concatenate([V, VB])
                path = path + '+' + args[k + 1]
        except (OSError, ValueError) as e:
            sys.stderr.write(f'count_intersections.py: {e}\n')
            return 2
        row = {'file': path, 'pairs': countIntersections(V, F, split)}
        if '--min-distance' in flags:
            # Pairs within a tenth of the mean edge length: far enough for any thickness tested.
            E = V[F[:, [1, 2, 0]]] - V[F]
            reach = 0.1 * float(np.linalg.norm(E, axis=2).mean()) if len(F) else 0.0
            reach = reachArg if reachArg is not None else reach
            row['min_distance'] = minimumDistance(V, F, reach)
        frames.append(row)
    total = sum(r['pairs'] for r in frames)
    hit = sum(r['pairs'] > 0 for r in frames)
    if '--json' in flags:
        for r in frames:
            if r.get('min_distance') == np.inf:
                r['min_distance'] = None
        print(json.dumps({'frames': frames, 'frames_with_intersections': hit, 'pairs': total}))
    else:
        for r in frames:
            extra = f" {r['min_distance']:.6g}" if 'min_distance' in r else ''
            print(f"{r['file']} {r['pairs']}{extra}")
        print(f'frames with intersections: {hit} of {len(frames)}, pairs in all: {total}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
