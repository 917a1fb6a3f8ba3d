# Frame-end trouble and `gale sim --strict` (../shared/spec/cli.md, "Shots"): a strip of 11 × 2
# vertices 5 cm apart, every vertex pinned, whose mesh has its right half moved 15 cm away from
# its rest mesh (rest_mesh), so that its two middle edges are held at 20/5 = 4× their rest length
# (closed form), past over_stretch = 1.5 (the default), from frame 2 on (frame 1 is the initial
# state); the diagonal between them is at √(0.2² + 0.05²)/√(2 · 0.05²) = 2.92×, past it too (three
# edges), and every other edge at rest. The scene forced it (both
# ends of the edges are pinned), and says so. Without --strict: exit 0, a warning per frame on
# stderr and run.json's "trouble" entries; with --strict: exit 4 at frame 2, frame 1 written and
# not 2, run.json status "trouble"; over_stretch = 5 makes the same run clean.
source "$(dirname "$0")/lib.bash" "$@"

python3 - <<'PY'
def strip(name, gap):
    with open(name, "w") as f:
        for j in range(2):
            for i in range(11):
                f.write("v %.6f %.6f 0\n" % (0.05 * i + (gap if i >= 6 else 0.0), 1.0 + 0.05 * j))
        for i in range(10):
            a, b, c, d = i + 1, i + 2, i + 13, i + 12
            f.write("f %d %d %d\nf %d %d %d\n" % (a, b, c, a, c, d))
strip("strip.obj", 0.15)
strip("rest.obj", 0.0)
PY
cat > scene.toml <<'TOML'
[scene]
fps = 24
frames = [1, 4]
substeps = 2

[[field]]
name = "calm"
expr = "calm.se"

[[cloth]]
name = "strip"
mesh = "strip.obj"
rest_mesh = "rest.obj"
pins = { box = [-1, 0, -1, 2, 2, 1] }
TOML
echo '[0, 0, 0]' > calm.se

run "$GALE" sim scene.toml -o plain
expect_rc 0 "gale sim without --strict"
expect_match "$ERR" "gale: warning: frame 2: strip: over-stretched: edge (5-6|16-17) at 4× its rest length \(limit 1\.5×\) at \(0\.35, 1(\.05)?, 0\) \(3 edges past the limit\), forced by pins \(the scene's" "a warning names the edge, its stretch, where, and the pins"
[ -f plain/strip.0004.obj ] || fail "without --strict every frame is written"
python3 - plain/run.json <<'PY' || fail "run.json's trouble entries"
import json, sys
run = json.load(open(sys.argv[1]))
assert run["status"] == "ok", run["status"]
by = {f["frame"]: f["objects"][0] for f in run["frames"]}
assert by[1]["trouble"] == [], by[1]["trouble"]                  # the initial state
for F in (2, 3, 4):
    t = by[F]["trouble"]
    assert len(t) == 1 and t[0]["kind"] == "over_stretch", t
    t = t[0]
    assert abs(t["stretch"] - 4.0) < 1e-5, t                      # 0.20 m / 0.05 m
    assert t["limit"] == 1.5 and t["scene"] is True and t["forced_by"] == "pins", t
    assert abs(t["position"][0] - 0.35) < 1e-6 and t["count"] == 3, t  # the middle edges, a diagonal
    assert {t["vertex"], t["other_vertex"]} in ({5, 6}, {16, 17}), t
    assert any(e.startswith("trouble: over-stretched") for e in by[F]["events"]), by[F]["events"]
PY

run "$GALE" sim scene.toml -o strict --strict
expect_rc 4 "gale sim --strict"
expect_match "$ERR" "frame 2 ends in trouble .*--strict refuses it: frames up to 1 are written" "the refusal names the frame"
[ -f strict/strip.0001.obj ] || fail "--strict writes the frames before the trouble"
[ ! -e strict/strip.0002.obj ] || fail "--strict does not write the frame in trouble"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["status"]=="trouble" and r["frames"][-1]["frame"]==2, (r["status"], r["frames"][-1]["frame"])' strict/run.json \
    || fail "run.json ends with frame 2, status trouble"

# Below the limit there is no trouble, and --strict lets the run through.
run "$GALE" sim scene.toml -o loose --strict --set solver.over_stretch=5
expect_rc 0 "gale sim --strict on frames without trouble"

# Cloth held inside a moving mesh (a closed box sequence, x from -0.2 to 0.2 plus 1 cm a frame,
# y 0.9-1.1, z -0.05 to -0.01): a 3 × 3 patch pinned at z = -0.03 is 20 mm below the box's
# nearest faces (closed form). Moving meshes are kept out by their continuous passes; cloth that
# ends inside one anyway is trouble, said as for the other colliders.
python3 - <<'PY'
import os
os.makedirs("box", exist_ok=True)
for f in range(1, 5):
    with open("box/b.%04d.obj" % f, "w") as o:
        for x in (-0.2, 0.2):
            for y in (0.9, 1.1):
                for z in (-0.05, -0.01):
                    o.write("v %.6f %.6f %.6f\n" % (x + 0.01 * f, y, z))
        for q in ((1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)):
            o.write("f %d %d %d %d\n" % q)
with open("patch.obj", "w") as o:
    for j in range(3):
        for i in range(3):
            o.write("v %.4f %.4f -0.03\n" % (-0.05 + 0.05 * i, 0.95 + 0.05 * j))
    for j in range(2):
        for i in range(2):
            a = j * 3 + i + 1
            o.write("f %d %d %d\nf %d %d %d\n" % (a, a + 1, a + 4, a, a + 4, a + 3))
PY
cat > inbox.toml <<'TOML'
[scene]
fps = 24
frames = [1, 4]
substeps = 1

[[cloth]]
name = "patch"
mesh = "patch.obj"
pins = { box = [-1, 0.9, -1, 1, 1.1, 1] }

[[collider]]
name = "box"
type = "mesh"
mesh = "box/b.####.obj"
thickness = 0.005
TOML
run "$GALE" sim inbox.toml -o inbox
expect_rc 0 "cloth pinned inside a moving mesh"
expect_match "$ERR" "frame 2: patch: inside a collider: vertex [0-9]+ 20 mm below its surface at .* \(9 vertices inside\), forced by collider 'box' and the pin holding vertex [0-9]+ inside it" \
    "the cloth inside the moving box is trouble, with its depth and the pins"
finish
