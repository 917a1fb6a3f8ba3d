# `gale sim --cache mdd`: OUTDIR/<object>.mdd is a LightWave MDD file (big-endian counts, times,
# positions) holding every frame written, equal to the OBJ frames in float32; killed part-way
# (SIGKILL) it is still a complete file whose header counts the frames it holds, and --resume
# extends it to the same bytes an uninterrupted run writes.
source "$(dirname "$0")/lib.bash" "$@"
PY=/usr/bin/python3

tiny_scene 90 24 4 > tiny.toml

# check_mdd FILE OBJ_PREFIX FIRST: the header matches the size, the times are frame/24 from
# FIRST, and every frame equals its OBJ (9 significant digits) in float32; prints the frame count.
check_mdd() {
    "$PY" - "$@" <<'PYEOF'
import struct, sys
path, prefix, first = sys.argv[1], sys.argv[2], int(sys.argv[3])
data = open(path, "rb").read()
frames, points = struct.unpack(">ii", data[:8])
assert len(data) == 8 + 4 * frames + 12 * frames * points, (len(data), frames, points)
times = struct.unpack(f">{frames}f", data[8:8 + 4 * frames])
at = 8 + 4 * frames
for i in range(frames):
    f = first + i
    assert times[i] == struct.unpack(">f", struct.pack(">f", f / 24))[0], (i, times[i])
    xyz = struct.unpack(f">{3 * points}f", data[at + 12 * points * i:at + 12 * points * (i + 1)])
    obj = [float(v) for line in open(f"{prefix}.{f:04d}.obj") if line.startswith("v ") for v in line.split()[1:4]]
    assert len(obj) == 3 * points, (len(obj), points)
    for a, b in zip(xyz, obj):
        assert abs(a - b) <= 1e-6 * max(1.0, abs(b)), (f, a, b)
print(frames)
PYEOF
}

run "$GALE" sim tiny.toml -o full --cache mdd
expect_rc 0 "an uninterrupted run with --cache mdd"
expect_eq "$(check_mdd full/c.mdd full/c 1)" "90" "the cache holds all 90 frames, equal to the OBJ frames"
expect_eq "$(stat -c %s full/c.mdd)" "$((8 + 4 * 90 + 12 * 90 * 576))" "its size is the layout's"

# Killed part-way: still a complete cache of the frames so far.
"$GALE" sim tiny.toml -o part --cache mdd 2> /dev/null &
pid=$!
for _ in $(seq 1 2000); do
    [ -f part/c.0020.obj ] && break
    sleep 0.01
done
kill -9 "$pid"
wait "$pid" 2> /dev/null
n=$(check_mdd part/c.mdd part/c 1)
[ -n "$n" ] && [ "$n" -ge 19 ] && [ "$n" -lt 90 ] || fail "the killed run's cache is whole with its frames ($n)"
[ -f part/c.0090.obj ] && fail "the run was killed before its last frame"
run "$GALE" sim tiny.toml -o part --cache mdd --resume
expect_rc 0 "resume"
expect_match "$ERR" "resuming after frame" "it resumed"
cmp -s part/c.mdd full/c.mdd || fail "the resumed cache is the uninterrupted run's, byte for byte"

# A cache cut short by hand (or a run started without --cache) is not silently extended.
"$PY" -c "
import struct,sys
d=open('part/c.mdd','rb').read(); f,p=struct.unpack('>ii',d[:8]); k=5
open('part/c.mdd','wb').write(struct.pack('>ii',k,p)+d[8:8+4*k]+d[8+4*f:8+4*f+12*p*k])"
rm -f part/.state/00[5-9]*.* part/.state/01*.*
run "$GALE" sim tiny.toml -o part --cache mdd --resume
expect_rc 3 "a cache shorter than the resumed frames"
expect_match "$ERR" "c.mdd.*the cache has 5 frames.*run without --resume" "says why and what to do"
run "$GALE" sim tiny.toml -o x --cache abc
expect_rc 2 "--cache takes mdd only"
finish
