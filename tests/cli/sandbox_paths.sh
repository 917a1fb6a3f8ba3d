# The path sandbox for every file reader an expression can reach (sdf, sdfgrad, shadow, meshvel,
# vdb), in expressions on the command line, in a scene's wind and in painted maps: `..`,
# absolute paths, a symbolic link out, a symlinked folder, `..` through a symlinked folder are
# refused unless --allow-path allows the folder; `gale wedge --allow-path` passes it on to every
# variant. No built-in writes files (printf goes to stderr). See docs/limits.md.
source "$(dirname "$0")/lib.bash" "$@"

box() { # box HALF: an OBJ box of half-size HALF around the origin
    local h=$1
    printf 'v -%s -%s -%s\nv %s -%s -%s\nv -%s %s -%s\nv %s %s -%s\n' $h $h $h $h $h $h $h $h $h $h $h $h
    printf 'v -%s -%s %s\nv %s -%s %s\nv -%s %s %s\nv %s %s %s\n' $h $h $h $h $h $h $h $h $h $h $h $h
    printf 'f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n'
}
mkdir -p shot/maps shared
box 0.2 > shot/box.obj
box 0.2 > shared/box.obj
box 0.4 > box.obj # a decoy next to shot/: reading it gives 0.1 at (0.5, 0, 0) instead of 0.3
"$GALE" sample -e '[1, 2, 3]' --bounds -1,-1,-1,1,1,1 --voxel 0.5 -o shared/w.vdb
cp shared/w.vdb shot/w.vdb
for f in 1 2; do # a mesh sequence for meshvel()
    box 0.2 > shared/m.000$f.obj
    cp shared/m.000$f.obj shot/m.000$f.obj
    ln -s ../shared/m.000$f.obj shot/link.000$f.obj
done
ln -s ../shared/box.obj shot/link.obj
ln -s ../shared/w.vdb shot/link.vdb
ln -s ../shared shot/linkdir
printf 'x,y,z\n0.5,0,0\n' > shot/p.csv

cd shot
# Every reader, every escape: refused; inside the folder: read.
# (@ stands for the file: mktemp's names never hold it, so the path cannot be substituted into.)
for call in 'sdf(@, $P)' 'sdfgrad(@, $P)' 'shadow(@, $P, [1, 0, 0], 1)' 'meshvel(@, $P, 1)' \
    'vdb(@, "vel", $P)'; do
    for name in box.obj '../shared/box.obj' "$TMP/shared/box.obj" link.obj linkdir/box.obj \
        'linkdir/../shared/box.obj' 'maps/../../shared/box.obj'; do
        fname=$name
        case $call in # meshvel() reads a sequence, vdb() a volume
        meshvel*) fname=${fname/box.obj/m.#.obj}; fname=${fname/link.obj/link.#.obj} ;;
        vdb*) fname=${fname/box.obj/w.vdb}; fname=${fname/link.obj/link.vdb} ;;
        esac
        expr=${call/@/\"$fname\"}
        run "$GALE" eval -e "$expr" --points p.csv
        if [ "$name" = box.obj ]; then
            expect_rc 0 "$expr inside the folder"
            continue
        fi
        expect_rc 1 "$expr"
        expect_match "$ERR" "leads outside|is an absolute path" "$expr: the reason"
        run "$GALE" eval -e "$expr" --points p.csv --allow-path ../shared
        expect_rc 0 "$expr with --allow-path ../shared"
    done
done

# `..` through a symlinked folder never reaches the decoy next to shot/.
run "$GALE" eval -e 'sdf("linkdir/../box.obj", $P)' --points p.csv --precision double
if [ "$RC" = 0 ]; then
    expect_match "$OUT" "^0.5,0,0,0.29999" "linkdir/../box.obj is shot/box.obj"
else
    expect_match "$ERR" "leads outside|cannot" "linkdir/../box.obj refused"
fi
run "$GALE" eval -e 'sdf("linkdir/../box.obj", $P)' --points p.csv --precision double --allow-path ../shared
expect_no_match "$OUT" "^0.5,0,0,0.0999" "the decoy is not read, even with --allow-path"
cd "$TMP"

# Painted maps resolve file names against the scene, whatever the current folder, with the
# scene's policy.
cat > shot/cloth.toml <<'TOML'
[scene]
frames = [1, 2]
[[field]]
name = "calm"
source = "[0, 0, 0]"
[[cloth]]
name = "cape"
grid = { size = [1, 1], res = [4, 4], origin = [0, 0, 0] }
lift = { source = 'sdf("box.obj", $P) > 0 ? 0.3 : 0.1' }
drag = { expr = "maps/drag.se" }
TOML
echo 'sdf("../box.obj", $P) > 0 ? 1 : 0.5' > shot/maps/drag.se
run "$GALE" sim shot/cloth.toml -o out
expect_rc 0 "painted maps reading shot/box.obj from another folder"
sed -i 's|sdf("box.obj"|sdf("../shared/box.obj"|' shot/cloth.toml
run "$GALE" sim shot/cloth.toml -o out2
expect_rc 1 "a painted map reaching outside the scene's folder"
expect_match "$ERR" "leads outside" "the reason"
[ -d out2 ] && [ -n "$(ls out2)" ] && fail "a refused scene wrote frames"
run "$GALE" sim shot/cloth.toml -o out3 --allow-path shared
expect_rc 0 "sim --allow-path shared"

# gale wedge passes --allow-path (absolute) to every variant, with the original scene's folder
# (the variant's scene lives in its own folder; expression files keep their place, so maps/drag.se
# still reaches shot/box.obj). Inline sources would resolve names against the variant's folder.
echo 'sdf("../../shared/box.obj", $P) > 0 ? 0.3 : 0.1' > shot/maps/lift.se
sed -i "s|^lift = .*|lift = { expr = \"maps/lift.se\" }|" shot/cloth.toml
run "$GALE" wedge shot/cloth.toml --vary cloth.cape.stretch=500,1000 -o w --jobs 1
expect_rc 1 "wedge without --allow-path: the variants fail"
run "$GALE" wedge shot/cloth.toml --vary cloth.cape.stretch=500,1000 -o w2 --jobs 1 --allow-path shared
expect_rc 0 "wedge --allow-path shared"
expect_match "$(sed -n 1p w2/tasks.txt)" "--allow-path '$TMP/shot' --allow-path '$TMP/shared'" "the task line"

# Nothing an expression does writes a file: printf goes to stderr, the output only to -o.
before=$(find . | sort)
run "$GALE" eval -e 'printf("%s\n", "/tmp/x")' --points shot/p.csv
expect_eq "$ERR" "/tmp/x" "printf goes to stderr"
expect_eq "$OUT" $'x,y,z,value\n0.5,0,0,0' "the output to stdout"
expect_eq "$(find . | sort)" "$before" "no file written"
finish
