#!/usr/bin/env python3
"""Checks a character shot from its files alone, independently of gale's code (numpy; the
triangle and segment tests are count_intersections.py's, imported): per frame, the cloth
against the body it was simulated on (the body's OBJ at that frame), against itself, and the
hair against the cloth; the cloth's edges against its rest mesh; the frame wall times of run.json.

Usage: character_check.py --body 'body/body.#.obj' --cloth 'out/cape.#.obj' --rest cape.obj
           --frames A:B [--collar I-J] [--hair 'out/hair.#.obj' [--hair-rest hair.csv]]
           [--run out/run.json] [--json] [--goals]

Per frame (a `#` run in a pattern is the zero-padded frame number):
- inside: cloth vertices inside the body: generalised winding number (Jacobson, Kavan and
  Sorkine-Hornung 2013: the sum of the signed solid angles of the body's triangles seen from the
  point, over 4 pi; 1 inside a closed surface, 0 outside) above 0.5. The body must be closed
  (every directed edge once and its reverse once), checked at every frame; hair vertices inside
  are counted too (hair_inside).
- crossings: cloth triangles that intersect a body triangle (an edge of one through the other).
- self: intersecting pairs of cloth triangles (count_intersections.countIntersections).
- hair: hair segments that pass through a cloth triangle.
- stretch: the longest cloth edge over its rest length (and the shortest, squash); hair
  segments against the strands file (hair_stretch, |length/rest - 1|).
- collar: the edges between the collar's vertices (I..J, both ends in it), their lengths over
  rest: min and max.
From run.json: wall_seconds of the frames in A:B that ran (a frame with 0 s is the initial
state), median and worst.

--goals exits 1 unless: no vertex inside, no crossing, no self-intersection, no hair crossing,
stretch <= 1.2, collar within +-5 %, worst frame <= 3 x the median; each miss is printed with
the frame and where. Exit 2 on bad arguments or unreadable files.
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from count_intersections import countIntersections, load, overlappingBoxes, segmentHitsTriangle  # noqa: E402


def frame_path(pattern, frame):
    start = pattern.find('#')
    if start < 0:
        return pattern
    end = start
    while end < len(pattern) and pattern[end] == '#':
        end += 1
    return pattern[:start] + str(frame).zfill(end - start) + pattern[end:]


def load_lines(path):
    """Vertices and polylines ('l' records, 1-based) of a hair OBJ."""
    V, L = [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == 'v':
                V.append([float(x) for x in w[1:4]])
            elif w[0] == 'l':
                L.append([int(x) - 1 for x in w[1:]])
    return np.array(V, float).reshape(-1, 3), L


def closed(F):
    """True when every directed edge appears once and its reverse once."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = e[:, 0].astype(np.int64) * (int(F.max()) + 1) + e[:, 1]
    rev = e[:, 1].astype(np.int64) * (int(F.max()) + 1) + e[:, 0]
    u, c = np.unique(key, return_counts=True)
    return bool((c == 1).all() and np.isin(rev, u).all())


def winding(P, V, F, chunk=8):
    """Generalised winding numbers of the points P about the triangle mesh (V, F): each
    triangle's signed solid angle by Van Oosterom and Strackee's formula,
    tan(Omega/2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|)."""
    A, B, C = (V[F[:, k]].T.copy() for k in range(3))  # 3 x m each
    out = np.zeros(len(P))
    for s in range(0, len(P), chunk):
        p = P[s:s + chunk]
        a = [A[k][None, :] - p[:, k:k + 1] for k in range(3)]
        b = [B[k][None, :] - p[:, k:k + 1] for k in range(3)]
        c = [C[k][None, :] - p[:, k:k + 1] for k in range(3)]
        dot = lambda u, v: u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
        la, lb, lc = np.sqrt(dot(a, a)), np.sqrt(dot(b, b)), np.sqrt(dot(c, c))
        num = (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2])
               + a[2] * (b[0] * c[1] - b[1] * c[0]))
        den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb
        out[s:s + chunk] = np.arctan2(num, den).sum(1) / (2 * np.pi)
    return out


def bipartite(loA, hiA, loB, hiB):
    """Pairs (i in A, j in B) of overlapping boxes (count_intersections' sweep on both sets)."""
    near = np.nonzero(np.all(loB <= hiA.max(0), 1) & np.all(hiB >= loA.min(0), 1))[0]  # B near A at all
    I, J = overlappingBoxes(np.vstack([loA, loB[near]]), np.vstack([hiA, hiB[near]]))
    n = len(loA)
    keep = (I < n) & (J >= n)
    return I[keep], near[J[keep] - n]


def crossing_triangles(V1, F1, V2, F2):
    """Triangles of mesh 1 whose edges cross a triangle of mesh 2 or are crossed by an edge of
    one (the meshes share no vertices): the set of such triangles of mesh 1."""
    T1, T2 = V1[F1], V2[F2]
    I, J = bipartite(T1.min(1), T1.max(1), T2.min(1), T2.max(1))
    hit = np.zeros(len(I), bool)
    for e in range(3):
        hit |= segmentHitsTriangle(T1[I][:, e], T1[I][:, (e + 1) % 3], T2[J][:, 0], T2[J][:, 1], T2[J][:, 2])
        hit |= segmentHitsTriangle(T2[J][:, e], T2[J][:, (e + 1) % 3], T1[I][:, 0], T1[I][:, 1], T1[I][:, 2])
    return np.unique(I[hit])


def segment_crossings(P, S, V, F):
    """Segments (rows of S, vertex pairs of P) that pass through a triangle of (V, F)."""
    if len(S) == 0:
        return 0
    a, b = P[S[:, 0]], P[S[:, 1]]
    T = V[F]
    I, J = bipartite(np.minimum(a, b), np.maximum(a, b), T.min(1), T.max(1))
    hit = segmentHitsTriangle(a[I], b[I], T[J][:, 0], T[J][:, 1], T[J][:, 2])
    return int(hit.sum())


def edges_of(F):
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), 1)
    return np.unique(e, axis=0)


def parse(argv):
    opts = {'json': False, 'goals': False}
    args = list(argv)
    keys = {'--body', '--cloth', '--rest', '--frames', '--collar', '--hair', '--hair-rest', '--run'}
    while args:
        a = args.pop(0)
        if a in ('--json', '--goals'):
            opts[a[2:]] = True
        elif a in keys and args:
            opts[a[2:].replace('-', '_')] = args.pop(0)
        else:
            raise ValueError('unknown or incomplete argument ' + a)
    for k in ('body', 'cloth', 'rest', 'frames'):
        if k not in opts:
            raise ValueError('--%s is required' % k)
    a, b = opts['frames'].split(':')
    opts['frames'] = range(int(a), int(b) + 1)
    if 'collar' in opts:
        i, j = opts['collar'].split('-')
        opts['collar'] = set(range(int(i), int(j) + 1))
    return opts


def main(argv):
    try:
        o = parse(argv)
    except ValueError as e:
        sys.stderr.write('character_check.py: %s\n%s' % (e, __doc__.split('\n\n')[1]))
        return 2
    try:
        R, RF = load(o['rest'])
        hair_rest = None
        if 'hair_rest' in o:
            rows = [l.split(',') for l in open(o['hair_rest']).read().split('\n')[1:] if l.strip()]
            hair_rest = np.array([[float(x) for x in r[:3]] for r in rows])
        E = edges_of(RF)
        rest_len = np.linalg.norm(R[E[:, 0]] - R[E[:, 1]], axis=1)
        collar = None
        if 'collar' in o:
            collar = np.array([a in o['collar'] and b in o['collar'] for a, b in E])
        rows = []
        for f in o['frames']:
            BV, BF = load(frame_path(o['body'], f))
            CV, CF = load(frame_path(o['cloth'], f))
            if len(CV) != len(R) or not np.array_equal(CF, RF):
                raise ValueError('%s: not the rest mesh\'s topology' % frame_path(o['cloth'], f))
            row = {'frame': f, 'body_closed': closed(BF)}
            w = winding(CV, BV, BF)
            inside = np.nonzero(w > 0.5)[0]
            row['inside'] = int(len(inside))
            row['inside_vertices'] = inside[:8].tolist()
            cross = crossing_triangles(CV, CF, BV, BF)
            row['crossings'] = int(len(cross))
            row['crossing_triangles'] = cross[:8].tolist()
            row['self'] = countIntersections(CV, CF)
            ratio = np.linalg.norm(CV[E[:, 0]] - CV[E[:, 1]], axis=1) / rest_len
            k = int(ratio.argmax())
            row['stretch'] = float(ratio[k])
            row['stretch_edge'] = E[k].tolist()
            row['squash'] = float(ratio.min())
            if collar is not None:
                row['collar'] = [float(ratio[collar].min()), float(ratio[collar].max())]
            if 'hair' in o:
                HV, HL = load_lines(frame_path(o['hair'], f))
                S = np.array([(a, b) for l in HL for a, b in zip(l, l[1:])], int).reshape(-1, 2)
                row['hair'] = segment_crossings(HV, S, CV, CF)
                row['hair_inside'] = int((winding(HV, BV, BF) > 0.5).sum())
                if hair_rest is not None:
                    h = np.linalg.norm(HV[S[:, 0]] - HV[S[:, 1]], axis=1)
                    h0 = np.linalg.norm(hair_rest[S[:, 0]] - hair_rest[S[:, 1]], axis=1)
                    row['hair_stretch'] = float(np.abs(h / h0 - 1).max())
            rows.append(row)
        walls = []
        if 'run' in o:
            run = json.load(open(o['run']))
            walls = [fr['wall_seconds'] for fr in run['frames'] if fr['frame'] in o['frames'] and fr['wall_seconds'] > 0]
    except (OSError, ValueError, KeyError, IndexError) as e:
        sys.stderr.write('character_check.py: %s\n' % e)
        return 2

    s = {'frames': len(rows),
         'body_closed': all(r['body_closed'] for r in rows),
         'inside': sum(r['inside'] for r in rows),
         'crossings': sum(r['crossings'] for r in rows),
         'self': sum(r['self'] for r in rows),
         'stretch': max(r['stretch'] for r in rows),
         'squash': min(r['squash'] for r in rows)}
    if collar is not None:
        s['collar'] = [min(r['collar'][0] for r in rows), max(r['collar'][1] for r in rows)]
    if 'hair' in o:
        s['hair'] = sum(r['hair'] for r in rows)
        s['hair_inside'] = sum(r['hair_inside'] for r in rows)
        if hair_rest is not None:
            s['hair_stretch'] = max(r['hair_stretch'] for r in rows)
    if walls:
        s['wall_median'] = float(np.median(walls))
        s['wall_worst'] = float(max(walls))
        s['wall_ratio'] = s['wall_worst'] / s['wall_median']

    misses = []
    if not s['body_closed']:
        misses.append('the body is not closed at frames %s' % [r['frame'] for r in rows if not r['body_closed']])
    for r in rows:
        f = r['frame']
        if r['inside']:
            misses.append('frame %d: %d cloth vertices inside the body (e.g. %s)' % (f, r['inside'], r['inside_vertices']))
        if r['crossings']:
            misses.append('frame %d: %d cloth triangles cross the body (e.g. %s)' % (f, r['crossings'], r['crossing_triangles']))
        if r['self']:
            misses.append('frame %d: %d self-intersecting cloth triangle pairs' % (f, r['self']))
        if r.get('hair'):
            misses.append('frame %d: %d hair segments through the cloth' % (f, r['hair']))
        if r['stretch'] > 1.2:
            misses.append('frame %d: edge %s at %.3f x its rest length' % (f, r['stretch_edge'], r['stretch']))
        if 'collar' in r and not (0.95 <= r['collar'][0] and r['collar'][1] <= 1.05):
            misses.append('frame %d: collar edges between %.3f and %.3f x rest' % (f, r['collar'][0], r['collar'][1]))
    if walls and s['wall_ratio'] > 3.0:
        misses.append('worst frame %.3f s is %.2f x the median %.3f s' % (s['wall_worst'], s['wall_ratio'], s['wall_median']))

    if o['json']:
        print(json.dumps({'summary': s, 'frames': rows, 'misses': misses}))
    else:
        print('frame inside crossings self hair hair_inside stretch squash collar_min collar_max')
        for r in rows:
            c = r.get('collar', [float('nan')] * 2)
            print('%d %d %d %d %s %s %.4f %.4f %.4f %.4f' % (r['frame'], r['inside'], r['crossings'], r['self'],
                  r.get('hair', '-'), r.get('hair_inside', '-'), r['stretch'], r['squash'], c[0], c[1]))
        print('summary ' + ' '.join('%s=%s' % (k, ('%.4g' % v) if isinstance(v, float) else
                                                 ('[%.4f,%.4f]' % tuple(v) if isinstance(v, list) else v))
                                    for k, v in s.items()))
        for m in misses:
            print('miss: ' + m)
    return 1 if (o['goals'] and misses) else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
