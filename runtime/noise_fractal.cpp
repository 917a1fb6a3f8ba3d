// Fractal sums of the gradient noises, in passes of kPass lanes with per-lane parameters: fbm
// and turbulence (3D and 4D, 1-3 channels), curl noise of 3D and 4D potentials, and flow noise
// (curl noise whose lattice gradients turn with time). Octave o runs at P_o = P_{o-1} * lac +
// shift.
#include "runtime/noise.h"
#include "runtime/noise_loops.h"

namespace gale::runtime::noise {

using namespace detail;

namespace {

// Per-lane octave state of one pass.
template <class T>
struct OctaveLanes {
    alignas(64) T count[kPass]; // octave count per lane (1..8, as T)
    alignas(64) T lac[kPass];
    alignas(64) T gain[kPass];
    alignas(64) T amp[kPass];    // amplitude of the current octave
    alignas(64) T weight[kPass]; // amp, or 0 for lanes whose octave count is reached
    int maxCount = 1;

    GALE_NOISE_INLINE void load(const FractalLanes<T>& f, int base, int m) {
        maxCount = 1;
        for (int i = 0; i < m; ++i) {
            const int c = octaveCount(f.octaves[base + i]);
            maxCount = c > maxCount ? c : maxCount;
            count[i] = T(c);
            lac[i] = f.lacunarity[base + i];
            gain[i] = f.gain[base + i];
            amp[i] = T(1);
        }
    }
    GALE_NOISE_INLINE void weights(int m, int octave) {
        const T o = T(octave);
        for (int i = 0; i < m; ++i) weight[i] = o < count[i] ? amp[i] : T(0);
    }
    GALE_NOISE_INLINE void advance(int m) {
        for (int i = 0; i < m; ++i) amp[i] = amp[i] * gain[i];
    }
    // P = P * lacunarity + shift (the fixed per-octave offset).
    GALE_NOISE_INLINE void scale(int m, T* __restrict p, int axis) const {
        const T shift = T(kOctaveShift[axis]);
        for (int i = 0; i < m; ++i) p[i] = p[i] * lac[i] + shift;
    }
};

template <class T>
GALE_NOISE_INLINE void accumulate(int m, bool absolute, const T* __restrict w,
                                  const T* __restrict v, T* __restrict acc) {
    if (absolute)
        for (int i = 0; i < m; ++i) acc[i] = acc[i] + w[i] * absOf(v[i]);
    else
        for (int i = 0; i < m; ++i) acc[i] = acc[i] + w[i] * v[i];
}

// Scale of curl and flow noise: one octave has component rms 0.19, like vnoise (the curl of
// unscaled potentials has rms 0.70).
constexpr double kCurlScale = 0.2709;

// acc += w * kCurlScale * curl, from the gradients g[c][axis] of the three potential channels.
template <class T>
GALE_NOISE_INLINE void
accumulateCurl(int m, const T* __restrict w, const T* __restrict g0y, const T* __restrict g0z,
               const T* __restrict g1x, const T* __restrict g1z, const T* __restrict g2x,
               const T* __restrict g2y, T* __restrict ax, T* __restrict ay, T* __restrict az) {
    for (int i = 0; i < m; ++i) {
        const T s = w[i] * T(kCurlScale);
        ax[i] = ax[i] + s * (g2y[i] - g1z[i]);
        ay[i] = ay[i] + s * (g0z[i] - g2x[i]);
        az[i] = az[i] + s * (g1x[i] - g0y[i]);
    }
}

template <class T>
GALE_NOISE_INLINE void copyLanes(int m, const T* __restrict from, T* __restrict to) {
    for (int i = 0; i < m; ++i) to[i] = from[i];
}

template <class T>
GALE_NOISE_INLINE void zeroLanes(int m, T* __restrict to) {
    for (int i = 0; i < m; ++i) to[i] = T(0);
}

// The potential channels of curl and flow noise (independent of the vector noises' channels).
constexpr int kCurlChannel = 3;

// ---- The pass and octave driver ------------------------------------------------------------

// Every fractal runs the same scaffolding: lanes in passes of kPass; per pass the D coordinates
// copied to p and the accumulators zeroed; octaves 0 .. maxCount-1, each added by
// `octave(m, o, p, oct, acc)`; between octaves P = P * lacunarity + shift on every axis, then
// `octave.next(m, oct)` (per-octave state of the octave functor) and the next amplitude.
// `octave.begin(m, base)` starts a pass; C of the accumulators are written to out.
template <class T, int D, class Octave>
GALE_NOISE_INLINE void fractalPasses(int n, const T* const (&coords)[D], const FractalLanes<T>& f,
                                     int C, T* const* out, Octave& octave) {
    for (int base = 0; base < n; base += kPass) {
        const int m = n - base < kPass ? n - base : kPass;
        OctaveLanes<T> oct;
        oct.load(f, base, m);
        alignas(64) T p[D][kPass], acc[3][kPass];
        for (int d = 0; d < D; ++d) copyLanes(m, coords[d] + base, p[d]);
        for (int c = 0; c < C; ++c) zeroLanes(m, acc[c]);
        octave.begin(m, base);
        for (int o = 0; o < oct.maxCount; ++o) {
            octave(m, o, p, oct, acc);
            if (o + 1 < oct.maxCount) {
                for (int d = 0; d < D; ++d) oct.scale(m, p[d], d);
                octave.next(m, oct);
                oct.advance(m);
            }
        }
        for (int c = 0; c < C; ++c) copyLanes(m, acc[c], out[c] + base);
    }
}

// An octave functor with no state of its own between octaves.
struct StatelessOctave {
    GALE_NOISE_INLINE void begin(int, int) {}
    template <class T>
    GALE_NOISE_INLINE void next(int, const OctaveLanes<T>&) {}
};

inline int clampChannels(int channels) {
    return channels < 1 ? 1 : (channels > 3 ? 3 : channels);
}

// ---- fbm and turbulence --------------------------------------------------------------------

// One octave of fbm (sum of snoise) or turbulence (sum of |snoise|) in 3D or 4D, C channels.
template <class T, int D>
struct FbmOctave : StatelessOctave {
    int channels = 1;
    bool absolute = false;
    alignas(64) T tmp[3][kPass];

    template <int C>
    GALE_NOISE_INLINE void lattice(int m, const T (*p)[kPass], uint32_t s0, uint32_t s1,
                                   uint32_t s2) {
        if constexpr (D == 3)
            gradient3Loop<T, C>(m, p[0], p[1], p[2], s0, s1, s2, tmp[0], tmp[1], tmp[2]);
        else
            gradient4Loop<T, C>(m, p[0], p[1], p[2], p[3], s0, s1, s2, tmp[0], tmp[1], tmp[2]);
    }
    GALE_NOISE_INLINE void operator()(int m, int o, const T (*p)[kPass], OctaveLanes<T>& oct,
                                      T (*acc)[kPass]) {
        const uint32_t s0 = channelSeed(0, o), s1 = channelSeed(1, o), s2 = channelSeed(2, o);
        if (channels == 3)
            lattice<3>(m, p, s0, s1, s2);
        else if (channels == 2)
            lattice<2>(m, p, s0, s1, s2);
        else
            lattice<1>(m, p, s0, s1, s2);
        oct.weights(m, o);
        for (int c = 0; c < channels; ++c) accumulate(m, absolute, oct.weight, tmp[c], acc[c]);
    }
};

template <class T>
GALE_NOISE_INLINE void fbm3Body(int n, const T* x, const T* y, const T* z, const FractalLanes<T>& f,
                                bool turbulence, int channels, T* const* out) {
    FbmOctave<T, 3> octave;
    octave.channels = clampChannels(channels);
    octave.absolute = turbulence;
    const T* const coords[3] = {x, y, z};
    fractalPasses(n, coords, f, octave.channels, out, octave);
}

template <class T>
GALE_NOISE_INLINE void fbm4Body(int n, const T* x, const T* y, const T* z, const T* w,
                                const FractalLanes<T>& f, int channels, T* const* out) {
    FbmOctave<T, 4> octave;
    octave.channels = clampChannels(channels);
    const T* const coords[4] = {x, y, z, w};
    fractalPasses(n, coords, f, octave.channels, out, octave);
}

// ---- Curl and flow noise -------------------------------------------------------------------

// One octave of curl noise: the gradients of three potential channels (3D or 4D), their curl.
template <class T, int D>
struct CurlOctave : StatelessOctave {
    alignas(64) T val[kPass], g[3][D][kPass];

    GALE_NOISE_INLINE void operator()(int m, int o, const T (*p)[kPass], OctaveLanes<T>& oct,
                                      T (*acc)[kPass]) {
        for (int c = 0; c < 3; ++c) {
            const uint32_t seed = channelSeed(kCurlChannel + c, o);
            if constexpr (D == 3)
                gradient3DerivLoop(m, p[0], p[1], p[2], seed, val, g[c][0], g[c][1], g[c][2]);
            else
                gradient4DerivLoop(m, p[0], p[1], p[2], p[3], seed, val, g[c][0], g[c][1], g[c][2],
                                   g[c][3]);
        }
        oct.weights(m, o);
        accumulateCurl(m, oct.weight, g[0][1], g[0][2], g[1][0], g[1][2], g[2][0], g[2][1], acc[0],
                       acc[1], acc[2]);
    }
};

template <class T>
GALE_NOISE_INLINE void curl3Body(int n, const T* x, const T* y, const T* z,
                                 const FractalLanes<T>& f, T* const* out) {
    CurlOctave<T, 3> octave;
    const T* const coords[3] = {x, y, z};
    fractalPasses(n, coords, f, 3, out, octave);
}

template <class T>
GALE_NOISE_INLINE void curl4Body(int n, const T* x, const T* y, const T* z, const T* t,
                                 const FractalLanes<T>& f, T* const* out) {
    CurlOctave<T, 4> octave;
    const T* const coords[4] = {x, y, z, t};
    fractalPasses(n, coords, f, 3, out, octave);
}

// Rotation axes of flow noise's three potential channels (unit vectors off the lattice axes).
constexpr double kFlowAxis[3][3] = {{0.2672612419124244, 0.5345224838248488, 0.8017837257372732},
                                    {0.8017837257372732, 0.2672612419124244, 0.5345224838248488},
                                    {0.5345224838248488, 0.8017837257372732, 0.2672612419124244}};

// R = c I + s [a]x + (1 - c) a a^T: rotation by the angle with cosine c and sine s about a.
template <class T>
GALE_NOISE_INLINE void rotationLanes(int m, const double* axis, const T* __restrict s,
                                     const T* __restrict c, T (*__restrict rot)[kPass]) {
    const T ax = T(axis[0]), ay = T(axis[1]), az = T(axis[2]);
    for (int i = 0; i < m; ++i) {
        const T ci = c[i], si = s[i], k = T(1) - ci;
        rot[0][i] = ci + k * ax * ax;
        rot[1][i] = k * ax * ay - si * az;
        rot[2][i] = k * ax * az + si * ay;
        rot[3][i] = k * ay * ax + si * az;
        rot[4][i] = ci + k * ay * ay;
        rot[5][i] = k * ay * az - si * ax;
        rot[6][i] = k * az * ax - si * ay;
        rot[7][i] = k * az * ay + si * ax;
        rot[8][i] = ci + k * az * az;
    }
}

// One octave of flow noise: curl noise of three potentials whose lattice gradients turn about
// kFlowAxis[c]. Octave o turns at (lacunarity * gain)^o radians per unit of t: its eddies' speed
// (amplitude gain^o) over their size (lacunarity^-o).
template <class T>
struct FlowOctave {
    const T* t = nullptr;
    int base = 0;
    alignas(64) T val[kPass], g[3][3][kPass];
    alignas(64) T rate[kPass], angle[kPass], sn[kPass], cs[kPass], rot[9][kPass];

    GALE_NOISE_INLINE void begin(int m, int passBase) {
        base = passBase;
        for (int i = 0; i < m; ++i) rate[i] = T(1);
    }
    GALE_NOISE_INLINE void operator()(int m, int o, const T (*p)[kPass], OctaveLanes<T>& oct,
                                      T (*acc)[kPass]) {
        for (int i = 0; i < m; ++i) angle[i] = t[base + i] * rate[i];
        sinCosLoop(m, angle, sn, cs);
        for (int c = 0; c < 3; ++c) {
            rotationLanes(m, kFlowAxis[c], sn, cs, rot);
            gradient3RotatedLoop(m, p[0], p[1], p[2], rot[0], rot[1], rot[2], rot[3], rot[4],
                                 rot[5], rot[6], rot[7], rot[8], channelSeed(kCurlChannel + c, o),
                                 val, g[c][0], g[c][1], g[c][2]);
        }
        oct.weights(m, o);
        accumulateCurl(m, oct.weight, g[0][1], g[0][2], g[1][0], g[1][2], g[2][0], g[2][1], acc[0],
                       acc[1], acc[2]);
    }
    GALE_NOISE_INLINE void next(int m, const OctaveLanes<T>& oct) {
        for (int i = 0; i < m; ++i) rate[i] = rate[i] * (oct.lac[i] * oct.gain[i]);
    }
};

template <class T>
GALE_NOISE_INLINE void flow3Body(int n, const T* x, const T* y, const T* z, const T* t,
                                 const FractalLanes<T>& f, T* const* out) {
    FlowOctave<T> octave;
    octave.t = t;
    const T* const coords[3] = {x, y, z};
    fractalPasses(n, coords, f, 3, out, octave);
}

} // namespace

GALE_NOISE_DISPATCH(fbm3,
                    (int n, const T* x, const T* y, const T* z, const FractalLanes<T>& f,
                     bool turbulence, int channels, T* const* out),
                    (n, x, y, z, f, turbulence, channels, out))
GALE_NOISE_DISPATCH(fbm4,
                    (int n, const T* x, const T* y, const T* z, const T* w,
                     const FractalLanes<T>& f, int channels, T* const* out),
                    (n, x, y, z, w, f, channels, out))
GALE_NOISE_DISPATCH(curl3,
                    (int n, const T* x, const T* y, const T* z, const FractalLanes<T>& f,
                     T* const* out),
                    (n, x, y, z, f, out))
GALE_NOISE_DISPATCH(curl4,
                    (int n, const T* x, const T* y, const T* z, const T* t,
                     const FractalLanes<T>& f, T* const* out),
                    (n, x, y, z, t, f, out))
GALE_NOISE_DISPATCH(flow3,
                    (int n, const T* x, const T* y, const T* z, const T* t,
                     const FractalLanes<T>& f, T* const* out),
                    (n, x, y, z, t, f, out))

#define GALE_NOISE_INSTANTIATE(T)                                                                  \
    template void fbm3<T>(int, const T*, const T*, const T*, const FractalLanes<T>&, bool, int,    \
                          T* const*);                                                              \
    template void fbm4<T>(int, const T*, const T*, const T*, const T*, const FractalLanes<T>&,     \
                          int, T* const*);                                                         \
    template void curl3<T>(int, const T*, const T*, const T*, const FractalLanes<T>&, T* const*);  \
    template void curl4<T>(int, const T*, const T*, const T*, const T*, const FractalLanes<T>&,    \
                           T* const*);                                                             \
    template void flow3<T>(int, const T*, const T*, const T*, const T*, const FractalLanes<T>&,    \
                           T* const*);

GALE_NOISE_INSTANTIATE(float)
GALE_NOISE_INSTANTIATE(double)
#undef GALE_NOISE_INSTANTIATE

} // namespace gale::runtime::noise
