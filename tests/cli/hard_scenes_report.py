#!/usr/bin/env python3
"""Each hard scene's largest stretch and energy, from its run.json (tests/cli/hard_scenes.sh):
one line per scene, worst first, and a summary. A frame's over-stretch beyond the limit carries
what forced it (`forced_by`; `scene`: true when pins, attachments or colliders force it, false
when the solver left it) and whether the scene starts intersecting (`start`: a cloth through
itself or another, a hair through a cloth, as the run's first-frame events say), and what the
run warned of at load that forces stretch (step keys that teleport pins or colliders, pins inside
a collider: run.json's warnings). Reported, not asserted.

    hard_scenes_report.py OUT_FOLDER [--top N]"""
import glob
import json
import os
import sys


def scene_stats(run_json):
    r = json.load(open(run_json))
    worst = {"stretch": 0.0, "object": "", "frame": 0, "forced_by": "", "scene": None}
    energy = 0.0
    tangled = False
    for f in r.get("frames", []):
        for o in f.get("objects", []):
            tangled = tangled or any("the start shape" in e for e in o.get("events", []))
            s = o.get("max_stretch", 0.0) or 0.0
            if s > worst["stretch"]:
                forced, scene = "", None
                for t in o.get("trouble", []):
                    if isinstance(t, dict) and t.get("kind") == "over_stretch":
                        forced, scene = t.get("forced_by", ""), t.get("scene")
                worst = {"stretch": s, "object": o.get("name", ""), "frame": f.get("frame", 0),
                         "forced_by": forced, "scene": scene}
            energy = max(energy, (o.get("energy") or {}).get("total", 0.0) or 0.0)
    worst["start"] = tangled
    # What the run warned of at load that forces stretch (run.json's warnings).
    warned = []
    for w in r.get("warnings", []):
        if "teleport" in w:
            warned.append("step keys teleport")
        elif "hold vertices inside" in w:
            warned.append("pins inside a collider")
    worst["warned"] = sorted(set(warned))
    return worst, energy


def main(argv):
    if not argv:
        sys.exit(__doc__)
    top = int(argv[argv.index("--top") + 1]) if "--top" in argv else 15
    rows = []
    for rj in sorted(glob.glob(os.path.join(argv[0], "*", "run.json"))):
        try:
            w, e = scene_stats(rj)
        except (OSError, ValueError) as err:
            print("%s: run.json unreadable: %s" % (rj, err))
            continue
        rows.append((w["stretch"], os.path.basename(os.path.dirname(rj)), w, e))
    rows.sort(key=lambda r: -r[0])
    print("scene  object  largest stretch (frame)  largest total energy (J)  forced by")
    for s, name, w, e in rows[:top]:
        who = w["forced_by"] or ("(below the over-stretch limit: not attributed)")
        print("%s  %s  %.3f (%d)  %.4g  %s%s%s%s" % (name, w["object"], s, w["frame"], e, who,
                                                    " [scene]" if w["scene"] else "",
                                                    " [starts intersecting]" if w["start"] else "",
                                                    "".join(" [%s]" % x for x in w["warned"])))
    n = len(rows)
    over = lambda x: sum(1 for r in rows if r[0] > x)
    solver = sum(1 for r in rows if r[0] > 1.5 and r[2]["scene"] is False)
    scene = sum(1 for r in rows if r[0] > 1.5 and r[2]["scene"] is True)
    print("summary scenes=%d over_1.2=%d over_1.5=%d over_3=%d over_1.5_forced_by_scene=%d "
          "over_1.5_by_solver=%d unattributed=%d over_1.5_starting_intersected=%d "
          "over_1.5_warned=%d over_3_warned=%d"
          % (n, over(1.2), over(1.5), over(3.0), scene, solver, over(1.5) - scene - solver,
             sum(1 for r in rows if r[0] > 1.5 and r[2]["start"]),
             sum(1 for r in rows if r[0] > 1.5 and r[2]["warned"]),
             sum(1 for r in rows if r[0] > 3.0 and r[2]["warned"])))


if __name__ == "__main__":
    main(sys.argv[1:])
