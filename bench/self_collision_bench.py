#!/usr/bin/env python3
# Issue 16's self-collision benchmark, all through `gale sim`: a 64x64 cape folding in gusts
# (examples/03_cape with res = [64, 64] and a strength-25 gust) with and without self_collision,
# both measured in the same run: the ratio of wall times, run.json's per-stage seconds (broad,
# proximity, ccd, fail-safe) and fail-safe runs, on 1 and 2 threads; then speed against
# thickness (1, 3, 6 mm) and substeps (2, 4, 8): time ratio, minimum vertex-triangle distance
# of the `on` run and intersecting pairs of both (tests/cli/count_intersections.py). The folding
# sheet (bench/scenes/folding_sheet.toml, issue 27) the same way; --baseline BUILD runs another
# build's gale alternately with this one (before/after of a change, in the same run). Times are
# wall and user CPU seconds of the process (the machine is shared: CPU seconds scatter less).
#   bench/self_collision_bench.py [--build build] [--repeats 1] [--quick] [--only cape|fold]
#                                 [--baseline /work/main/build]
#   bench/self_collision_bench.py --only gusts [--strengths 20,22,...] [--threads 1] [--no-count]
#     (the cape at several gust strengths: one trajectory is chaotic, their sum is fairer)
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
FOLD = os.path.join(ROOT, "bench", "scenes", "folding_sheet.toml")
sys.path.insert(0, os.path.join(ROOT, "tests", "cli"))
import count_intersections  # noqa: E402  (the independent counter, beside the CLI tests)


def scene(on, thickness, substeps, strength=25.0):
    """The 64x64 cape: the example's text with the resolution, the gust (its strength, m/s),
    substeps and the self-collision keys replaced."""
    text = open(CAPE).read()
    text = re.sub(r"res = \[\d+, \d+\]", "res = [64, 64]", text)
    text = re.sub(r"(?m)^strength = .*$", "strength = %g" % strength, text)
    text = re.sub(r"(?m)^substeps = \d+", "substeps = %d" % substeps, text)
    text = re.sub(r"(?m)^(self_collision|thickness) = .*\n", "", text)
    text = re.sub(r"(?m)^(drag = .*)$", r"\1\nself_collision = %s\nthickness = %g"
                  % ("true" if on else "false", thickness), text, count=1)
    return text


def foldScene(on):
    """The folding sheet with self_collision set."""
    return re.sub(r"(?m)^self_collision = .*$", "self_collision = %s" % ("true" if on else "false"),
                  open(FOLD).read())


def runGale(args, build, work, name, text, threads):
    """Runs `gale sim` --repeats times; returns (median wall s, median user CPU s, run.json,
    output folder)."""
    path = os.path.join(work, name + ".toml")
    with open(path, "w") as f:
        f.write(text)
    walls, cpus = [], []
    for _ in range(args.repeats):
        out = os.path.join(work, name)
        shutil.rmtree(out, ignore_errors=True)
        start = time.perf_counter()
        p = subprocess.Popen([os.path.join(build, "cli", "gale"), "sim", path, "-o", out,
                              "--threads", str(threads)], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
        err = p.stderr.read()
        _, status, usage = os.wait4(p.pid, 0)
        walls.append(time.perf_counter() - start)
        cpus.append(usage.ru_utime)
        if os.waitstatus_to_exitcode(status) != 0:
            sys.exit("gale sim %s: exit %d: %s" % (path, os.waitstatus_to_exitcode(status),
                                                   err[-400:]))
    with open(os.path.join(out, "run.json")) as f:
        return statistics.median(walls), statistics.median(cpus), json.load(f), out


def simulate(args, work, name, on, thickness=0.003, substeps=4, threads=2):
    """The cape: (median wall seconds, run.json, output folder)."""
    wall, _, data, out = runGale(args, args.build, work, name, scene(on, thickness, substeps),
                                 threads)
    return wall, data, out


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


def passes(run):
    """Self-collision passes and candidate gatherings (full and incremental) of a run."""
    n = g = 0
    for f in run["frames"]:
        sc = f.get("self_collision")
        if sc:
            n += sc["passes"]
            g += sc["broad_phases"]
    return n, g


def folding(args, work):
    """The folding sheet on and off, 2 and 1 threads; with --baseline, that build's gale and
    this one alternately, each pair of runs (off, on) back to back."""
    builds = [("this", args.build)]
    if args.baseline:
        builds.insert(0, ("baseline", args.baseline))
    print("### Folding sheet (bench/scenes/folding_sheet.toml), 64x64, 3 mm, 4 substeps, "
          "49 frames\n")
    print("| build | threads | off s | on s | on / off | off CPU s | on CPU s | on / off CPU "
          "| broad s | proximity s | ccd s | passes | gatherings | rejected substeps | "
          "unresolved | on: pairs | on: min distance mm |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for threads in (2, 1):
        for label, build in builds:
            tag = "%s%d" % (label, threads)
            off, offCpu, _, _ = runGale(args, build, work, "foldoff" + tag, foldScene(False),
                                        threads)
            on, onCpu, data, out = runGale(args, build, work, "foldon" + tag, foldScene(True),
                                           threads)
            s, _, unresolved, halved = stages(data)
            n, g = passes(data)
            print("| %s | %d | %.2f | %.2f | **%.2f×** | %.2f | %.2f | **%.2f×** | %.2f | %.2f | "
                  "%.2f | %d | %d | %d | %d | %d | %.2f |"
                  % (label, threads, off, on, on / off, offCpu, onCpu, onCpu / offCpu,
                     s["broad"], s["proximity"], s["ccd"], n, g, halved, unresolved, pairs(out),
                     1000 * minDistance(out, 0.003, args.distance_step)), flush=True)
    print()


def gusts(args, work):
    """The cape at several gust strengths (one chaotic trajectory each: the cape's halvings and
    the pass's work vary by 2-3x from one strength to the next), on and off back to back, per
    strength and summed; with --baseline, that build's pair of runs before this one's."""
    strengths = [float(v) for v in args.strengths.split(",")]
    builds = [("this", args.build)]
    if args.baseline:
        builds.insert(0, ("baseline", args.baseline))
    print("### 64x64 cape, gust strengths %s m/s, 3 mm, 4 substeps, 48 frames, %d thread(s)\n"
          % (args.strengths, args.threads))
    print("| build | strength m/s | off CPU s | on CPU s | on / off CPU | off s | on s | on / off "
          "| halved | solved again | on: pairs |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    total = {label: [0.0, 0.0, 0.0, 0.0, 0, 0] for label, _ in builds}
    for strength in strengths:
        for label, build in builds:
            tag = "%s%g" % (label, strength)
            off, offCpu, _, _ = runGale(args, build, work, "goff" + tag,
                                        scene(False, 0.003, 4, strength), args.threads)
            on, onCpu, data, out = runGale(args, build, work, "gon" + tag,
                                           scene(True, 0.003, 4, strength), args.threads)
            halved = sum(f.get("self_collision", {}).get("halvings", 0) for f in data["frames"])
            again = sum(f.get("self_collision", {}).get("retries", 0) for f in data["frames"])
            t = total[label]
            for k, v in enumerate((offCpu, onCpu, off, on, halved, again)):
                t[k] += v
            print("| %s | %g | %.2f | %.2f | **%.2f×** | %.2f | %.2f | %.2f× | %d | %d | %s |"
                  % (label, strength, offCpu, onCpu, onCpu / offCpu, off, on, on / off, halved,
                     again, "–" if args.no_count else pairs(out)), flush=True)
    for label, _ in builds:
        t = total[label]
        print("| %s | all | %.2f | %.2f | **%.2f×** | %.2f | %.2f | **%.2f×** | %d | %d | |"
              % (label, t[0], t[1], t[1] / t[0], t[2], t[3], t[3] / t[2], t[4], t[5]))
    print()


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
    ap.add_argument("--quick", action="store_true", help="threads tables only")
    ap.add_argument("--only", choices=("cape", "fold", "gusts"), help="one scene's tables")
    ap.add_argument("--strengths", default="20,22,24,25,26,28,30",
                    help="--only gusts: the gust strengths (m/s) of the cape")
    ap.add_argument("--threads", type=int, default=1, help="--only gusts: threads")
    ap.add_argument("--no-count", action="store_true",
                    help="--only gusts: skip counting the on runs' intersecting pairs (the slow part)")
    ap.add_argument("--baseline", help="another build folder whose gale runs alternately")
    ap.add_argument("--distance-step", type=int, default=4,
                    help="minimum distance on every N-th frame (it costs ~1 s a frame)")
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="gale_selfcoll_bench.")
    try:
        if args.only == "gusts":
            gusts(args, work)
            return
        if args.only != "cape":
            folding(args, work)
        if args.only == "fold":
            return
        print("### 64x64 cape in gusts, thickness 3 mm, 4 substeps, 48 frames\n")
        print("| build | threads | off s | on s | on / off | off CPU s | on CPU s | on / off CPU "
              "| broad s | proximity s | ccd s | fail-safe s | fail-safe runs | unresolved "
              "| rejected substeps | on: pairs |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        builds = [("this", args.build)]
        if args.baseline:
            builds.insert(0, ("baseline", args.baseline))
        for threads in (2, 1):
            for label, build in builds:
                tag = "%s%d" % (label, threads)
                text = [scene(on, 0.003, 4) for on in (False, True)]
                off, offCpu, _, _ = runGale(args, build, work, "off" + tag, text[0], threads)
                on, onCpu, data, out = runGale(args, build, work, "on" + tag, text[1], threads)
                s, runs, unresolved, halved = stages(data)
                print("| %s | %d | %.2f | %.2f | **%.2f×** | %.2f | %.2f | **%.2f×** | %.2f | %.2f "
                      "| %.2f | %.3f | %d | %d | %d | %d |"
                      % (label, threads, off, on, on / off, offCpu, onCpu, onCpu / offCpu,
                         s["broad"], s["proximity"], s["ccd"], s["fail_safe"], runs, unresolved,
                         halved, pairs(out)), flush=True)
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
