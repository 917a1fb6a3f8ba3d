# `gale sample --frames A:B`: one file per frame with the '#' run replaced by the zero-padded
# frame number, t = frame / fps (the scene's, --fps, else 24), each file written atomically.
source "$(dirname "$0")/lib.bash" "$@"

run "$GALE" sample -e '[$frame, $t * 48, $fps]' --bounds 0,0,0,1,1,1 --res 1 --frames 1:3 -o 'v.#.csv'
expect_rc 0 "frames"
expect_eq "$(ls v.*.csv | tr '\n' ' ')" "v.0001.csv v.0002.csv v.0003.csv " "a lone # pads to 4 digits"
expect_eq "$(sed -n 2p v.0002.csv)" "0.5,0.5,0.5,2,4,24" "frame 2 at 24 fps"

run "$GALE" sample -e '[$frame, $t, $fps]' --bounds 0,0,0,1,1,1 --res 1 --frames 9:10 --fps 10 -o 'out/f.##.npy'
expect_rc 3 "missing folder"
mkdir out
run "$GALE" sample -e '[$frame, $t, $fps]' --bounds 0,0,0,1,1,1 --res 1 --frames 9:10 --fps 10 -o 'out/f.##.npy'
expect_rc 0 "frames into a folder"
expect_eq "$(ls out | tr '\n' ' ')" "f.09.npy f.10.npy " "## pads to 2 digits"
vals=$(od -A n -t f4 -j 128 -N 12 out/f.10.npy | awk '{print $1+0, $2+0, $3+0}')
expect_eq "$vals" "10 1 10" "frame 10 at --fps 10"

cat > s.toml <<'TOML'
[scene]
fps = 25
frames = [1, 4]

[[field]]
name = "f"
source = "[$frame, 0, $fps]"
TOML
run "$GALE" sample s.toml --bounds 0,0,0,1,1,1 --res 1 --frames 0:1 -o 'w.#.vdb'
expect_rc 0 "scene frames as vdb"
expect_eq "$(ls w.*.vdb | tr '\n' ' ')" "w.0000.vdb w.0001.vdb " "vdb frame files"

# Each frame is complete or absent: frame 1 divides by zero, so frame 0 is written and the
# run stops with exit 4 before writing frame 1.
run "$GALE" sample -e '[1 / ($frame - 1), 0, 0]' --bounds 0,0,0,1,1,1 --res 2 --frames 0:2 -o 'n.#.npy'
expect_rc 4 "non-finite frame"
expect_match "$ERR" "8 of 8 cell\(s\).*frame 1" "non-finite count and frame"
expect_eq "$(ls n.*.npy | tr '\n' ' ')" "n.0000.npy " "only the good frame written"
expect_eq "$(ls -a | grep -c tmp)" "0" "no temporary files left"

run "$GALE" sample -e '[1,0,0]' --bounds 0,0,0,1,1,1 --res 1 --frames 1:2 -o v.csv
expect_rc 2 "--frames without # in the name"
run "$GALE" sample -e '[1,0,0]' --bounds 0,0,0,1,1,1 --res 1 --frames 1:2
expect_rc 2 "--frames to stdout"
run "$GALE" sample -e '[1,0,0]' --bounds 0,0,0,1,1,1 --res 1 --frames 1:2 -o 'a#b#.csv'
expect_rc 2 "two # runs"
run "$GALE" sample -e '[1,0,0]' --bounds 0,0,0,1,1,1 --res 1 --frames 3:1 -o 'v.#.csv'
expect_rc 2 "backwards range"
run "$GALE" sample -e '[1,0,0]' --bounds 0,0,0,1,1,1 --res 1 --frames a:b -o 'v.#.csv'
expect_rc 2 "non-numeric range"
run "$GALE" sample -e '[1,0,0]' --bounds 0,0,0,1,1,1 --res 1 --frames 1:2 --time 1 -o 'v.#.csv'
expect_rc 2 "--frames with --time"

finish
