# Thin body parts against cloth faces (issue 25, the body vertex–cloth triangle pair): a 1 cm rod
# (an octagonal prism with pointed ends, an OBJ sequence written here) pokes tip first at 2 m/s
# into a hanging sheet of 2.5 cm spacing (0.3 m, 13 x 13, top row pinned), entering a face's
# interior, 8.3 cm in one frame, and is held there with its tip 5.3 cm past the sheet's plane:
# no cloth vertex meets the rod's triangles and no cloth edge its edges, only its tip vertex
# meets the face. Counted from the output files, independently of gale
# (count_intersections.py --pairs): no rod triangle intersects a sheet triangle in any frame, no
# frame failed, and the largest edge stretch (run.json) stays below the solver's over-stretch
# limit, 3 (measured 1.14). Before the pair existed the rod went through (144 intersecting pairs at 1 and 2
# substeps); without the [[collider]] it does too (so the count can fail).
source "$(dirname "$0")/lib.bash" "$@"
PY=$(test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
"$PY" -c 'import numpy' 2> /dev/null || { echo "SKIP: python3 with numpy is not installed (make deps installs python3-numpy)"; exit 0; }
COUNTER="$SRC/tests/cli/count_intersections.py"

# The rod along z, 0.2 m long, tip first; its tip at z = -0.03 at frame 1 (t = 1/24 s) and
# 2/24 m further (2 m/s) at frames 2-10, its axis through the centroid of the sheet's triangle
# (6,6)-(7,6)-(7,7): x = -0.15 + 6.667 * 0.025, y = 1 + 6.333 * 0.025.
"$PY" - <<'PY'
import math, os
os.makedirs("rod", exist_ok=True)
d, length, m = 0.01, 0.2, 8
ring = [(0.5 * d * math.cos(2 * math.pi * k / m), 0.5 * d * math.sin(2 * math.pi * k / m)) for k in range(m)]
local = [(x, y, 0.0) for x, y in ring] + [(x, y, -length) for x, y in ring]
local += [(0.0, 0.0, 0.5 * d), (0.0, 0.0, -length - 0.5 * d)]
front, back = 2 * m, 2 * m + 1
faces = []
for k in range(m):
    a, b, c, e = k, (k + 1) % m, m + k, m + (k + 1) % m
    faces += [(a, c, e), (a, e, b), (front, a, b), (back, e, c)]
cx, cy = -0.15 + (6 + 2 / 3) * 0.025, 1.0 + (6 + 1 / 3) * 0.025
for f in range(1, 13):
    z = -0.03 + 2.0 * min(f - 1, 1) / 24.0
    with open("rod/rod.%04d.obj" % f, "w") as out:
        for x, y, zz in local:
            out.write("v %.9f %.9f %.9f\n" % (cx + x, cy + y, z + zz))
        for t in faces:
            out.write("f %d %d %d\n" % tuple(i + 1 for i in t))
pins = [12 * 13 + i for i in range(13)]
open("pins.txt", "w").write(", ".join(map(str, pins)))
PY

scene() { # SUBSTEPS WITH_COLLIDER
    cat <<TOML
[scene]
fps = 24
frames = [1, 10]
substeps = $1

[[cloth]]
name = "sheet"
grid = { size = [0.3, 0.3], res = [13, 13], origin = [-0.15, 1.0, 0.0], axes = "xy" }
density = 0.2
pins = { vertices = [$(cat pins.txt)] }
TOML
    [ "$2" = yes ] && cat <<TOML

[[collider]]
name = "rod"
type = "mesh"
mesh = "rod/rod.#.obj"
thickness = 0.003
friction = 0.3
TOML
}

# crossings DIR: intersecting (sheet, rod) triangle pairs summed over frames 1-10.
crossings() {
    local args=() f
    for f in $(seq -f %04g 1 10); do args+=("$1/sheet.$f.obj" "rod/rod.$f.obj"); done
    "$PY" "$COUNTER" --pairs "${args[@]}" | tail -n 1 | sed -E 's/.*pairs in all: ([0-9]+)$/\1/'
}

# stretch DIR: the largest max_stretch of the sheet over the frames, or "failed".
stretch() {
    "$PY" - "$1/run.json" <<'PY'
import json, sys
run = json.load(open(sys.argv[1]))
objs = [o for f in run["frames"] for o in f["objects"] if o["name"] == "sheet"]
print("failed" if any(o["failed"] for o in objs) else "%.4f" % max(o["max_stretch"] for o in objs))
PY
}

for sub in 1 2; do
    scene $sub yes > rod$sub.toml
    run "$GALE" sim rod$sub.toml -o on$sub
    expect_rc 0 "the rod through the sheet, $sub substeps a frame"
    n=$(crossings on$sub)
    s=$(stretch on$sub)
    echo "substeps $sub: $n crossing pairs, largest stretch $s" >&2
    expect_eq "$n" "0" "no rod triangle crosses a sheet triangle ($sub substeps)"
    awk -v s="$s" 'BEGIN { exit !(s + 0 > 0 && s + 0 < 3.0) }' ||
        fail "the sheet is pushed, not torn ($sub substeps): largest stretch $s"
done

scene 2 no > open.toml
run "$GALE" sim open.toml -o open
expect_rc 0 "the sheet without the collider"
n=$(crossings open)
echo "without the collider: $n crossing pairs" >&2
[ "$n" -gt 0 ] 2> /dev/null || fail "without the collider the rod passes through the sheet (got '$n')"
finish
