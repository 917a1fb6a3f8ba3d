# examples/08_wedge_lift_drag: a short version of the example's lift x drag wedge (2 x 2 variants,
# 3 frames, two at a time) completes, and its contact sheet renders.
source "$(dirname "$0")/lib.bash" "$@"
EX="$SRC/examples/08_wedge_lift_drag"

run "$GALE" check "$EX/scene.toml"
expect_rc 0 "the scene checks clean"
run "$GALE" wedge "$EX/scene.toml" --vary cloth.cape.lift=0.1,0.6 --vary cloth.cape.drag=0.6,1.4 \
    -o wedge --frames 1:3 --jobs 2
expect_rc 0 "the wedge"
expect_eq "$(grep -c '"status": "done"' wedge/manifest.jsonl)" "4" "every variant done"
expect_eq "$(ls wedge/*/cape.0003.obj | wc -l)" "4" "every variant's last frame"
run "$GALE" viz --contact-sheet wedge --frames 1,3 -o sheet.png
expect_rc 0 "the contact sheet"
[ -s sheet.png ] || fail "sheet.png written"
finish
