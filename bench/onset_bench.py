#!/usr/bin/env python3
# Issue 26's wind-onset flag (bench/scenes/wind_onset_flag.toml) through `gale sim`: per
# resolution, the frame cost with plain and with smoothed aggregation (the scene key
# `multigrid`), both measured in the same run, and the automatic choice; median frame wall over
# frames 4..13, the worst frame over that median, median CG iterations, the smoothed/plain ratio.
#   bench/onset_bench.py [--build build] [--res 32,64,128] [--threads 1] [--frames 1:13]
#                        [--kinds plain,smoothed,auto]
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "bench", "scenes", "wind_onset_flag.toml")


def run(args, res, kind, out):
    cmd = [os.path.join(args.build, "cli", "gale"), "sim", SCENE, "-o", out, "--threads",
           str(args.threads), "--frames", args.frames, "--set", "cloth.flag.grid.res=[%d, %d]" % (res, res),
           "--set", 'cloth.flag.multigrid="%s"' % kind]
    shutil.rmtree(out, ignore_errors=True)
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    path = os.path.join(out, "run.json")
    if not os.path.exists(path):
        sys.exit("onset_bench.py: `%s` exited %d:\n%s" % (" ".join(cmd), p.returncode, p.stderr[-2000:]))
    with open(path) as f:
        return json.load(f)


def summary(r):
    frames = [f for f in r["frames"] if f["objects"][0]["substeps"] > 0]
    walls = [f["wall_seconds"] for f in frames]
    steady = [f["wall_seconds"] for f in frames if f["frame"] >= 4] or walls
    med = statistics.median(steady)
    o = [f["objects"][0] for f in frames]
    its = statistics.median([x["solver_iterations"] / max(1, x["substeps"]) for x in o])
    return {"median": med, "worst": max(walls), "worst_frame": frames[walls.index(max(walls))]["frame"],
            "its": its, "newton": sum(x["newton_iterations"] for x in o),
            "halvings": max(x["deepest_halving"] for x in o), "stretch": max(x["max_stretch"] for x in o)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--res", default="32,64,128")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--frames", default="1:13")
    ap.add_argument("--kinds", default="plain,smoothed,auto")
    args = ap.parse_args()
    kinds = args.kinds.split(",")
    tmp = tempfile.mkdtemp(prefix="gale_onset_")
    print("| res | multigrid | median frame s | per vertex µs | worst/median (frame) | CG its | Newton its | halvings | max stretch | /plain |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for res in [int(x) for x in args.res.split(",")]:
        base = None
        for kind in kinds:
            s = summary(run(args, res, kind, os.path.join(tmp, "%d_%s" % (res, kind))))
            if base is None:
                base = s["median"]
            print("| %d² | %s | %.4f | %.2f | %.1f× (%d) | %g | %d | %d | %.3f | %.2f |" % (
                res, kind, s["median"], 1e6 * s["median"] / (res * res), s["worst"] / s["median"],
                s["worst_frame"], s["its"], s["newton"], s["halvings"], s["stretch"], s["median"] / base))
            sys.stdout.flush()
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
