# Writes N randomised hard scenes for tests/cli/hard_scenes.sh: wind 0-60 m/s (windicator keys,
# gusts, presets, expressions), cloth densities 0.001-1 kg/m^2, hair, keyframed and rotating
# pins, colliders, moving mesh bodies (OBJ sequences written beside the scene: boxes and thin
# paddles flying up to 8 m/s and spinning up to 360 deg/s) and cloth or hair attached to them;
# self-collision on every third scene's cloth; short and small. Deterministic: its own Park-Miller generator from `seed`.
# Usage: awk -v seed=1 -v count=50 -v out=DIR -f hard_scenes.awk
function rnd() { state = (state * 16807) % 2147483647; return state / 2147483647 }
function uni(a, b) { return a + (b - a) * rnd() }
function logu(a, b) { return exp(log(a) + (log(b) - log(a)) * rnd()) }
function pick(n) { return int(rnd() * n) }
function num(x) { return sprintf("%.4g", x) }
function vec(a, b) { return "[" num(uni(a, b)) ", " num(uni(a, b)) ", " num(uni(a, b)) "]" }
# A number or a keyframed curve over [0, dur] seconds with values in [a, b].
function param(a, b, dur,    n, k, s, t) {
    if (rnd() < 0.5) return num(uni(a, b))
    n = 2 + pick(3)
    s = "{ keys = ["
    for (k = 0; k < n; k++) {
        t = dur * k / (n - 1)
        s = s (k ? ", " : "") "[" num(t) ", " num(uni(a, b)) "]"
    }
    return s "], interp = \"" interps[pick(3)] "\" }"
}
# A keyframed vector path over [0, dur] starting at `start` and moving up to `reach` metres.
function path(start, reach, dur,    n, k, s, t) {
    n = 2 + pick(3)
    s = "{ keys = ["
    for (k = 0; k < n; k++) {
        t = dur * k / (n - 1)
        s = s (k ? ", " : "") "[" num(t) ", " (k ? vec(-reach, reach) : start) "]"
    }
    return s "], interp = \"" interps[pick(3)] "\" }"
}
function field(f, i, dur, windicator,    kind, a, speed) {
    kind = pick(4)
    printf "\n[[field]]\nname = \"f%d\"\n", i > f
    if (kind == 0) {
        # With a [windicator] the preset takes its speed from it.
        speed = windicator ? "" : "speed = " param(0, 60, dur) ", "
        printf "preset = \"wind\"\nparams = { %sturbulence = %s, turbulenceScale = %s, spread = %s }\n",
            speed, num(uni(0, 1)), num(logu(0.1, 5)), num(uni(0, 60)) > f
    } else if (kind == 1) {
        printf "preset = \"ripple\"\nparams = { wavelength = %s, speed = %s, amplitude = %s, direction = %s }\n",
            num(logu(0.2, 6)), num(uni(-20, 20)), param(0, 60, dur), vec(-1, 1) > f
    } else if (kind == 2) {
        printf "preset = \"volume_axis\"\nparams = { shape = %d, radius = %s, height = %s, magnitude = %s, aroundAxis = %s, awayFromAxis = %s, turbulence = %s }\n",
            pick(5), num(uni(0.3, 3)), num(uni(0.3, 3)), param(0, 60, dur), num(uni(-1, 1)), num(uni(-1, 1)),
            num(uni(0, 1)) > f
    } else {
        a = uni(0, 60)
        printf "source = \"[%s * sin(%s * $t + %s * $P[1]), %s * vnoise($P * %s + $t)[1], %s * cos(%s * $t)]\"\n",
            num(a), num(uni(0, 60)), num(uni(0, 20)), num(uni(0, 60 - a)), num(logu(0.5, 20)),
            num(uni(0, 30)), num(uni(0, 60)) > f
    }
}
# A box of half sizes (hx, hy, hz) flying from `c0` at velocity `v` (m/s) and spinning about
# y at `w` (rad/s), written as frames 1..n of OUT/NAME.####.obj (frame F at t = F/24).
function body_sequence(name, n, hx, hy, hz, c0x, c0y, c0z, vx, vy, vz, w,    fr, t, k, x, y, z, c, sn, g, fn) {
    for (fr = 1; fr <= n; fr++) {
        t = (fr - 1) / 24
        c = cos(w * t); sn = sin(w * t)
        fn = sprintf("%s/%s.%04d.obj", out, name, fr)
        for (k = 0; k < 8; k++) {
            x = (k % 2) ? hx : -hx; y = (int(k / 2) % 2) ? hy : -hy; z = (int(k / 4) % 2) ? hz : -hz
            printf "v %.6f %.6f %.6f\n", c * x + sn * z + c0x + vx * t, y + c0y + vy * t, -sn * x + c * z + c0z + vz * t > fn
        }
        printf "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n" > fn
        close(fn)
    }
}
BEGIN {
    if (count == "") count = 50
    if (out == "") out = "."
    state = seed > 0 ? seed : 1
    interps[0] = "linear"; interps[1] = "smooth"; interps[2] = "step"
    for (s = 0; s < count; s++) {
        f = sprintf("%s/hard%02d.toml", out, s)
        frames = 6 + pick(11)
        dur = frames / 24
        printf "# gale hard scene %d (seed %d)\n[scene]\nfps = 24\nframes = [1, %d]\nsubsteps = %d\n",
            s, seed, frames, 1 + pick(4) > f
        printf "gravity = [0, %s, 0]\nair_density = %s\n", num(uni(-20, 0)), num(uni(0.5, 2)) > f
        windicator = rnd() < 0.7
        if (windicator) {
            if (rnd() < 0.5) dir = "[" num(uni(0.2, 1)) ", " num(uni(-1, 1)) ", " num(uni(-1, 1)) "]"
            else dir = "{ keys = [[0, [1, 0, 0]], [" num(dur) ", " vec(0.2, 1) "]] }"
            printf "\n[windicator]\ndirection = %s\nspeed = %s\n", dir, param(0, 60, dur) > f
        }
        ng = pick(3)
        for (g = 0; g < ng; g++)
            printf "\n[[gust]]\nstart = %s\nattack = %s\nhold = %s\ndecay = %s\nstrength = %s\ntravel_speed = %s\n",
                num(uni(0, dur)), num(uni(0, 0.1)), num(uni(0, 0.1)), num(uni(0, 0.2)), param(0, 30, dur),
                num(uni(2, 40)) > f
        nf = 1 + pick(2)
        for (i = 0; i < nf; i++) field(f, i, dur, windicator)
        body = pick(10) # 0-4 cloth, 5-7 hair, 8-9 both
        # A moving mesh body (a box or a 1-2 cm paddle) in about a third of the scenes; cloth
        # or hair attached to it in half of those.
        moving = rnd() < 0.35
        attach = moving && rnd() < 0.5
        seq = sprintf("s%d_hard%02d_body", seed, s)
        if (moving) {
            if (rnd() < 0.5) { hx = uni(0.05, 0.4); hy = uni(0.05, 0.4); hz = uni(0.05, 0.4) }
            else { hx = uni(0.1, 0.4); hy = uni(0.1, 0.4); hz = uni(0.005, 0.01) }
            body_sequence(seq, frames + 1, hx, hy, hz, uni(-0.3, 0.8), uni(0.5, 1.5), uni(-0.6, -0.2),
                uni(-8, 8) * 0.3, uni(-8, 8) * 0.3, uni(0, 8), uni(-6.3, 6.3))
        }
        if (body <= 4 || body >= 8) {
            axes = "xy"; if (rnd() < 0.3) axes = "xz"
            printf "\n[[cloth]]\nname = \"c\"\ngrid = { size = [%s, %s], res = [%d, %d], origin = [0, 1, 0], axes = \"%s\" }\n",
                num(uni(0.2, 1.5)), num(uni(0.2, 1.5)), 3 + pick(14), 3 + pick(14), axes > f
            printf "density = %s\nstretch = %s\nshear = %s\nbend = %s\ndamping = %s\n",
                num(logu(0.001, 1)), param(10, 10000, dur), num(logu(1, 1000)), num(logu(1e-6, 1e-2)),
                num(uni(0, 0.05)) > f
            model = "frozen"; if (rnd() < 0.5) model = "smooth-lift"
            r = rnd(); jac = r < 0.3 ? "paper" : r < 0.5 ? "projected" : "bounded"
            lin = "pcg"; if (rnd() < 0.3) lin = "direct"
            fmt = "obj"; if (rnd() < 0.5) fmt = "ply"
            printf "lift = %s\ndrag = %s\naero_model = \"%s\"\naero_jacobian = \"%s\"\nlinear_solver = \"%s\"\noutput = \"%s\"\n",
                param(0, 1.5, dur), param(0, 2, dur), model, jac, lin, fmt > f
            # Self-collision on every third scene's cloth (chosen by index, not drawn, so the
            # other keys of every scene stay those of the seed), with a 2 mm thickness on half.
            if (s % 3 == 1) printf "self_collision = true\n%s", (s % 6 == 1 ? "thickness = 0.002\n" : "") > f
            if (attach) {
                printf "attach = { mesh = \"%s.#.obj\", box = [-10, 0.999, -10, 10, 1.001, 10] }\n", seq > f
            } else if (rnd() < 0.8) {
                move = ""; if (rnd() < 0.5) move = ", translate = " path("[0, 0, 0]", 1.5, dur)
                if (rnd() < 0.3) move = move ", rotate = { pivot = " vec(-0.5, 0.5) ", axis = " vec(-1, 1) ", angle = " param(-360, 360, dur) " }"
                printf "pins = { box = [-10, 0.999, -10, 10, 1.001, 10]%s }\n", move > f
            }
        }
        if (body >= 5) {
            hdir = "[0, -1, 0]"; if (rnd() < 0.3) hdir = vec(-1, 1)
            printf "\n[[hair]]\nname = \"h\"\ngrid = { size = [%s, %s], count = [%d, %d], length = %s, segments = %d, origin = [0, 1.2, 0], direction = %s }\n",
                num(uni(0.05, 0.5)), num(uni(0.05, 0.5)), 1 + pick(4), 1 + pick(4), num(uni(0.1, 0.8)),
                3 + pick(14), hdir > f
            pinned = "true"; if (rnd() < 0.2) pinned = "false"
            fmt = "obj"; if (rnd() < 0.5) fmt = "ply"
            printf "radius = %s\ndensity = %s\nstretch = %s\nbend = %s\ndrag_normal = %s\ndrag_tangent = %s\nroot_pinned = %s\noutput = \"%s\"\n",
                num(logu(1e-5, 5e-4)), num(logu(100, 3000)), num(logu(10, 2000)), num(logu(1e-7, 1e-3)),
                param(0, 2, dur), num(uni(0, 0.2)), pinned, fmt > f
            if (attach) printf "attach = { mesh = \"%s.#.obj\" }\n", seq > f
        }
        if (moving)
            printf "\n[[collider]]\ntype = \"mesh\"\nmesh = \"%s.#.obj\"\nthickness = %s\nfriction = %s\n",
                seq, num(logu(0.001, 0.02)), num(uni(0, 1)) > f
        nc = pick(3)
        for (c = 0; c < nc; c++) {
            kind = pick(3)
            if (kind == 0)
                printf "\n[[collider]]\ntype = \"sphere\"\ncenter = %s\nradius = %s\nfriction = %s\n",
                    path("[0.3, 0.6, 0.2]", 1, dur), num(uni(0.05, 0.5)), num(uni(0, 1)) > f
            else if (kind == 1)
                printf "\n[[collider]]\ntype = \"capsule\"\na = %s\nb = [0.2, 1.4, 0.3]\nradius = %s\n",
                    path("[0, 0.3, 0.2]", 1, dur), num(uni(0.05, 0.3)) > f
            else
                printf "\n[[collider]]\ntype = \"plane\"\npoint = [0, %s, 0]\nnormal = [%s, 1, %s]\n",
                    num(uni(-0.5, 0.9)), num(uni(-0.3, 0.3)), num(uni(-0.3, 0.3)) > f
        }
        close(f)
    }
}
