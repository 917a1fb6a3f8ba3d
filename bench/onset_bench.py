#!/usr/bin/env python3
# Issue 26's wind-onset flag (bench/scenes/wind_onset_flag.toml) through `gale sim`.
#
# Default mode: per resolution, the frame cost with plain and with smoothed aggregation (the
# scene key `multigrid`), both measured in the same run, and the automatic choice; median frame
# wall over frames 4..13, the worst frame over that median, median CG iterations, the
# smoothed/plain ratio.
#   bench/onset_bench.py [--build build] [--res 32,64,128] [--threads 1] [--frames 1:13]
#                        [--kinds plain,smoothed,auto]
#
# --responses: the response to a substep in trouble instead (issue 26, third pass), each
# response a name and `[solver]` settings, e.g.
#   --responses 'repeat16=retry_repeat=true,retry_newton=16;halve=retry_newton=0,grow_back=true'
# (a dotted key is any scene key: 'bounded=cloth.flag.aero_jacobian="bounded"')
# per response: median frame wall (frames 4..), worst frame / median (wall and CG iterations:
# the frame's summed CG iterations over the median frame's), max stretch over the run, Newton
# retries, rejected substeps and the deepest halving, and — with --reference-substeps N — the
# largest vertex distance at the last frame from the same scene at N substeps per frame (run
# once per resolution with the first response's settings).
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


def run(args, res, sets, out):
    cmd = [os.path.join(args.build, "cli", "gale"), "sim", SCENE, "-o", out, "--threads",
           str(args.threads), "--frames", args.frames, "--set", "cloth.flag.grid.res=[%d, %d]" % (res, res)]
    if args.onset_time > 0:
        # The same gusting wind switched on at onset_time (s): the onset frame is then not the
        # first stepped frame, whose wall time also holds the solver's one-time set-up.
        cmd += ["--set", 'field.wind.source="$speed = ($t >= %g ? 12 : 0) * (1 + 0.25 * sin(2 * PI * '
                '(1.5 * $t - 0.5 * $P[0]))); [$speed, 0, 0.15 * $speed]"' % args.onset_time]
    for s in sets:
        cmd += ["--set", s]
    shutil.rmtree(out, ignore_errors=True)
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    path = os.path.join(out, "run.json")
    if not os.path.exists(path):
        sys.exit("onset_bench.py: `%s` exited %d:\n%s" % (" ".join(cmd), p.returncode, p.stderr[-2000:]))
    with open(path) as f:
        return json.load(f)


def last_positions(out, r):
    last = max(f["frame"] for f in r["frames"])
    pts = []
    with open(os.path.join(out, "flag.%04d.obj" % last)) as f:
        for line in f:
            if line.startswith("v "):
                pts.append(tuple(float(x) for x in line.split()[1:4]))
    return pts


def summary(r, first=4):
    # Median over frames from `first` on; worst over all stepped frames (with a late onset, all
    # but the first stepped frame, which holds the one-time set-up and no trouble).
    frames = [f for f in r["frames"] if f["objects"][0]["substeps"] > 0]
    if first > 4:
        frames = frames[1:]
    walls = [f["wall_seconds"] for f in frames]
    steady = [f["wall_seconds"] for f in frames if f["frame"] >= first] or walls
    med = statistics.median(steady)
    o = [f["objects"][0] for f in frames]
    its = statistics.median([x["solver_iterations"] / max(1, x["substeps"]) for x in o])
    work = [x["solver_iterations"] for x in o]
    medWork = statistics.median([x["solver_iterations"] for f, x in zip(frames, o) if f["frame"] >= first] or work)
    return {"median": med, "worst": max(walls), "worst_frame": frames[walls.index(max(walls))]["frame"],
            "its": its, "newton": sum(x["newton_iterations"] for x in o),
            "retries": sum(x["newton_retries"] for x in o),
            "rejected": sum(x["rejected_substeps"] for x in o),
            "work": max(work) / medWork, "work_frame": frames[work.index(max(work))]["frame"],
            "halvings": max(x["deepest_halving"] for x in o), "stretch": max(x["max_stretch"] for x in o)}


def kinds_mode(args, tmp):
    kinds = args.kinds.split(",")
    print("| res | multigrid | median frame s | per vertex µs | worst/median (frame) | CG its | Newton its | halvings | max stretch | /plain |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for res in [int(x) for x in args.res.split(",")]:
        base = None
        for kind in kinds:
            s = summary(run(args, res, ['cloth.flag.multigrid="%s"' % kind], os.path.join(tmp, "%d_%s" % (res, kind))))
            if base is None:
                base = s["median"]
            print("| %d² | %s | %.4f | %.2f | %.1f× (%d) | %g | %d | %d | %.3f | %.2f |" % (
                res, kind, s["median"], 1e6 * s["median"] / (res * res), s["worst"] / s["median"],
                s["worst_frame"], s["its"], s["newton"], s["halvings"], s["stretch"], s["median"] / base))
            sys.stdout.flush()


def responses_mode(args, tmp):
    responses = []
    for item in args.responses.split(";"):
        name, _, sets = item.partition("=")
        # A bare key is a [solver] one; a dotted one (cloth.flag.aero_jacobian=...) is taken as is.
        responses.append((name, [s if "." in s.split("=")[0] else "solver." + s for s in sets.split(",") if s]))
    print("| res | response | median frame s | worst/median wall (frame) | worst/median CG its (frame) | max stretch | retries | Newton its | rejected | deepest halving | distance to ref (m) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for res in [int(x) for x in args.res.split(",")]:
        ref = None
        if args.reference_substeps:
            out = os.path.join(tmp, "%d_ref" % res)
            rr = run(args, res, responses[0][1] + ["scene.substeps=%d" % args.reference_substeps], out)
            ref = last_positions(out, rr)
            print("| %d² | reference: %d substeps | | | | %.3f | | | | | 0 |" % (
                res, args.reference_substeps, max(f["objects"][0]["max_stretch"] for f in rr["frames"])))
        for name, sets in responses:
            out = os.path.join(tmp, "%d_%s" % (res, name))
            r = run(args, res, sets, out)
            s = summary(r, first=int(args.onset_time * 24 + 1e-9) + 3 if args.onset_time > 0 else 4)
            dist = ""
            if ref is not None:
                x = last_positions(out, r)
                dist = "%.4f" % max(sum((a - b) ** 2 for a, b in zip(p, q)) ** 0.5 for p, q in zip(x, ref))
            print("| %d² | %s | %.4f | %.1f× (%d) | %.1f× (%d) | %.3f | %d | %d | %d | %d | %s |" % (
                res, name, s["median"], s["worst"] / s["median"], s["worst_frame"], s["work"], s["work_frame"],
                s["stretch"], s["retries"], s["newton"], s["rejected"], s["halvings"], dist))
            sys.stdout.flush()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--res", default="32,64,128")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--frames", default="1:13")
    ap.add_argument("--kinds", default="plain,smoothed,auto")
    ap.add_argument("--responses", default="")
    ap.add_argument("--reference-substeps", type=int, default=0)
    ap.add_argument("--onset-time", type=float, default=0.0)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="gale_onset_")
    if args.responses:
        responses_mode(args, tmp)
    else:
        kinds_mode(args, tmp)
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
