#!/usr/bin/env python3
"""What contact costs in each example that has colliders (issue 25): the example run in full as
shipped, and the same scene with its [[collider]] sections removed (everything else as shipped:
pins, attachments to mesh sequences, self-collision, wind), in the same session, alternating.
Reports the wall seconds summed from run.json (the frames' wall_seconds), the CG iterations
summed over the frames and objects (a count, independent of the machine's load), and the ratios.

    bench/example_contact_cost.py [--gale build/cli/gale] [--repeats 1] [--only 10_hair_turn,...]
    bench/example_contact_cost.py --rotation [--repeats 1] [--only ...]

With --rotation, each example as shipped instead with [solver] rotation_projection "off", "contact"
(the default) and "always", alternating: the seconds against "off" and the largest stretch.

Each example's assets are made first with its README's generator (make_head.py, make_body.py,
make_character.py) in a scratch folder; nothing is written inside examples/."""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# name: (generator command or None, extra gale sim arguments)
EXAMPLES = {
    "03_cape": (None, []),
    "05_ice_cape": (None, []),
    "09_walking_cape": (["make_body.py", "body"], []),
    "10_hair_turn": (["make_head.py", "head"], []),
    "11_character": (["make_character.py", "body"], []),
}


def without_colliders(text):
    """The scene text with every [[collider]] table removed (up to the next table header)."""
    out, skip = [], False
    for line in text.splitlines(keepends=True):
        header = re.match(r"\s*\[", line)
        if header:
            skip = re.match(r"\s*\[\[\s*collider\s*\]\]", line) is not None
        if not skip:
            out.append(line)
    return "".join(out)


def run(gale, folder, scene, out, extra):
    t0 = time.time()
    p = subprocess.run([gale, "sim", scene, "-o", out] + extra, cwd=folder,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        raise RuntimeError("%s: gale sim exited %d: %s" % (scene, p.returncode, p.stderr[-400:]))
    r = json.load(open(os.path.join(folder, out, "run.json")))
    frames = r["frames"]
    sim = sum(f.get("wall_seconds", 0.0) for f in frames)
    its = sum(o.get("solver_iterations", 0) for f in frames for o in f.get("objects", []))
    solves = sum(o.get("linear_solves", 0) for f in frames for o in f.get("objects", []))
    stretch = max((o.get("max_stretch", 0.0) for f in frames for o in f.get("objects", [])),
                  default=0.0)
    return {"wall": wall, "sim": sim, "its": its, "solves": solves, "stretch": stretch}


def rotation_modes(gale, folder, name, repeats):
    """One row: the example as shipped with each rotation_projection mode, "off" the baseline."""
    modes = ("off", "contact", "always")
    best = {}
    for rep in range(repeats):
        for m in modes:
            r = run(gale, folder, "scene.toml", "out_" + m, ["--set", "solver.rotation_projection=" + m])
            if m not in best or r["sim"] < best[m]["sim"]:
                best[m] = r
    off = best["off"]
    print("| %s | %s | %s |" % (name, " | ".join(
        "%.2f (%.2f×)" % (best[m]["sim"], best[m]["sim"] / max(off["sim"], 1e-9)) for m in modes),
        " / ".join("%.3f" % best[m]["stretch"] for m in modes)), flush=True)


def main(argv):
    gale = os.path.join(ROOT, "build", "cli", "gale")
    repeats, only, rotation = 1, None, False
    i = 0
    while i < len(argv):
        if argv[i] == "--gale":
            gale = os.path.abspath(argv[i + 1]); i += 2
        elif argv[i] == "--repeats":
            repeats = int(argv[i + 1]); i += 2
        elif argv[i] == "--only":
            only = argv[i + 1].split(","); i += 2
        elif argv[i] == "--rotation":
            rotation = True; i += 1
        else:
            sys.exit("usage: example_contact_cost.py [--gale PATH] [--repeats N] [--only A,B] "
                     "[--rotation]")
    py = "/usr/bin/python3" if os.access("/usr/bin/python3", os.X_OK) else sys.executable
    if rotation:
        print("| example | sim s, rotation_projection off | contact (default) | always | "
              "max stretch off / contact / always |")
        print("|---|---|---|---|---|")
    else:
        print("| example | sim s with colliders | without | time ratio | CG iterations with / "
              "without | ratio | linear solves with / without | max stretch with / without |")
        print("|---|---|---|---|---|---|---|---|")
    for name, (gen, extra) in EXAMPLES.items():
        if only and name not in only:
            continue
        work = tempfile.mkdtemp(prefix="gale_contact_cost_")
        try:
            folder = os.path.join(work, name)
            shutil.copytree(os.path.join(ROOT, "examples", name), folder)
            if gen:
                subprocess.run([py] + gen, cwd=folder, check=True, stdout=subprocess.DEVNULL)
            if rotation:
                rotation_modes(gale, folder, name, repeats)
                continue
            text = open(os.path.join(folder, "scene.toml")).read()
            with open(os.path.join(folder, "no_colliders.toml"), "w") as f:
                f.write(without_colliders(text))
            best = {}
            for rep in range(repeats):
                for kind, scene in (("with", "scene.toml"), ("without", "no_colliders.toml")):
                    r = run(gale, folder, scene, "out_" + kind, extra)
                    if kind not in best or r["sim"] < best[kind]["sim"]:
                        best[kind] = r
            w, wo = best["with"], best["without"]
            print("| %s | %.2f | %.2f | %.2f× | %d / %d | %.2f× | %d / %d | %.3f / %.3f |" % (
                name, w["sim"], wo["sim"], w["sim"] / max(wo["sim"], 1e-9), w["its"], wo["its"],
                w["its"] / max(wo["its"], 1), w["solves"], wo["solves"], w["stretch"],
                wo["stretch"]), flush=True)
        finally:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main(sys.argv[1:])
