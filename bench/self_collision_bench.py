#!/usr/bin/env python3
# Issue 16's self-collision benchmark, all through `gale sim`: a 64x64 cape folding in gusts
# (examples/03_cape with res = [64, 64] and a strength-25 gust) with and without self_collision,
# both measured in the same run: the ratio of wall times, run.json's per-stage seconds (broad,
# proximity, ccd, fail-safe) and fail-safe runs, on 1 and 2 threads; then speed against
# thickness (1, 3, 6 mm) and substeps (2, 4, 8): time ratio, minimum vertex-triangle distance
# of the `on` run and intersecting pairs of both (tests/cli/count_intersections.py).
#   bench/self_collision_bench.py [--build build] [--repeats 1] [--quick]
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CAPE = os.path.join(ROOT, "examples", "03_cape", "scene.toml")
sys.path.insert(0, os.path.join(ROOT, "tests", "cli"))
import count_intersections  # noqa: E402  (the independent counter, beside the CLI tests)


def scene(on, thickness, substeps):
    """The 64x64 cape: the example's text with the resolution, the gust, substeps and the
    self-collision keys replaced."""
    text = open(CAPE).read()
    text = re.sub(r"res = \[\d+, \d+\]", "res = [64, 64]", text)
    text = re.sub(r"(?m)^strength = .*$", "strength = 25.0", text)
    text = re.sub(r"(?m)^substeps = \d+", "substeps = %d" % substeps, text)
    text = re.sub(r"(?m)^(self_collision|thickness) = .*\n", "", text)
    text = re.sub(r"(?m)^(drag = .*)$", r"\1\nself_collision = %s\nthickness = %g"
                  % ("true" if on else "false", thickness), text, count=1)
    return text


def simulate(args, work, name, on, thickness=0.003, substeps=4, threads=2):
    """Runs `gale sim` --repeats times; returns (median wall seconds, run.json, output folder)."""
    path = os.path.join(work, name + ".toml")
    with open(path, "w") as f:
        f.write(scene(on, thickness, substeps))
    walls = []
    for _ in range(args.repeats):
        out = os.path.join(work, name)
        shutil.rmtree(out, ignore_errors=True)
        start = time.perf_counter()
        r = subprocess.run([os.path.join(args.build, "cli", "gale"), "sim", path, "-o", out,
                            "--threads", str(threads)], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True)
        walls.append(time.perf_counter() - start)
        if r.returncode != 0:
            sys.exit("gale sim %s: exit %d: %s" % (path, r.returncode, r.stderr[-400:]))
    with open(os.path.join(out, "run.json")) as f:
        return statistics.median(walls), json.load(f), out


def stages(run):
    """Summed self-collision seconds per stage, fail-safe runs and unresolved pairs, halvings."""
    s = {"broad": 0.0, "proximity": 0.0, "ccd": 0.0, "fail_safe": 0.0}
    runs = unresolved = halved = 0
    for f in run["frames"]:
        sc = f.get("self_collision")
        if sc:
            for k in s:
                s[k] += sc["seconds"][k]
            runs += sc["fail_safe_runs"]
            unresolved += sc["unresolved"]
        halved += sum(o["rejected_substeps"] for o in f["objects"])
    return s, runs, unresolved, halved


def frames(out, step):
    names = sorted(n for n in os.listdir(out) if n.endswith(".obj"))
    return [os.path.join(out, n) for n in names[::step]]


def pairs(out):
    return sum(count_intersections.countIntersections(*count_intersections.load(p))
               for p in frames(out, 1))


def minDistance(out, thickness, step):
    best = float("inf")
    for p in frames(out, step):
        V, F = count_intersections.load(p)
        best = min(best, count_intersections.minimumDistance(V, F, 2 * thickness))
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="threads table only")
    ap.add_argument("--distance-step", type=int, default=4,
                    help="minimum distance on every N-th frame (it costs ~1 s a frame)")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="gale_selfcoll_bench.")
    try:
        print("### 64x64 cape in gusts, thickness 3 mm, 4 substeps, 48 frames\n")
        print("| threads | off s | on s | on / off | broad s | proximity s | ccd s | fail-safe s "
              "| fail-safe runs | unresolved | rejected substeps |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for threads in (2, 1):
            off, _, _ = simulate(args, work, "off%d" % threads, False, threads=threads)
            on, run, _ = simulate(args, work, "on%d" % threads, True, threads=threads)
            s, runs, unresolved, halved = stages(run)
            print("| %d | %.2f | %.2f | **%.2f×** | %.2f | %.2f | %.2f | %.3f | %d | %d | %d |"
                  % (threads, off, on, on / off, s["broad"], s["proximity"], s["ccd"],
                     s["fail_safe"], runs, unresolved, halved), flush=True)
        if args.quick:
            return
        print("\n### Against thickness and substeps (2 threads; minimum distance on every %d-th "
              "frame)\n" % args.distance_step)
        print("| thickness mm | substeps | off s | on s | on / off | fail-safe runs | unresolved "
              "| on: min distance mm | on: pairs | off: pairs |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for thickness, substeps in ((0.001, 4), (0.003, 4), (0.006, 4), (0.003, 2), (0.003, 8)):
            tag = "%g_%d" % (thickness * 1000, substeps)
            off, _, offOut = simulate(args, work, "off" + tag, False, thickness, substeps)
            on, run, onOut = simulate(args, work, "on" + tag, True, thickness, substeps)
            _, runs, unresolved, _ = stages(run)
            print("| %g | %d | %.2f | %.2f | **%.2f×** | %d | %d | %.2f | %d | %d |"
                  % (thickness * 1000, substeps, off, on, on / off, runs, unresolved,
                     1000 * minDistance(onOut, thickness, args.distance_step), pairs(onOut),
                     pairs(offOut)), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
