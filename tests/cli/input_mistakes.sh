# Input mistakes a TD makes with bodies and meshes (issue 27, item 4; the brief: "bad input gets a
# clear error naming file, line and column"), each said where it was made:
# - an OBJ vertex that is not a number, not finite, missing a coordinate or beyond single
#   precision: an error at its line and column (tinyobjloader alone reads them as 0 or inf);
# - a body that only an attachment names, whose sequence is shorter than the run or in
#   centimetres: the warnings a collider gets, at the attach key;
# - an attachment bound far from its body's surface (units, or a body far from where the cloth
#   was modelled at the binding's frame): a warning at the attach key;
# - a frame pattern that matches one file: the body would stand still, said at the key;
# - a frame file that is a link to nothing (an unmounted cache): an error naming the link;
# - another program's frame token (${F4} in an attachment, <F> or {frame:04d} in a collider,
#   with or without a rest_mesh): the error lists the tokens gale reads;
# - an attachment whose box selects nothing: a warning at the attach key; a --set attach mesh
#   that cannot be read: an error at that --set;
# - held vertices the scene pulls apart (a pinned edge and an attached edge 1 m apart): the
#   frame's trouble says the scene forced it, naming both, not "the solver".
source "$(dirname "$0")/lib.bash" "$@"
command -v python3 > /dev/null || { echo "SKIP: python3 is not installed"; exit 0; }

python3 - <<'PY'
import os
def grid(path, res, size, y0):
    with open(path, 'w') as f:
        for j in range(res + 1):
            for i in range(res + 1):
                f.write('v %.6f %.6f 0\n' % (-size / 2 + size * i / res, y0 + size * j / res))
        for j in range(res):
            for i in range(res):
                a = j * (res + 1) + i + 1
                f.write('f %d %d %d\nf %d %d %d\n' % (a, a + 1, a + res + 2, a, a + res + 2, a + res + 1))
def box(path, dx, s=1.0):
    with open(path, 'w') as f:
        for x in (-0.2, 0.2):
            for y in (0.9, 1.1):
                for z in (-0.05, -0.01):
                    f.write('v %.6f %.6f %.6f\n' % (s * (x + dx), s * y, s * z))
        for q in ((1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)):
            f.write('f %d %d %d %d\n' % q)
grid('cape.obj', 6, 0.3, 0.75)
os.makedirs('body', exist_ok=True)
os.makedirs('cm', exist_ok=True)
os.makedirs('one', exist_ok=True)
os.makedirs('far', exist_ok=True)
for f in range(1, 9):
    if f < 6:
        box('body/box.%04d.obj' % f, 0.02 * f)
        box('cm/box.%04d.obj' % f, 0.02 * f, 100.0)
    box('far/box.%04d.obj' % f, 2.0 + 0.02 * f)
box('one/box.0001.obj', 0.0)
PY
scene() { # ATTACH_MESH [EXTRA]
    cat <<EOF
[scene]
fps = 24
frames = [1, 8]
substeps = 1

[[cloth]]
name = "c"
mesh = "cape.obj"
attach = { mesh = "$1", box = [-1, 1.04, -1, 1, 1.06, 1] }
${2:-}
EOF
}

# OBJ vertices: the line and column of the bad coordinate.
for bad in "v abc 1 0|1:3|not a number|expected a number, found 'abc'" \
    "v nan 1 0|1:3|nan|must be finite" "v 1 0|1:6|missing z|needs x, y and z" \
    "v 1e999 1 0|1:3|1e999|out of range|beyond single precision" "v 1 4e38 0|1:5|4e38|beyond single precision"; do
    IFS='|' read -r line at what want alt <<< "$bad"
    { echo "$line"; sed 1d cape.obj; } > bad.obj
    scene body/box.#.obj | sed 's|mesh = "cape.obj"|mesh = "bad.obj"|' > bad.toml
    run "$GALE" check bad.toml
    expect_rc 1 "an OBJ vertex with $what"
    expect_match "$ERR" "bad.obj:$at: .*(${want}${alt:+|$alt})" "the error names bad.obj:$at ($what)"
done

# A body only the attachment names: a sequence shorter than the run, and one in centimetres.
scene body/box.#.obj > short.toml
run "$GALE" check short.toml
expect_rc 0 "an attachment's short sequence (a warning)"
expect_match "$ERR" "short.toml:9:[0-9]+: warning: .*attach: its mesh sequence .* has frames 1-5 but the run goes from frame 1 to 8" \
    "the short sequence is warned of at the attach key"
scene cm/box.#.obj > cm.toml
run "$GALE" check cm.toml
expect_match "$ERR" "cm.toml:9:[0-9]+: warning: .*attach: its body is .* centimetres" \
    "a body in centimetres is warned of at the attach key"
scene one/box.#.obj > one.toml
run "$GALE" check one.toml
expect_rc 0 "a one-file sequence (a warning)"
expect_match "$ERR" "one.toml:9:[0-9]+: warning: .*matches one file \(frame 1\), so the body stands still" \
    "a pattern that matches one file is warned of"

# An attachment bound far from its body: the box stands 2 m to the side of the cape at frame 1
# (x from 1.82 to 2.22), so the cape's top row (y = 1.05, 1 cm in front of the box's face when it
# is in place) is bound up to 1.82 + 0.15 = 1.97 m from its surface (the vertex at x = −0.15,
# against the box's left face). The boxes in place say nothing of it.
scene "far/box.#.obj" > far.toml
run "$GALE" check far.toml
expect_rc 0 "an attachment bound far from its body (a warning)"
expect_match "$ERR" "far.toml:9:[0-9]+: warning: .*attach: vertex [0-9]+ is bound 1\.97 m from the body's surface at frame 1 \(7 of 7 bound vertices" \
    "the far binding is warned of at the attach key, with its distance"
scene "body/box.#.obj" > near.toml
run "$GALE" check near.toml --set scene.frames=[1,5]
expect_no_match "$ERR" "is bound" "a cape bound 1 cm off its body: no warning"

# A collider far below the cloth: the cape (y 0.75-1.05) falls 0.41 m in 8 frames (½ g T², T =
# 7/24 s), so a ball 1.95 m below it is out of reach and warned of; in 40 frames it falls
# 3.7 m and lands on it: no warning.
scene "body/box.#.obj" '[[collider]]
name = "ball"
type = "sphere"
center = [0, -1.25, 0]
radius = 0.05' > ball.toml
run "$GALE" check ball.toml
expect_match "$ERR" "ball.toml:10:1: warning: .*'ball' never comes within 1\.95 m of any cloth or hair over the run \(farther than they fall in it, 0\.417 m\)" \
    "a ball out of reach is warned of ($ERR)"
run "$GALE" check ball.toml --set 'scene.frames=[1, 40]'
expect_no_match "$ERR" "never comes within" "a ball the cape falls onto in 40 frames: no warning"

# A frame linked to a cache that is not there.
mkdir -p linked
for f in 1 2 3 4 5; do ln -s "$PWD/body/box.000$f.obj" "linked/box.000$f.obj"; done
rm linked/box.0003.obj
ln -s /nonexistent/cache/box.0003.obj linked/box.0003.obj
scene linked/box.#.obj > dangling.toml
run "$GALE" check dangling.toml
expect_rc 3 "a dangling frame link (a missing file: exit 3, spec cli.md)"
expect_match "$ERR" "dangling.toml:9:[0-9]+: .*'box.0003.obj' .* is a link to /nonexistent/cache/box.0003.obj, which does not exist" \
    "the error names the link and its target"

# Houdini's ${F4} (not one of gale's spellings).
scene 'body/box.${F4}.obj' > braces.toml
run "$GALE" check braces.toml
expect_rc 3 "an unknown frame token (no such file)"
expect_match "$ERR" "write the frame number as .*#.*%04d.*\\\$F4" "the error lists the tokens gale reads"
# A collider named with another program's token (read as one static file that is not there):
# the same list, at the collider's mesh key; with a rest_mesh beside it, still the mesh's error.
for token in '<F>' '{frame:04d}'; do
    { scene body/box.#.obj; printf '\n[[collider]]\nname = "b"\ntype = "mesh"\nmesh = "body/box.%s.obj"\n' "$token"; } > tok.toml
    for rest in "" 'rest_mesh = "body/box.0001.obj"'; do
        { cat tok.toml; echo "$rest"; } > tok2.toml
        run "$GALE" check tok2.toml
        expect_rc 3 "a collider's sequence written box.$token.obj ${rest:+(with a rest_mesh)}"
        expect_match "$ERR" "tok2.toml:15:[0-9]+: error: .*cannot read 'body/box\.$token\.obj'.*write the frame number as .*#.*%04d" \
            "the collider's error lists the tokens gale reads ($token${rest:+, with a rest_mesh})"
        expect_no_match "$ERR" "a static mesh does not move" "no rest_mesh error hides it ($token)"
    done
done

# A --set that names a mesh that is not there: said at the --set, not at the scene's attach line.
run "$GALE" check short.toml --set cloth.c.attach.mesh=nowhere.obj
expect_rc 3 "an attach mesh from --set that does not exist"
expect_match "$ERR" "^--set cloth.c.attach.mesh=nowhere.obj: error: .*cannot read 'nowhere.obj'" \
    "the error is at the --set"

# A box that selects nothing.
scene body/box.#.obj | sed 's|box = \[-1, 1.04, -1, 1, 1.06, 1\]|box = [5, 5, 5, 6, 6, 6]|' > none.toml
run "$GALE" check none.toml
expect_match "$ERR" "none.toml:9:[0-9]+: warning: .*attach: it selects no vertex" \
    "an empty selection is warned of at the attach key"

# Held vertices pulled apart: the left column attached to a box walking away along -x, the right
# column pinned; the cloth between them must stretch past 3x from frame 5 (4.7x by frame 8).
python3 - <<'PY'
import os
os.makedirs('away', exist_ok=True)
for f in range(1, 9):
    dx = -0.16 * (f - 1)
    with open('away/b.%04d.obj' % f, 'w') as o:
        for x in (-0.2, -0.14):
            for y in (0.7, 1.1):
                for z in (-0.05, 0.05):
                    o.write('v %.6f %.6f %.6f\n' % (x + dx, y, z))
        for q in ((1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)):
            o.write('f %d %d %d %d\n' % q)
PY
cat > apart.toml <<'EOF'
[scene]
fps = 24
frames = [1, 8]
substeps = 1

[[cloth]]
name = "c"
mesh = "cape.obj"
lift = 0.0
drag = 0.0
attach = { mesh = "away/b.#.obj", box = [-0.16, 0.7, -0.01, -0.14, 1.1, 0.01] }
pins = { box = [0.14, 0.7, -0.01, 0.16, 1.1, 0.01] }
EOF
run "$GALE" sim apart.toml -o apart
expect_rc 0 "the pulled-apart cloth"
trouble=$(python3 -c "
import json
for f in json.load(open('apart/run.json'))['frames']:
    for o in f['objects']:
        for t in o['trouble']:
            if t['kind'] == 'over_stretch': print(f['frame'], t['scene'], t['forced_by'])")
echo "$trouble"
expect_match "$trouble" "^[0-9]+ True the (pin|attachment) at vertex [0-9]+ and the (pin|attachment) at vertex [0-9]+, .* m apart" \
    "the over-stretch is the scene's, naming the held vertices pulled apart"
expect_no_match "$trouble" "the solver" "no frame blames the solver"
# A static mesh collider thinner than the cloth's edges (5 cm here): its contact is per cloth
# vertex, so a 1 cm plate standing between two columns of vertices goes through the faces. Said at
# the collider; a 20 cm block is not.
plate() { # FILE HALF_X: a box 0.6 m deep and 0.4 m tall under the cape, 2 HALF_X thick along x
    awk -v h="$2" 'BEGIN { for (i = -1; i <= 1; i += 2) for (j = 0; j <= 1; j++) for (k = -1; k <= 1; k += 2)
        printf "v %g %g %g\n", i * h, 0.3 + 0.4 * j, k * 0.3
        print "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6" }' > "$1"
}
plate plate.obj 0.005
plate block.obj 0.1
for body in plate block; do
    { scene body/box.#.obj; printf '\n[[collider]]\nname = "%s"\ntype = "mesh"\nmesh = "%s.obj"\n' "$body" "$body"; } > "$body.toml"
    run "$GALE" check "$body.toml"
    expect_rc 0 "a static $body checks"
done
run "$GALE" check plate.toml
expect_match "$ERR" "plate.toml:[0-9]+:1: warning: \[\[collider\]\] 'plate' is a static mesh 0.01 m thin along x, less than the longest cloth edge .*one-frame sequence" \
    "a thin static plate is warned of at its collider ($ERR)"
run "$GALE" check block.toml
expect_no_match "$ERR" "thin along" "a 20 cm block is not thin ($ERR)"
finish
