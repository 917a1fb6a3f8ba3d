# gale's MDD cache in a real client: Debian's Blender (installed here when missing, as root)
# in background mode imports the first frame's OBJ, plays OUTDIR/cape.mdd through a Mesh Cache
# modifier, and its evaluated positions at frame 10 equal gale's frame-10 OBJ within 1e-5 m.
# Then `import gale` inside Blender's Python. Skips (exit 0, with a message) only where Blender
# cannot be installed.
source "$(dirname "$0")/lib.bash" "$@"
PY=/usr/bin/python3

if ! command -v blender > /dev/null; then
    if [ "$(id -u)" = 0 ] && command -v apt-get > /dev/null; then
        echo "installing Debian's blender (about 20 s)" >&2
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends blender > apt.log 2>&1 ||
            { apt-get update -qq > /dev/null 2>&1 &&
              DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends blender > apt.log 2>&1; }
    fi
    if ! command -v blender > /dev/null; then
        echo "SKIP: blender is not installed and cannot be installed here (not root, or no apt): $(tail -n 1 apt.log 2> /dev/null)"
        exit 0
    fi
fi

run "$GALE" sim "$SRC/examples/03_cape/scene.toml" -o sim --frames 1:12 --cache mdd
expect_rc 0 "gale sim --cache mdd"
BL=(blender -b --factory-startup --python-exit-code 1)
run "${BL[@]}" --python "$SRC/tests/cli/blender/mesh_cache.py" -- sim/cape.0001.obj sim/cape.mdd 10 1 frame10.txt
expect_rc 0 "blender plays the cache (stderr: $ERR)"
expect_match "$OUT" "verts 768" "Blender's mesh has the cape's 768 vertices"
run "$PY" - sim/cape.0010.obj sim/cape.0001.obj frame10.txt <<'PYEOF'
import sys
def obj(p):
    return [[float(v) for v in l.split()[1:4]] for l in open(p) if l.startswith("v ")]
want, start = obj(sys.argv[1]), obj(sys.argv[2])
got = [[float(v) for v in l.split()] for l in open(sys.argv[3])]
assert len(got) == len(want) == 768, (len(got), len(want))
err = max(abs(a - b) for g, w in zip(got, want) for a, b in zip(g, w))
moved = max(abs(a - b) for s, w in zip(start, want) for a, b in zip(s, w))
print(f"max error {err:.3g} m, frame 1 to 10 moved {moved:.3g} m")
assert err <= 1e-5, err
assert moved > 1e-3, moved   # frame 10 is not frame 1: the cache, not the OBJ, gave the shape
PYEOF
expect_rc 0 "Blender's frame 10 equals gale's within 1e-5 m ($OUT $ERR)"

# The module built for Debian's python3 loads in Blender's Python (an ASan build cannot: its
# runtime would have to be loaded first).
MOD=$(dirname "$GALE")/../python
if ldd "$GALE" | grep -q libasan; then
    echo "(sanitizer build: import gale inside Blender not tried)"
elif compgen -G "$MOD/gale*.so" > /dev/null; then
    run "${BL[@]}" --python "$SRC/tests/cli/blender/import_gale.py" -- "$MOD"
    expect_rc 0 "import gale inside Blender ($ERR)"
    expect_match "$OUT" "GALE .* \[\[2\.0, 4\.0, 6\.5\]\]" "Blender's Python evaluates a gale expression"
fi
finish
