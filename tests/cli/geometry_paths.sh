# Geometry in expressions from the command line: sdf() of a box mesh, files resolved against
# the folder of the expression or scene, `..`, absolute paths and symbolic links out of it
# refused unless --allow-path allows the folder (eval, check, sample, viz).
source "$(dirname "$0")/lib.bash" "$@"

mkdir -p shot/wind shared
# A box of half-size 0.2 around the origin (quads, as DCC tools write them).
cat > shared/box.obj <<'OBJ'
v -0.2 -0.2 -0.2
v 0.2 -0.2 -0.2
v -0.2 0.2 -0.2
v 0.2 0.2 -0.2
v -0.2 -0.2 0.2
v 0.2 -0.2 0.2
v -0.2 0.2 0.2
v 0.2 0.2 0.2
f 1 5 7 3
f 2 4 8 6
f 1 2 6 5
f 3 7 8 4
f 1 3 4 2
f 5 6 8 7
OBJ
cp shared/box.obj shot/box.obj
printf 'x,y,z\n0.5,0,0\n0,0.3,0\n' > shot/pts.csv

# 0.3 m from the box: beyond its narrow band (4 voxels of 0.05 here), the distance to the box.
run "$GALE" eval -e 'sdf("box.obj", $P, 0.05)' --points pts.csv --precision double
expect_rc 3 "the points are in shot/, not here"
cd shot
run "$GALE" eval -e 'sdf("box.obj", $P, 0.05)' --points pts.csv --precision double
expect_rc 0 "sdf at points"
# (The mesh's vertices are float32: 0.2 is 0.20000000298.)
expect_eq "$(sed -n 2p <<< "$OUT" | cut -d, -f4 | xargs printf '%.6f')" "0.300000" "0.3 m beside the box"
expect_eq "$(sed -n 3p <<< "$OUT" | cut -d, -f4 | xargs printf '%.6f')" "0.100000" "0.1 m above it"

# Files resolve against the expression file's folder, wherever gale runs.
cd ..
echo 'sdf("../box.obj", $P, 0.05) * [1, 0, 0]' > shot/wind/around.se
run "$GALE" eval shot/wind/around.se --points shot/pts.csv --precision double
expect_rc 1 "an expression file may not leave its folder"
expect_match "$ERR" "^shot/wind/around.se:1:5: error: '../box.obj' leads outside .*shot/wind" "names the file and folder"
run "$GALE" eval shot/wind/around.se --points shot/pts.csv --precision double --allow-path shot
expect_rc 0 "--allow-path lets it reach shot/"
expect_match "$OUT" "^0.5,0,0,0.2999999970[0-9]*,0,0$" "the value"
run "$GALE" check shot/wind/around.se
expect_rc 1 "check refuses it too"
run "$GALE" check shot/wind/around.se --allow-path shot
expect_rc 0 "check with --allow-path"

# In a scene the expression files may reach anywhere in the scene's folder.
cat > shot/scene.toml <<'TOML'
[[field]]
name = "around"
expr = "wind/around.se"
TOML
run "$GALE" eval shot/scene.toml --points shot/pts.csv --precision double
expect_rc 0 "a scene's expression reaching the scene folder"
run "$GALE" sample shot/scene.toml --bounds -1,-1,-1,1,1,1 --res 4 -o s.npy
expect_rc 0 "sample a scene"
cat > shot/outside.toml <<'TOML'
[[field]]
name = "shared"
source = 'sdf("../shared/box.obj", $P) * [0, 1, 0]'
TOML
run "$GALE" sample shot/outside.toml --bounds -1,-1,-1,1,1,1 --res 4 -o s.npy
expect_rc 1 "outside the scene's folder"
expect_match "$ERR" "^shot/outside.toml:3:15: error: '../shared/box.obj' leads outside" "scene position"
run "$GALE" sample shot/outside.toml --bounds -1,-1,-1,1,1,1 --res 4 -o s.npy --allow-path shared
expect_rc 0 "sample --allow-path"
run "$GALE" viz shot/outside.toml --plane z=0 --bounds -1,-1,1,1 --size 320x320 -o v.png
expect_rc 1 "viz refuses it"
run "$GALE" viz shot/outside.toml --plane z=0 --bounds -1,-1,1,1 --size 320x320 -o v.png --allow-path shared
expect_rc 0 "viz --allow-path"
run "$GALE" check shot/outside.toml --allow-path shared
expect_rc 0 "check a scene with --allow-path"

# Absolute paths and links out.
run "$GALE" eval -e "sdf(\"$PWD/shared/box.obj\", \$P)"
expect_rc 1 "absolute path"
expect_match "$ERR" "is an absolute path" "absolute path message"
run "$GALE" eval -e "sdf(\"$PWD/shared/box.obj\", \$P)" --allow-path shared
expect_rc 0 "absolute path in an allowed folder"
ln -s ../shared/box.obj shot/link.obj
cd shot
run "$GALE" eval -e 'sdf("link.obj", $P)'
expect_rc 1 "a link out of the folder"
expect_match "$ERR" "'link.obj' leads outside" "link message"
run "$GALE" eval -e 'sdf("link.obj", $P)' --allow-path ../shared
expect_rc 0 "a link into an allowed folder"

# Meshes that are not surfaces, and settings that cannot build a volume.
printf 'v 0 0 0\nv 1 0 0\n' > points.obj
run "$GALE" eval -e 'sdf("points.obj", $P)'
expect_rc 1 "no faces"
expect_match "$ERR" "cannot load 'points.obj'.*no faces" "no faces message"
run "$GALE" eval -e 'sdf("box.obj", $P, $P[0])' --points pts.csv
expect_rc 1 "varying voxel"
expect_match "$ERR" "'voxel' of 'sdf' must be uniform" "varying voxel message"

finish
