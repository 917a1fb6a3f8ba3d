# `gale viz`: PNG of the requested size (signature and IHDR checked) whose pixels follow the
# wind, deterministic output, SVG that is well-formed with the requested size, every style,
# every plane, and scene overlays (windicator, gusts, timeline).
source "$(dirname "$0")/lib.bash" "$@"

# png_size FILE: "WIDTH HEIGHT" from the IHDR chunk (big-endian at bytes 16..23).
png_size() {
    od -A n -t u1 -j 16 -N 8 "$1" | awk '{print $1*16777216 + $2*65536 + $3*256 + $4, $5*16777216 + $6*65536 + $7*256 + $8}'
}

run "$GALE" viz -e '[-$P[1], $P[0], 0]' --bounds -2,-2,2,2 --size 640x480 -o vortex.png
expect_rc 0 "png"
expect_eq "$(head -c 8 vortex.png | od -A n -t x1 | tr -d ' \n')" "89504e470d0a1a0a" "png signature"
expect_eq "$(head -c 16 vortex.png | tail -c 4)" "IHDR" "png header chunk"
expect_eq "$(png_size vortex.png)" "640 480" "requested size"

# The same wind gives the same bytes; another wind gives other pixels.
"$GALE" viz -e '[-$P[1], $P[0], 0]' --bounds -2,-2,2,2 --size 640x480 -o again.png
cmp -s vortex.png again.png || fail "two renders of one wind differ"
"$GALE" viz -e '[$P[1], -$P[0], 0]' --bounds -2,-2,2,2 --size 640x480 -o reversed.png
cmp -s vortex.png reversed.png && fail "reversing the wind did not change the picture"
"$GALE" viz -e '2 * [-$P[1], $P[0], 0]' --bounds -2,-2,2,2 --size 640x480 -o faster.png
cmp -s vortex.png faster.png && fail "doubling the wind did not change the picture"

for style in arrows streamlines none; do
    run "$GALE" viz -e '[1, 0.5 * sin($P[0]), 0]' --bounds 0,0,6,3 --style "$style" --size 500x400 -o "s_$style.png"
    expect_rc 0 "--style $style"
    expect_eq "$(png_size "s_$style.png")" "500 400" "--style $style size"
done
cmp -s s_arrows.png s_none.png && fail "arrows are not drawn"
cmp -s s_streamlines.png s_none.png && fail "streamlines are not drawn"

for plane in x=0.5 y=-1 Z=2; do
    run "$GALE" viz -e '$P' --plane "$plane" --bounds -1,-1,1,1 --size 300x300 -o plane.png
    expect_rc 0 "--plane $plane"
done
run "$GALE" viz -e '$P' --bounds -1,-1,1,1 --size 400x300 --speed-max 10 --arrow-spacing 40 -o opts.png
expect_rc 0 "--speed-max and --arrow-spacing"

# SVG: well-formed XML of the requested size in pixels.
run "$GALE" viz -e '[-$P[1], $P[0], 0]' --bounds -2,-2,2,2 --size 640x480 -o vortex.svg
expect_rc 0 "svg"
expect_match "$(head -c 400 vortex.svg)" '<svg [^>]*width="640px" height="480px"' "svg size"
expect_match "$(tail -c 20 vortex.svg)" '</svg>' "svg is complete"
if command -v xmllint >/dev/null; then
    xmllint --noout vortex.svg 2>/dev/null || fail "svg is not well-formed XML"
fi

# A scene: windicator arrow, gust fronts and the timeline strip.
cat > gusty.toml <<'TOML'
[scene]
fps = 24
frames = [1, 48]

[windicator]
direction = [1, 0, 0.3]
speed = { keys = [[0, 2.0], [1.5, 6.0]], interp = "smooth" }

[[gust]]
start = 0.5
strength = 5.0
travel_speed = 6.0

[[field]]
name = "main"
source = "$windDir * ($windSpeed + gust($P))"
TOML
run "$GALE" viz gusty.toml --plane y=0 --bounds -6,-4,6,4 --time 1 --size 800x700 -o gusty.png
expect_rc 0 "scene picture"
expect_eq "$(png_size gusty.png)" "800 700" "scene picture size"
run "$GALE" viz gusty.toml --plane y=0 --bounds -6,-4,6,4 --time 1 --size 800x700 -o gusty.svg
expect_rc 0 "scene svg"
grep -q '<svg' gusty.svg || fail "scene svg"
"$GALE" viz gusty.toml --plane y=0 --bounds -6,-4,6,4 --time 1.2 --size 800x700 -o later.png
cmp -s gusty.png later.png && fail "the picture does not follow time"
expect_eq "$(ls -a | grep -c tmp)" "0" "no temporary files left"

finish
