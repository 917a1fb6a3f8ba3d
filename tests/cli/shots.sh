# Shot conventions (../shared/spec/cli.md, "Shots"): studio frame numbers with time_zero, mesh
# sequences named as DCCs write them (#, %04d, $F4), frame files that are symbolic links into a
# cache elsewhere, and `gale check` loading the whole scene as a run would.
# The reference for time_zero is the same shot renumbered to start at frame 0: $t is the same
# at every frame, so every output frame must be byte for byte the same.
source "$(dirname "$0")/lib.bash" "$@"

# A box body sliding along +x at 0.5 m/s under a sheet pinned at one edge, one file per frame.
# (A fifth argument: the metres it slides a frame instead.)
write_body() { # write_body FOLDER FIRST LAST NAME_PRINTF_FORMAT [STEP]
    mkdir -p "$1"
    for ((f = $2; f <= $3; f++)); do
        awk -v x=$(awk -v k=$((f - $2)) -v s="${5:-}" 'BEGIN { printf "%.6f", s == "" ? k * 0.5 / 24 : k * s }') 'BEGIN {
            split("-0.2 0.2", X); split("0.2 0.5", Y); split("-0.2 0.2", Z)
            for (i = 1; i <= 2; i++) for (j = 1; j <= 2; j++) for (k = 1; k <= 2; k++)
                printf "v %.6f %.6f %.6f\n", X[i] + x, Y[j], Z[k]
            print "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4" }' \
            > "$1/$(printf "$4" "$f")"
    done
}
write_scene() { # write_scene FILE FIRST LAST TIME_ZERO MESH
    cat > "$1" <<EOF
[scene]
fps = 24
frames = [$2, $3]
time_zero = $4
substeps = 2

[windicator]
direction = [0, 0, 1]
speed = { keys = [[0, 0], [0.25, 6]] }

[[cloth]]
name = "sheet"
grid = { size = [0.6, 0.6], res = [10, 10], origin = [-0.3, 0.6, -0.3], axes = "xz" }
pins = { box = [-0.31, 0.59, -0.31, 0.31, 0.61, -0.29] }

[[collider]]
name = "box"
type = "mesh"
mesh = "$5"
EOF
}

mkdir shot renumbered
write_body shot/cache 1001 1013 'body.%04d.obj'
write_body renumbered/cache 0 12 'body.%04d.obj'
write_scene shot/scene.toml 1001 1012 1001 'cache/body.####.obj'
write_scene renumbered/scene.toml 0 11 0 'cache/body.####.obj'

run "$GALE" check shot/scene.toml
expect_rc 0 "the shot checks clean"
run "$GALE" sim shot/scene.toml -o shot/out
expect_rc 0 "the shot at frames 1001-1012"
run "$GALE" sim renumbered/scene.toml -o renumbered/out
expect_rc 0 "the same shot renumbered from 0"
for ((f = 0; f <= 11; f++)); do
    a=shot/out/sheet.$(printf %04d $((f + 1001))).obj
    b=renumbered/out/sheet.$(printf %04d $f).obj
    [ -s "$a" ] || fail "$a written"
    cmp -s "$a" "$b" || fail "frame $((f + 1001)) of the shot is frame $f renumbered"
done
# The wind rose with the shot's own time: the sheet moved by its last frame.
cmp -s shot/out/sheet.1001.obj shot/out/sheet.1012.obj && fail "the shot's wind moves the sheet"
expect_match "$(head -c 400 shot/out/run.json)" '"frames": \[1001, 1012\]' "run.json has the studio frames"
t1012=$(grep -o '"frame": 1012, "time": [^,]*' shot/out/run.json | sed 's/.*: //')
awk -v t="$t1012" 'BEGIN { exit !(t > 0.4583 && t < 0.4584) }' || fail "frame 1012 ends at 11/24 s, got $t1012"

# A range that starts mid-shot starts from the simulated state there: the frames before it are
# simulated first, so each frame is the full run's, byte for byte (never the rest mesh
# teleported to the body's pose at the range's first frame).
run "$GALE" sim shot/scene.toml -o shot/late --frames 1008:1012
expect_rc 0 "a range that starts mid-shot"
expect_match "$ERR" "frames 1001-1008 are simulated first, frames 1001-1007 not written" "the run-up is said ($ERR)"
[ -e shot/late/sheet.1007.obj ] && fail "frames before the range are not written"
for ((f = 1008; f <= 1012; f++)); do
    cmp -s shot/late/sheet.$f.obj shot/out/sheet.$f.obj || fail "frame $f of --frames 1008:1012 is the full run's"
done

# $frame is the studio frame, $t the shot time.
cat > shot/frame.se <<'EOF'
[$frame, $t, 0]
EOF
cat >> shot/scene.toml <<'EOF'

[[field]]
name = "probe"
expr = "frame.se"
EOF
run "$GALE" eval shot/scene.toml --frame 1013
expect_rc 0 "eval at a studio frame"
expect_match "$OUT" '^1013,0.5,0$|^1013 0.5 0$' "\$frame = 1013 and \$t = 0.5 s at frame 1013 ($OUT)"

# The DCC spellings of a sequence name the same files.
for name in 'cache/body.%04d.obj' 'cache/body.$F4.obj'; do
    write_scene renumbered/dcc.toml 0 11 0 "$name"
    run "$GALE" sim renumbered/dcc.toml -o renumbered/dcc
    expect_rc 0 "a sequence named $name"
    cmp -s renumbered/dcc/sheet.0011.obj renumbered/out/sheet.0011.obj || fail "$name gives the same run as ####"
done
# A name that matches no file says which tokens gale reads.
write_scene renumbered/bad.toml 0 11 0 'cache/body.%03d.obj'
run "$GALE" check renumbered/bad.toml
expect_rc 3 "a sequence with no files (a missing file: exit 3)"
expect_match "$ERR" "bad.toml:[0-9]+:[0-9]+: .*no files of the sequence.*%04d or \\\$F4" "the error names the tokens ($ERR)"

# Frame files that are symbolic links to a cache elsewhere are the scene's own choice.
mkdir -p linked elsewhere
write_body elsewhere/cache 0 12 'body.%04d.obj'
mkdir linked/cache
for f in elsewhere/cache/*.obj; do ln -s "$TMP/$f" "linked/cache/$(basename "$f")"; done
write_scene linked/scene.toml 0 11 0 'cache/body.####.obj'
run "$GALE" check linked/scene.toml
expect_rc 0 "symlinked frame files check clean"
run "$GALE" sim linked/scene.toml -o linked/out
expect_rc 0 "symlinked frame files simulate"
cmp -s linked/out/sheet.0011.obj renumbered/out/sheet.0011.obj || fail "the linked cache gives the same run"

# Likely mistakes are warnings at the collider's line: a run longer than the body's sequence,
# a body in centimetres, a collider far from every cloth. The shot as written has none.
expect_no_match "$(cd shot && "$GALE" check scene.toml 2>&1)" "warning" "the shot has no warnings"
run "$GALE" check renumbered/scene.toml --set 'scene.frames=[0, 20]'
expect_rc 0 "a run past the sequence still checks"
expect_match "$ERR" "scene.toml:16:1: warning: \[\[collider\]\] 'box': its mesh sequence .* has frames 0-12 but the run goes from frame 0 to 20" "the run outlives the sequence ($ERR)"
mkdir -p cm/cache
for f in renumbered/cache/*.obj; do awk '/^v / { printf "v %.4f %.4f %.4f\n", $2 * 100, $3 * 100, $4 * 100; next } { print }' "$f" > cm/cache/$(basename "$f"); done
write_scene cm/scene.toml 0 11 0 'cache/body.####.obj'
run "$GALE" check cm/scene.toml
expect_match "$ERR" "scene.toml:16:1: warning: .*'box' is [0-9.]+ m across, [0-9.]+x the largest cloth .*centimetres" "a body in centimetres ($ERR)"
# A body of the cloth's size that travels far (30 m over the run) is not taken for centimetres:
# its size is that of one frame, not of the ground it covers.
write_body travels/cache 0 12 'body.%04d.obj' 2.5
write_scene travels/scene.toml 0 11 0 'cache/body.####.obj'
run "$GALE" check travels/scene.toml
expect_rc 0 "a body that travels far checks"
expect_no_match "$ERR" "centimetres" "a body that travels far is not in centimetres ($ERR)"
mkdir -p far/cache
for f in renumbered/cache/*.obj; do awk '/^v / { printf "v %.4f %.4f %.4f\n", $2 + 30, $3, $4; next } { print }' "$f" > far/cache/$(basename "$f"); done
write_scene far/scene.toml 0 11 0 'cache/body.####.obj'
run "$GALE" sim far/scene.toml -o far/out
expect_rc 0 "a far collider does not stop a run"
expect_match "$ERR" "scene.toml:16:1: warning: .*'box' never comes within [0-9.]+ m of any cloth" "a collider far from the cloth ($ERR)"
# Step keys on pins teleport the held vertices: a warning at the pins' line with the jump (0.3 m
# at t = 0.25 s, one substep of 1/48 s: 14.4 m/s); the same keys linear, or a step after the
# run's end (t = 0.6 s > 11/24 s), say nothing.
STEP='cloth.sheet.pins.translate={ keys = [[0, [0, 0, 0]], [0.25, [0.3, 0, 0]]], interp = "step" }'
run "$GALE" check renumbered/scene.toml --set "$STEP"
expect_rc 0 "a pin teleport still checks"
expect_match "$ERR" "scene.toml:14:8: warning: \[\[cloth\]\] 'sheet' pins: translate is keyed with interp = \"step\": at t = 0.25 s it jumps 0.3 m in one substep \(14.4 m/s\)" "a pin teleport ($ERR)"
run "$GALE" check renumbered/scene.toml --set "${STEP/step/linear}"
expect_no_match "$ERR" "teleport" "linear pin keys ($ERR)"
run "$GALE" check renumbered/scene.toml --set "${STEP/0.25,/0.6,}"
expect_no_match "$ERR" "teleport" "a step after the run's end ($ERR)"
# Pins keyed down through the floor hold their vertices inside it: a warning at the pins' line
# (the pinned row, at 0.6 m, keyed 0.85 m down by t = 0.5 s: 0.25 m below the floor); the same
# pins left where they are say nothing.
cat > pinned_floor.toml <<'EOF'
[scene]
frames = [1, 13]

[[cloth]]
name = "sheet"
grid = { size = [0.6, 0.6], res = [8, 8], origin = [-0.3, 0.6, -0.3], axes = "xz" }
pins = { box = [-0.31, 0.59, -0.31, 0.31, 0.61, -0.29], translate = { keys = [[0, [0, 0, 0]], [0.5, [0, -0.85, 0]]] } }

[[collider]]
name = "floor"
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
EOF
run "$GALE" check pinned_floor.toml
expect_rc 0 "pins through the floor still check"
expect_match "$ERR" "pinned_floor.toml:7:8: warning: .*'sheet' pins: they hold vertices inside .*'floor' in [0-9]+ frame.s. of the run .vertex [0-9]+ 0.25 m below its surface at frame [0-9]+" "pins inside the floor ($ERR)"
run "$GALE" check pinned_floor.toml --set 'cloth.sheet.pins.translate=[0, 0, 0]'
expect_no_match "$ERR" "inside" "pins above the floor ($ERR)"

# gale check builds the bodies too: what `gale sim` rejects, check rejects, at the same place.
cat > bad_body.toml <<'EOF'
[scene]
frames = [1, 2]

[[cloth]]
name = "sheet"
mesh = "missing.obj"
EOF
run "$GALE" check bad_body.toml
check_rc=$RC
check_err=$ERR
run "$GALE" sim bad_body.toml -o bad_out
expect_eq "$check_rc" "$RC" "check and sim exit alike on a missing cloth mesh"
expect_match "$check_err" "bad_body.toml:[0-9]+:[0-9]+: .*missing.obj" "check names the scene place and the mesh ($check_err)"
finish
