#!/usr/bin/env python3
# Issue 14's flag benchmarks, all through `gale sim` (whatever the binary does; every count is
# read back from run.json): gale against Bullet's soft body on the gossamer flag ("peer"), error
# against a fine-step reference versus time ("error"), and Newton/CG iterations per step
# for 32², 64², 128² flags ("iterations"). Each section prints a Markdown table; ratios are
# against a baseline measured in the same run, and every timing is the median of --repeats.
#   bench/flag_bench.py [--build build] [--only peer|error|iterations] [--repeats 3] [--quick]
import argparse
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLAG = os.path.join(ROOT, "bench", "scenes", "gossamer_flag.toml")
FRAMES_AFTER_REST = 47  # the scene's frames 1..48: frame 1 is the rest state


def wind_set(speed, angle=3.0):
    return ("field.wind.source=$speed = %g; [$speed * cos(%g * PI / 180), 0, "
            "$speed * sin(%g * PI / 180)]" % (speed, angle, angle))


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_gale(args, sets, out, frames=None):
    """One `gale sim` of the flag on one thread; returns run.json, process wall and CPU seconds."""
    cmd = [os.path.join(args.build, "cli", "gale"), "sim", FLAG, "-o", out, "--threads", "1",
           "--set", "scene.air_density=1.2"]
    if frames:
        cmd += ["--frames", frames]
    for s in sets:
        cmd += ["--set", s]
    shutil.rmtree(out, ignore_errors=True)  # no frames left over from an earlier run
    cpu0, wall0 = child_cpu(), time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall, cpu = time.perf_counter() - wall0, child_cpu() - cpu0
    path = os.path.join(out, "run.json")
    if not os.path.exists(path):
        sys.exit("flag_bench.py: `%s` exited %d without run.json:\n%s"
                 % (" ".join(cmd), p.returncode, p.stderr.strip()[-2000:]))
    with open(path) as f:
        run = json.load(f)
    run["_exit"] = p.returncode
    return run, wall, cpu


def summarise(run):
    """Per-frame sums over the simulated frames (those that took substeps) of run.json."""
    frames = [f for f in run["frames"] if f["objects"][0]["substeps"] > 0]
    objs = [f["objects"][0] for f in frames]
    keys = ["substeps", "rejected_substeps", "newton_retries", "recovered_substeps",
            "solver_iterations", "newton_iterations", "line_search_cuts", "newton_unconverged"]
    s = {k: sum(o.get(k, 0) for o in objs) for k in keys}
    s["frames"] = len(frames)
    s["step_seconds"] = sum(f["wall_seconds"] for f in frames)
    s["max_cg"] = max((o.get("max_iterations", 0) for o in objs), default=0)
    s["max_newton"] = max((o.get("max_newton_iterations", 0) for o in objs), default=0)
    s["max_newton_residual"] = max((o.get("max_newton_residual", 0) for o in objs), default=0)
    s["max_stretch"] = max((o.get("max_stretch", 0) for o in objs), default=0)
    s["status"] = run["status"]
    s["exit"] = run["_exit"]
    return s


def read_obj(path):
    pts = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                pts.append(tuple(float(x) for x in line.split()[1:4]))
    return pts


def median_runs(n, fn):
    """Runs fn() n times; returns the last result and the median of each timing it returns."""
    results = [fn() for _ in range(n)]
    timings = [statistics.median(r[i] for r in results) for i in range(1, len(results[0]))]
    return results[-1][0], timings


# ---------------------------------------------------------------------------------------------
# peer: gale at one substep per frame against Bullet's soft body (bench/bullet_flag_bench.cpp)

def run_bullet(args, speed, steps, iterations, lift):
    exe = os.path.join(args.build, "bench", "gale_bench_bullet_flag")
    cmd = [exe, "--wind", str(speed), "--steps-per-frame", str(steps), "--iterations",
           str(iterations), "--lift", str(lift), "--frames", str(FRAMES_AFTER_REST)]
    cpu0, wall0 = child_cpu(), time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    wall, cpu = time.perf_counter() - wall0, child_cpu() - cpu0
    d = json.loads(p.stdout)
    return d, d["ms_per_frame"], d["cpu_ms_per_frame"], 1000 * wall / d["frames"], \
        1000 * cpu / d["frames"]


def peer(args, tmp):
    exe = os.path.join(args.build, "bench", "gale_bench_bullet_flag")
    if not os.path.exists(exe):
        print("peer: %s is not built (needs Debian's libbullet-dev; bench/peer_bench.sh "
              "installs it and builds it)" % exe)
        return
    speeds = [20] if args.quick else [20, 40]
    steps_list = [16, 32, 64, 128]  # per 1/24 s frame: 1/384, 1/768, 1/1536, 1/3072 s
    # Bullet's position iterations (1 = its default) and lift coefficient: gale's 0.3, and 0.3·U,
    # which gives Bullet's lift (one power of |v| lower) gale's magnitude at U.
    variants = [(1, 1.0), (2, 1.0), (4, 1.0), (2, None), (4, None)]
    print("\n### gale against Bullet's soft body (%d frames, one thread, median of %d)\n"
          % (FRAMES_AFTER_REST, args.repeats))
    print("| wind | solver | step (s) | bounded | max stretch | step ms/frame (wall) | "
          "ms/frame (CPU) | process ms/frame (CPU) | gale / this (CPU per frame) | "
          "gale / this (process CPU) | gale / this (step wall) |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for speed in speeds:
        out = os.path.join(tmp, "peer")
        # gale per frame: the frames' own wall_seconds (the step), and the process CPU time
        # less that of a run of the rest frame alone (start-up, scene, first OBJ), per frame:
        # step plus output. Bullet: its stepping loop (wall and CPU) and its whole process.
        _, (wall0, cpu0) = median_runs(args.repeats, lambda: run_gale(
            args, [wind_set(speed)], out, "1:1"))
        run, (wall, cpu) = median_runs(args.repeats, lambda: run_gale(
            args, [wind_set(speed)], out))
        s = summarise(run)
        g = (1000 * s["step_seconds"] / s["frames"], 1000 * (cpu - cpu0) / s["frames"],
             1000 * cpu / s["frames"])
        label = "gale, 1 substep/frame (%d retried, %d rejected, %s)" % (
            s["newton_retries"], s["rejected_substeps"], s["status"])
        rows = [(label, "1/24", "yes", s["max_stretch"]) + g]
        best = None
        for its, lift in variants:
            lift = 0.3 if lift else 0.3 * speed
            for steps in steps_list:
                d, t = median_runs(args.repeats, lambda: run_bullet(args, speed, steps, its, lift))
                rows.append(("Bullet, %d position iteration%s, lift %g" % (
                    its, "s" if its > 1 else "", lift),
                             "1/%d" % (24 * steps), "yes" if d["bounded"] else
                             "no (frame %d)" % d["first_unbounded_frame"],
                             d["max_stretch"] if d["max_stretch"] >= 0 else math.inf,
                             t[0], t[1], t[3]))
                if d["bounded"] and (best is None or t[1] < best[5]):
                    best = rows[-1]
        for r in rows:
            print("| %d m/s | %s | %s | %s | %.3g | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |" % (
                (speed,) + r + (g[1] / r[5], g[2] / r[6], g[0] / r[4])))
        if best:
            print("| %d m/s | cheapest bounded Bullet (CPU): %s at %s | | | | | | | **%.2f** | "
                  "%.2f | %.2f |" % (speed, best[0], best[1], g[1] / best[5], g[2] / best[6],
                                     g[0] / best[4]))


# ---------------------------------------------------------------------------------------------
# error: speed against error against a fine-step reference

def frame_shapes(out, frames):
    return {f: read_obj(os.path.join(out, "flag.%04d.obj" % f)) for f in frames}


def mean_shape(out, first, last):
    acc = None
    for f in range(first, last + 1):
        pts = read_obj(os.path.join(out, "flag.%04d.obj" % f))
        if acc is None:
            acc = [[0.0, 0.0, 0.0] for _ in pts]
        for a, p in zip(acc, pts):
            for k in range(3):
                a[k] += p[k] / (last - first + 1)
    return acc


def distances(a, b):
    d = [math.dist(p, q) for p, q in zip(a, b)]
    return math.sqrt(sum(x * x for x in d) / len(d)), max(d)


def tip_heights(out, first, last, tip):
    return [read_obj(os.path.join(out, "flag.%04d.obj" % f))[tip][1]
            for f in range(first, last + 1)]


def error(args, tmp):
    speed = 20
    checkpoints = [2, 6, 12, 24]
    last = 24 if args.quick else 48
    frames = "1:%d" % last
    ref_sub = args.ref_substeps // 4 if args.quick else args.ref_substeps
    ref_sets = [wind_set(speed), "scene.substeps=%d" % ref_sub,
                "cloth.flag.newton_iterations=%d" % args.ref_newton,
                "cloth.flag.newton_tolerance=1e-4", "cloth.flag.cg_tolerance=1e-6"]
    ref = os.path.join(tmp, "ref")
    t0 = time.perf_counter()
    ref_run, _, _ = run_gale(args, ref_sets, ref, frames)
    ref_wall = time.perf_counter() - t0
    rs = summarise(ref_run)
    if rs["status"] != "ok":
        sys.exit("flag_bench.py: the reference run ended '%s' (exit %d); try --ref-substeps"
                 % (rs["status"], rs["exit"]))
    n = len(read_obj(os.path.join(ref, "flag.0001.obj")))
    tip = n - 1  # the free corner (x = 1, y = 2 at rest)
    ref_shapes = frame_shapes(ref, checkpoints)
    ref_mean = mean_shape(ref, 2, last)
    ref_tip = tip_heights(ref, 2, last, tip)
    ref_tip_mean = statistics.fmean(ref_tip)
    ref_tip_sd = statistics.pstdev(ref_tip)
    print("\n### Speed against error (gossamer flag, %d m/s, frames 1-%d, one thread, median of "
          "%d)\n" % (speed, last, args.repeats))
    print("Reference: %d substeps/frame, newton_iterations = %d, newton_tolerance = 1e-4 m/s, "
          "cg_tolerance = 1e-6: %s, %.1f s, %d of %d substeps above the Newton tolerance, "
          "largest Newton residual %.3g m/s, %.1f Newton iterations/substep; tip height mean "
          "%.4f m, standard deviation %.4f m.\n" % (
              ref_sub, args.ref_newton, rs["status"], ref_wall, rs["newton_unconverged"], rs["substeps"],
              rs["max_newton_residual"], rs["newton_iterations"] / max(1, rs["substeps"]),
              ref_tip_mean, ref_tip_sd))
    cases = [("linearised, %d substep%s" % (k, "s" if k > 1 else ""), ["scene.substeps=%d" % k])
             for k in ([1, 2, 4] if args.quick else [1, 2, 4, 8, 16])]
    for its in [2, 4, 8]:
        for tol in [0.1, 0.01]:
            cases.append(("Newton %d, tolerance %g m/s, 1 substep" % (its, tol),
                          ["cloth.flag.newton_iterations=%d" % its,
                           "cloth.flag.newton_tolerance=%g" % tol]))
    cases.append(("reference settings at %d substeps (the reference's own error)" % (ref_sub // 2),
                  ref_sets[:1] + ["scene.substeps=%d" % (ref_sub // 2)] + ref_sets[2:]))
    head = " | ".join("frame %d RMS / max (m)" % c for c in checkpoints)
    print("| run | status | substeps | retries | Newton its/substep | unconverged | max residual "
          "(m/s) | CG its/frame | %s | mean shape RMS (m) | tip mean error (m) | tip s.d. (m) | "
          "step ms/frame (wall) | process s (wall) | process s (CPU) | CPU vs 1 substep |" % head)
    print("|---|---|---:|---:|---:|---:|---:|---:|%s---:|---:|---:|---:|---:|---:|---:|"
          % ("---:|" * len(checkpoints)))
    base = None
    for label, sets in cases:
        out = os.path.join(tmp, "case")
        reps = 1 if "reference" in label else args.repeats
        run, (wall, cpu) = median_runs(reps, lambda: run_gale(
            args, ([] if "reference" in label else [wind_set(speed)]) + sets, out, frames))
        s = summarise(run)
        if base is None:
            base = cpu
        if not all(os.path.exists(os.path.join(out, "flag.%04d.obj" % f))
                   for f in range(1, last + 1)):
            print("| %s | %s (exit %d): frames missing, no errors | | | | | | | %s| | | | | | | |"
                  % (label, s["status"], s["exit"], "| " * len(checkpoints)))
            continue
        errs = []
        for c in checkpoints:
            rms, mx = distances(read_obj(os.path.join(out, "flag.%04d.obj" % c)), ref_shapes[c])
            errs.append("%.3f / %.3f" % (rms, mx))
        mrms, _ = distances(mean_shape(out, 2, last), ref_mean)
        tips = tip_heights(out, 2, last, tip)
        print("| %s | %s | %d | %d | %.2f | %d | %.3g | %.0f | %s | %.4f | %+.4f | %.4f | %.2f | "
              "%.3f | %.3f | %.2f |" % (
                  label, s["status"], s["substeps"], s["newton_retries"],
                  s["newton_iterations"] / max(1, s["substeps"]), s["newton_unconverged"],
                  s["max_newton_residual"], s["solver_iterations"] / s["frames"],
                  " | ".join(errs), mrms, statistics.fmean(tips) - ref_tip_mean,
                  statistics.pstdev(tips), 1000 * s["step_seconds"] / s["frames"], wall, cpu,
                  cpu / base))


# ---------------------------------------------------------------------------------------------
# iterations: Newton and CG iterations per step against resolution

def iterations(args, tmp):
    sizes = [32, 64] if args.quick else [32, 64, 128]
    print("\n### Newton and CG iterations per step (1 substep/frame, 20 m/s, one thread)\n")
    print("| flag | density (kg/m²) | Newton setting | status | substeps | retries | rejected | "
          "Newton its/step (mean / max) | unconverged | CG its/step, all its solves (mean / max) | "
          "ms/step (wall) | ms/step (process CPU) |")
    print("|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for density in [0.005, 0.1]:
        for res in sizes:
            frames = "1:%d" % (12 if res >= 128 else 24 if res >= 64 else 48)
            for label, newton in [("default", []),
                                  ("newton_iterations = 8", ["cloth.flag.newton_iterations=8"])]:
                out = os.path.join(tmp, "its")
                sets = [wind_set(20), "cloth.flag.grid.res=[%d,%d]" % (res, res),
                        "cloth.flag.density=%g" % density] + newton
                run, (_, cpu) = median_runs(1, lambda: run_gale(args, sets, out, frames))
                s = summarise(run)
                sub = max(1, s["substeps"])
                print("| %d² | %g | %s | %s | %d | %d | %d | %.2f / %d | %d | %.1f / %d | %.2f | "
                      "%.2f |"
                      % (res, density, label, s["status"], s["substeps"], s["newton_retries"],
                         s["rejected_substeps"], s["newton_iterations"] / sub, s["max_newton"],
                         s["newton_unconverged"], s["solver_iterations"] / sub, s["max_cg"],
                         1000 * s["step_seconds"] / sub, 1000 * cpu / sub))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--only", choices=["peer", "error", "iterations"])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="fewer cases and frames")
    ap.add_argument("--ref-substeps", type=int, default=64, help="error: the reference's substeps")
    ap.add_argument("--ref-newton", type=int, default=0,
                    help="error: the reference's newton_iterations (0: linearised; Newton does "
                    "not reach its tolerance on this flag yet, so it only adds cost)")
    args = ap.parse_args()
    gale = os.path.join(args.build, "cli", "gale")
    if not os.path.exists(gale):
        sys.exit("flag_bench.py: %s not found: build first (make build)" % gale)
    with tempfile.TemporaryDirectory() as tmp:
        for name, fn in [("peer", peer), ("error", error), ("iterations", iterations)]:
            if args.only in (None, name):
                fn(args, tmp)
                sys.stdout.flush()


if __name__ == "__main__":
    main()
