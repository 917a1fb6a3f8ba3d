# Preview renders: `gale viz SCENE --frames A:B` draws the simulated cloth per frame; the PNGs
# are non-empty images of the asked size whose pixels change when the wind does; a contact
# sheet of a wedge is a PNG with one row per variant; the usage errors.
source "$(dirname "$0")/lib.bash" "$@"

# png_size FILE: "WxH" from the IHDR chunk.
png_size() {
    python3 -c 'import struct,sys; d=open(sys.argv[1],"rb").read(24); assert d[:8]==b"\x89PNG\r\n\x1a\n" and d[12:16]==b"IHDR"; w,h=struct.unpack(">II",d[16:24]); print(f"{w}x{h}")' "$1"
}

cat > flag.toml <<'TOML'
[scene]
fps = 24
frames = [1, 4]
substeps = 2

[windicator]
direction = [1, 0, 0.3]
speed = { keys = [[0, 2.0], [0.2, 9.0]] }

[[gust]]
start = 0.05
attack = 0.05
hold = 0.05
decay = 0.1
strength = 3.0
travel_speed = 10.0

[[field]]
name = "main"
preset = "wind"

[[cloth]]
name = "flag"
grid = { size = [0.6, 0.4], res = [10, 8], origin = [0, 0.8, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
lift = 0.4
drag = 1.0
pins = { box = [-0.01, -1, -1, 0.01, 2, 1] }
TOML

run "$GALE" sim flag.toml -o sim
expect_rc 0 "the simulation"
run "$GALE" viz flag.toml --frames 1:4 -o 'preview.#.png' --size 640x480
expect_rc 0 "preview frames"
for f in 0001 0002 0003 0004; do
    [ -s "preview.$f.png" ] || fail "preview.$f.png written"
    [ -s "preview.$f.png" ] && expect_eq "$(png_size "preview.$f.png")" "640x480" "preview.$f.png size"
done
# The wind (and the cloth with it) changes between frames 1 and 4, so the pictures do.
if cmp -s preview.0001.png preview.0004.png; then fail "frames 1 and 4 differ"; fi

# The same frame under a different wind: other pixels.
run "$GALE" sim flag.toml -o calm --set windicator.speed=0.5 --set gust.0.strength=0
expect_rc 0 "the calm simulation"
run "$GALE" viz flag.toml --frames 4:4 --sim calm --set windicator.speed=0.5 --set gust.0.strength=0 \
    -o 'calm.#.png' --size 640x480 --no-field
expect_rc 0 "calm preview"
run "$GALE" viz flag.toml --frames 4:4 --sim sim -o 'windy.#.png' --size 640x480 --no-field
expect_rc 0 "windy preview"
expect_eq "$(png_size calm.0004.png)" "640x480" "no-field size"
if cmp -s calm.0004.png windy.0004.png; then fail "pixels change with the wind"; fi
python3 - calm.0004.png windy.0004.png <<'PY' || fail "decoded pixels differ"
import sys, zlib, struct
def pixels(path):
    d = open(path, "rb").read(); pos = 8; idat = b""
    while pos < len(d):
        n, = struct.unpack(">I", d[pos:pos + 4]); kind = d[pos + 4:pos + 8]
        if kind == b"IDAT": idat += d[pos + 8:pos + 8 + n]
        pos += 12 + n
    return zlib.decompress(idat)
a, b = pixels(sys.argv[1]), pixels(sys.argv[2])
diff = sum(1 for x, y in zip(a, b) if x != y)
assert diff > 500, diff
PY

# A contact sheet of a small wedge: one row per variant, three frame columns.
run "$GALE" wedge flag.toml --vary cloth.flag.lift=0.1,0.8 -o w --frames 1:3 --jobs 2
expect_rc 0 "the wedge"
run "$GALE" viz --contact-sheet w --frames 1,2,3 --cell 120x100 -o sheet.png
expect_rc 0 "contact sheet"
# labelW 220 + 3 * (120 + 8) + 8 = 612 wide; 64 + 22 + 2 * (100 + 8) + 8 = 310 high.
expect_eq "$(png_size sheet.png)" "612x310" "contact sheet size"

# Errors: no # in -o, frames not simulated, bad --frames, a folder without a manifest.
run "$GALE" viz flag.toml --frames 1:2 -o preview.png
expect_rc 2 "-o without #"
run "$GALE" viz flag.toml --frames 1:9 -o 'p.#.png'
expect_rc 3 "frames not simulated"
expect_match "$ERR" "flag.0005.obj" "names the missing frame"
run "$GALE" viz flag.toml --frames 3:1 -o 'p.#.png'
expect_rc 2 "backwards --frames"
run "$GALE" viz --contact-sheet sim -o s.png
expect_rc 3 "no manifest"
finish
