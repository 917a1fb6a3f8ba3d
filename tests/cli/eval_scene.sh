# `gale eval SCENE.toml` and `gale check SCENE.toml`: a scene's summed wind at the origin and at
# points, windicator keys and gusts in closed form, --set by dotted scene path, --fps from the
# scene, presets by name, and the parameter idiom of expression files (--set overrides it).
source "$(dirname "$0")/lib.bash" "$@"

mkdir -p wind
printf '$gain = 2; # 0, 10\n[$gain, 0, 0] + $P * 0\n' > wind/steady.se
cat > scene.toml <<'TOML'
[scene]
fps = 10

[windicator]
direction = [0, 0, 1]
speed = { keys = [[0, 2.0], [1.0, 8.0]] }

[[gust]]
name = "front"
start = 0.5
attack = 0.2
hold = 0.3
decay = 0.6
strength = 6.0
travel_speed = 8.0

[[field]]
name = "main"
preset = "wind"

[[field]]
name = "steady"
expr = "wind/steady.se"
params = { gain = 3 }
scale = 0.5
TOML

# At the origin, t = 0: windicator speed 2 along z, plus 0.5 * 3 along x.
run "$GALE" eval scene.toml
expect_rc 0 "a scene at the origin"
expect_eq "$OUT" "1.5 0 2" "windicator speed plus the scaled steady field"

# t = 0.5: speed 5 (linear key); the gust front has just started at the origin.
run "$GALE" eval scene.toml --time 0.5 --precision double
expect_eq "$OUT" "1.5 0 5" "keyframed windicator speed"
# t = 1: speed 8, and the gust at the origin is at the end of its hold: + 6.
run "$GALE" eval scene.toml --time 1 --precision double
expect_eq "$OUT" "1.5 0 14" "gust at full strength"
# --frame uses the scene's fps (10): frame 10 is t = 1.
run "$GALE" eval scene.toml --frame 10 --precision double
expect_eq "$OUT" "1.5 0 14" "--frame through the scene's fps"
run "$GALE" eval scene.toml --frame 10 --fps 20 --precision double
expect_eq "$OUT" "1.5 0 5" "--fps overrides the scene's"

# The gust reaches z = 8 (1 s downwind at 8 m/s) one second later.
printf 'x,y,z\n0,0,0\n0,0,8\n5,3,8\n' > p.csv
run "$GALE" eval scene.toml --points p.csv --time 1.0 --precision double
expect_rc 0 "scene at points"
expect_eq "$OUT" $'x,y,z,vx,vy,vz\n0,0,0,1.5,0,14\n0,0,8,1.5,0,8\n5,3,8,1.5,0,8' "the gust has not reached z = 8"
run "$GALE" eval scene.toml --points p.csv --time 2.0 --precision double
expect_eq "$(printf '%s\n' "$OUT" | sed -n 3p)" "0,0,8,1.5,0,14" "one second later it has"

# --set by dotted path.
run "$GALE" eval scene.toml --set windicator.speed=4 --set field.steady.params.gain=10 \
    --set field.steady.scale=1 --set gust.front.strength=0 --time 1 --precision double
expect_rc 0 "--set scene paths"
expect_eq "$OUT" "10 0 4" "overridden speed, parameter, scale and gust"
run "$GALE" eval scene.toml --set 'windicator.direction=1,0,0' --precision double
expect_eq "$OUT" "3.5 0 0" "a vector --set"
run "$GALE" eval scene.toml --set 'field.1.params.gain={ keys = [[0, 0], [2, 4]] }' --time 1 \
    --set gust.0.strength=0 --precision double
expect_eq "$OUT" "1 0 8" "a keyframed --set, fields and gusts by index"

# Output files and formats work as for expressions.
run "$GALE" eval scene.toml --points p.csv -o out.ply
expect_rc 0 "scene to PLY"
expect_match "$(head -c 400 out.ply | tr -d '\0')" "property float vz" "PLY has vx, vy, vz"
run "$GALE" eval scene.toml -o value.txt
expect_eq "$(cat value.txt)" "1.5 0 2" "-o without points"

# Presets and inline sources.
cat > ripple.toml <<'TOML'
[[field]]
preset = "ripple"
params = { wavelength = 4, speed = 2, amplitude = 3 }

[[field]]
source = "[0, $fps, 0]"
TOML
run "$GALE" eval ripple.toml --time 0 --precision double --set scene.fps=30
expect_rc 0 "ripple preset"
expect_eq "$OUT" "0 30 0" "a ripple at phase 0 is calm; \$fps from --set scene.fps"
printf 'x,y,z\n1,0,0\n3,0,0\n' > r.csv
run "$GALE" eval ripple.toml --points r.csv --time 1 --precision double
expect_eq "$OUT" $'x,y,z,vx,vy,vz\n1,0,0,-3,24,0\n3,0,0,3,24,0' "crest and trough moved by c t = 2 m"

run "$GALE" check scene.toml ripple.toml
expect_rc 0 "check good scenes"
expect_eq "$OUT$ERR" "" "check is silent on success"

# The parameter idiom in expression files: --set overrides a declared parameter.
printf '$speed = 5; # 0, 40\n$dir = [1, 0, 0];\n$dir * $speed\n' > param.se
run "$GALE" eval param.se
expect_eq "$OUT" "5 0 0" "parameter defaults"
run "$GALE" eval param.se --set speed=8 --set dir=0,1,0
expect_eq "$OUT" "0 8 0" "--set overrides declared parameters"
run "$GALE" check param.se --set speed=8
expect_rc 0 "check with a parameter override"
# gust() exists outside scenes (0 without a rig).
run "$GALE" eval -e 'gust($P) + 1'
expect_eq "$OUT" "1" "gust() outside a scene"

finish
