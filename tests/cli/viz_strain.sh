# `gale viz --sim DIR --frames A:B --strain` colours cloth by rest-relative strain (viz/strain.h):
# on tests/live/resim's soft sheet, which its weight stretches by about ρgL/k ≈ 49 % at its
# pinned top (well past the map's red end, 25 %), the SVG picture gets red triangles, and the
# same picture without --strain gets none; the 24×24 flag beside it (stiff, under 1 %) stays
# the cloth's own blue, so the red ones are the sheet's.
source "$(dirname "$0")/lib.bash" "$@"
command -v python3 > /dev/null || { echo "SKIP: python3 is needed"; exit 0; }
cp "$SRC/tests/live/resim/"{scene.toml,wind.se} .
run "$GALE" sim scene.toml -o out --frames 1:12
expect_rc 0 "gale sim of the stretched sheet and the flag"
for mode in strain plain; do
    extra=()
    [ "$mode" = strain ] && extra=(--strain)
    run "$GALE" viz scene.toml --sim out --frames 12:12 --plane z=0 --no-field "${extra[@]}" -o "$mode.#.svg"
    expect_rc 0 "gale viz --frames 12:12 ($mode)"
done
# red_fills SVG: the fills whose red is well above green and blue (the map's stretched end).
red_fills() {
    python3 - "$1" <<'PY'
import re, sys
n = 0
for r, g, b in re.findall(r"fill:rgb\(([\d.]+)%,([\d.]+)%,([\d.]+)%\)", open(sys.argv[1]).read()):
    r, g, b = float(r), float(g), float(b)
    n += r > 30 and r > 1.6 * g and r > 1.6 * b
print(n)
PY
}
strained=$(red_fills strain.0012.svg)
plain=$(red_fills plain.0012.svg)
# The sheet has 8×8 cells, 128 triangles; those near its top (strain over 0.25 by the closed form's
# linear profile, about the upper half) are red.
[ "$strained" -ge 30 ] || fail "red triangles where the sheet is stretched: $strained, wanted at least 30"
[ "$((strained - plain))" -ge 30 ] || fail "--strain adds the red ones: $strained with it, $plain without"
[ "$strained" -le 128 ] || fail "at most the sheet's 128 triangles are red (the flag is barely strained): $strained"
echo "red triangles: $strained with --strain, $plain without"
finish
