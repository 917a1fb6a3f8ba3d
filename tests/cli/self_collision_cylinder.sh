# Self-collision (issue 16): a twisted cylinder. A tube (radius 0.1 m, 0.5 m long, 24 around x 24
# along, written here) has its two end rings turned in opposite directions at 90 deg/s each (3/8
# of a turn by frame 36, 1.5 s): the near ring by a rotating pin, the far one attached to a ring
# body (an OBJ sequence turning the other way). The twist collapses the tube into itself. With
# self_collision = true no frame has an intersecting triangle pair (count_intersections.py, not
# gale), gale's count agrees, nothing is left unresolved, and both rings follow their motion;
# with self_collision = false the tube passes through itself.
source "$(dirname "$0")/lib.bash" "$@"
source "$SRC/tests/cli/self_collision_lib.bash"

cat > make_tube.py <<'PY'
import math, os
around, along, radius, length, frames, turns = 24, 24, 0.1, 0.5, 36, 0.5
def ring(x, phase):
    return [(x, radius * math.cos(2 * math.pi * k / around + phase),
             0.6 + radius * math.sin(2 * math.pi * k / around + phase)) for k in range(around)]
with open('tube.obj', 'w') as f:
    for j in range(along):
        for p in ring(-length / 2 + length * j / (along - 1), 0):
            f.write('v %.9f %.9f %.9f\n' % p)
    for j in range(along - 1):
        for k in range(around):
            a, b = j * around + k + 1, j * around + (k + 1) % around + 1
            f.write('f %d %d %d\nf %d %d %d\n' % (a, b, b + around, a, b + around, a + around))
# The far ring as a body: its vertices and a fan round its centre; frame F is at t = F / 24 s,
# turned by -half a turn * min(t / 2 s, 1) (the pin's keys the other way).
os.makedirs('ring', exist_ok=True)
for fr in range(1, frames + 2):
    with open('ring/ring.%04d.obj' % fr, 'w') as f:
        for p in ring(length / 2, -2 * math.pi * turns * min(fr / 48, 1)):
            f.write('v %.9f %.9f %.9f\n' % p)
        f.write('v %.9f 0 0.6\n' % (length / 2))
        for k in range(around):
            f.write('f %d %d %d\n' % (k + 1, (k + 1) % around + 1, around + 1))
PY
run "$PY" make_tube.py
expect_rc 0 "make_tube.py"

tube() {
    cat <<TOML
[scene]
fps = 24
frames = [1, 36]
substeps = 4

[[cloth]]
name = "tube"
mesh = "tube.obj"
density = 0.1
stretch = 500.0
shear = 50.0
bend = 1e-4
self_collision = $1
thickness = 0.003
pins = { box = [-0.26, -1, -1, -0.24, 2, 2], rotate = { pivot = [0, 0, 0.6], axis = [1, 0, 0], angle = { keys = [[0, 0], [2, 180]] } } }
attach = { mesh = "ring/ring.#.obj", box = [0.24, -1, -1, 0.26, 2, 2] }
TOML
}
tube true > on.toml
tube false > off.toml

run "$GALE" sim on.toml -o on
expect_rc 0 "the twisted tube with self-collision"
expect_clean on tube "the twisted cylinder"
# The rings at frames 24 and 36 (t = F / 24 s): the near one turned +F x 3.75 deg about the axis
# (x, through z = 0.6) by its pin keys; the far one by its body's turn since frame 1, where the
# attachment was bound: -(F - 1) x 3.75 deg. Both to the rounding of the OBJ output.
for frame in 24 36; do
    err=$("$PY" - "$frame" <<'PY'
import math, sys
def verts(p):
    return [list(map(float, l.split()[1:4])) for l in open(p) if l.startswith('v ')]
frame = int(sys.argv[1])
a, b = verts('tube.obj'), verts('on/tube.%04d.obj' % frame)
err = 0.0
for i in list(range(24)) + list(range(23 * 24, 24 * 24)):
    turn = math.radians(3.75 * frame if i < 24 else -3.75 * (frame - 1))
    y, z = a[i][1], a[i][2] - 0.6
    want = (a[i][0], y * math.cos(turn) - z * math.sin(turn), 0.6 + y * math.sin(turn) + z * math.cos(turn))
    err = max(err, max(abs(u - v) for u, v in zip(want, b[i])))
print('%.2e' % err)
PY
    )
    awk -v e="$err" 'BEGIN { exit !(e != "" && e < 1e-5) }' ||
        fail "the end rings turned the opposite ways at frame $frame: off by $err m"
done

run "$GALE" sim off.toml -o off
expect_rc 0 "the twisted tube without self-collision"
expect_dirty off tube "the twisted cylinder"
finish
