# `gale wedge`: a 4-variant wedge (lift x drag) of a tiny cloth scene, emitted and run through GNU
# parallel (installed from Debian when missing and we are root; else gale wedge --jobs), then
# every variant's frames, the manifest, the resolved scenes and the exit codes checked.
source "$(dirname "$0")/lib.bash" "$@"

mkdir -p shot/wind
cat > shot/wind/push.se <<'SE'
$speed = 5;  # 0, 20
[$speed, 0, 2 * sin(6 * $t)]
SE
cat > shot/tiny.toml <<'TOML'
[scene]
fps = 24
frames = [1, 3]
substeps = 2

[[field]]
name = "main"
expr = "wind/push.se"

[[cloth]]
name = "c"
grid = { size = [0.5, 0.5], res = [8, 8], origin = [-0.25, 0.5, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
bend = 0.001
lift = 0.3
drag = 1.0
pins = { box = [-1, 0.99, -1, 1, 1.01, 1] }
TOML

VARY=(--vary cloth.c.lift=0.1,0.6 --vary "cloth.c.drag=0.5, 1.5")
run "$GALE" wedge shot/tiny.toml "${VARY[@]}" -o w --emit-only
expect_rc 0 "wedge --emit-only"
expect_eq "$(wc -l < w/tasks.txt)" "4" "four tasks"
expect_eq "$(wc -l < w/manifest.jsonl)" "4" "four manifest lines"
expect_eq "$(grep -c '"status": "pending"' w/manifest.jsonl)" "4" "all pending before running"
for v in v000_lift=0.1_drag=0.5 v001_lift=0.1_drag=1.5 v002_lift=0.6_drag=0.5 v003_lift=0.6_drag=1.5; do
    [ -f "w/$v/scene.toml" ] || fail "w/$v/scene.toml written"
done
# The resolved scene carries the values and an absolute expression path.
expect_match "$(cat w/v002_lift=0.6_drag=0.5/scene.toml)" '^lift = 0\.6' "resolved lift"
expect_match "$(cat w/v002_lift=0.6_drag=0.5/scene.toml)" "expr = '$TMP/shot/wind/push.se'|expr = \"$TMP/shot/wind/push.se\"" "absolute expr path"
expect_match "$(sed -n 1p w/tasks.txt)" "^cd '$TMP/w/v000_lift=0.1_drag=0.5' && " "task line cds into the variant"
expect_match "$(sed -n 1p w/tasks.txt)" "sim scene.toml -o \. --resume" "task line resumes"

# Run the tasks through GNU parallel (the farm path); fall back to --jobs without it.
if ! command -v parallel > /dev/null; then
    if [ "$(id -u)" = 0 ]; then
        (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq parallel) > /dev/null 2>&1
    fi
fi
if command -v parallel > /dev/null; then
    parallel --will-cite -j 2 < w/tasks.txt
    expect_eq "$?" "0" "GNU parallel runs every task"
    run "$GALE" wedge shot/tiny.toml "${VARY[@]}" -o w --emit-only # refreshes the manifest
    expect_rc 0 "wedge refresh"
else
    echo "note: GNU parallel is not installed and we are not root; running with --jobs 2" >&2
    run "$GALE" wedge shot/tiny.toml "${VARY[@]}" -o w --jobs 2
    expect_rc 0 "wedge --jobs 2"
fi
for d in w/v00*/; do
    for f in 0001 0002 0003; do [ -s "$d/c.$f.obj" ] || fail "$d/c.$f.obj written"; done
    [ -f "$d/DONE" ] || fail "$d/DONE marker"
    expect_match "$(head -c 20 "$d/run.json")" '"status": "ok"' "$d run.json ok"
done
expect_eq "$(grep -c '"status": "done"' w/manifest.jsonl)" "4" "manifest: all done"
# The manifest matches the folders and values.
python3 - "$TMP/w" <<'PY' || fail "manifest matches the variants"
import json, os, sys
out = sys.argv[1]
rows = [json.loads(l) for l in open(os.path.join(out, "manifest.jsonl"))]
want = [(0.1, 0.5), (0.1, 1.5), (0.6, 0.5), (0.6, 1.5)]
assert [r["index"] for r in rows] == [0, 1, 2, 3], rows
for r, (lift, drag) in zip(rows, want):
    assert r["values"] == {"cloth.c.lift": lift, "cloth.c.drag": drag}, r
    assert r["path"] == os.path.join(out, r["folder"]) and os.path.isdir(r["path"]), r
    assert r["frames"] == [1, 3] and r["objects"] == [{"name": "c", "format": "obj"}], r
    assert r["id"] == "v%03d" % r["index"] and r["folder"].startswith(r["id"] + "_"), r
PY
# A variant gives the frames a direct run with the same --set values gives; variants differ.
run "$GALE" sim shot/tiny.toml -o direct --set cloth.c.lift=0.6 --set cloth.c.drag=1.5
expect_rc 0 "direct run"
cmp -s direct/c.0003.obj w/v003_lift=0.6_drag=1.5/c.0003.obj || fail "variant v003 equals gale sim --set"
if cmp -s w/v000_lift=0.1_drag=0.5/c.0003.obj w/v003_lift=0.6_drag=1.5/c.0003.obj; then
    fail "lift and drag change the cloth"
fi
# Running the wedge again redoes nothing.
before=$(stat -c %y w/v001_lift=0.1_drag=1.5/c.0003.obj)
run "$GALE" wedge shot/tiny.toml "${VARY[@]}" -o w --jobs 2
expect_rc 0 "re-run"
expect_match "$ERR" "4 variant\(s\) already complete" "re-run skips complete variants"
expect_eq "$(stat -c %y w/v001_lift=0.1_drag=1.5/c.0003.obj)" "$before" "frames not rewritten"
# A task line is idempotent: running it again does nothing and succeeds.
(eval "$(sed -n 2p w/tasks.txt)")
expect_eq "$?" "0" "task line re-run"

# Errors: bad --vary (2), an unknown key (1, nothing written), a missing scene (3).
run "$GALE" wedge shot/tiny.toml --vary cloth.c.lift -o bad
expect_rc 2 "--vary without values"
run "$GALE" wedge shot/tiny.toml --vary cloth.c.lift=0.1 --vary cloth.c.lift=0.2 -o bad
expect_rc 2 "--vary key twice"
run "$GALE" wedge shot/tiny.toml --vary cloth.c.lfit=0.1,0.2 -o bad
expect_rc 1 "unknown key"
expect_match "$ERR" "lfit" "names the key"
[ -e bad/tasks.txt ] && fail "nothing written for a wrong scene"
run "$GALE" wedge missing.toml --vary cloth.c.lift=0.1 -o bad
expect_rc 3 "missing scene"
run "$GALE" wedge shot/tiny.toml --vary cloth.c.lift=0.1 -o bad --jobs 0
expect_rc 2 "--jobs 0"
finish
