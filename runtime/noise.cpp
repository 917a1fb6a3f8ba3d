// Entry points of the noise core for single noises: SIMD-level detection and dispatch, the
// gradient noises (1-4D, derivatives, rotated, periodic), cell values, Voronoi features and
// sin/cos. Each dispatching entry point runs one always-inline lane loop from noise_loops.h.
#include <atomic>

#include "runtime/noise.h"
#include "runtime/noise_loops.h"

namespace gale::runtime::noise {

using namespace detail;

// ---- SIMD level ----------------------------------------------------------------------------

namespace {
std::atomic<int> gSimdLimit{static_cast<int>(Simd::Avx512)};
}

Simd detectedSimd() {
    static const Simd level = [] {
#if defined(GALE_NOISE_X86)
        __builtin_cpu_init();
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx2"))
            return Simd::Avx512;
        if (__builtin_cpu_supports("avx2")) return Simd::Avx2;
        if (__builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt")) return Simd::Sse42;
#endif
        return Simd::Sse2;
    }();
    return level;
}

Simd simdLevel() {
    const int limit = gSimdLimit.load(std::memory_order_relaxed);
    const int detected = static_cast<int>(detectedSimd());
    return static_cast<Simd>(detected < limit ? detected : limit);
}

void limitSimd(Simd max) { gSimdLimit.store(static_cast<int>(max), std::memory_order_relaxed); }

const char* simdName(Simd s) {
    switch (s) {
    case Simd::Avx512: return "AVX-512";
    case Simd::Avx2: return "AVX2";
    case Simd::Sse42: return "SSE4.2";
    default: return "SSE2";
    }
}

uint32_t channelSeed(int channel, int octave) {
    return mixStrong(static_cast<uint32_t>(channel) * 0x9E3779B9u + static_cast<uint32_t>(octave) * 0x632BE5ABu +
                     0x1B873593u);
}

// ---- Bodies --------------------------------------------------------------------------------

namespace {

template <class T>
GALE_NOISE_INLINE void gradient2Body(int n, const T* x, const T* y, uint32_t seed, T* out) {
    gradient2Loop(n, x, y, seed, out);
}

template <class T>
GALE_NOISE_INLINE void gradient3Body(int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds,
                                     T* const* out) {
    if (channels >= 3) gradient3Loop<T, 3>(n, x, y, z, seeds[0], seeds[1], seeds[2], out[0], out[1], out[2]);
    else if (channels == 2) gradient3Loop<T, 2>(n, x, y, z, seeds[0], seeds[1], 0u, out[0], out[1], nullptr);
    else gradient3Loop<T, 1>(n, x, y, z, seeds[0], 0u, 0u, out[0], nullptr, nullptr);
}

template <class T>
GALE_NOISE_INLINE void gradient3DerivBody(int n, const T* x, const T* y, const T* z, uint32_t seed, T* value,
                                          T* const* grad) {
    gradient3DerivLoop(n, x, y, z, seed, value, grad[0], grad[1], grad[2]);
}

template <class T>
GALE_NOISE_INLINE void gradient3RotatedBody(int n, const T* x, const T* y, const T* z, const T* const* rot,
                                            uint32_t seed, T* value, T* const* grad) {
    gradient3RotatedLoop(n, x, y, z, rot[0], rot[1], rot[2], rot[3], rot[4], rot[5], rot[6], rot[7], rot[8], seed,
                         value, grad[0], grad[1], grad[2]);
}

template <class T>
GALE_NOISE_INLINE void gradient4Body(int n, const T* x, const T* y, const T* z, const T* w, int channels,
                                     const uint32_t* seeds, T* const* out) {
    if (channels >= 3) gradient4Loop<T, 3>(n, x, y, z, w, seeds[0], seeds[1], seeds[2], out[0], out[1], out[2]);
    else if (channels == 2) gradient4Loop<T, 2>(n, x, y, z, w, seeds[0], seeds[1], 0u, out[0], out[1], nullptr);
    else gradient4Loop<T, 1>(n, x, y, z, w, seeds[0], 0u, 0u, out[0], nullptr, nullptr);
}

template <class T>
GALE_NOISE_INLINE void gradient4DerivBody(int n, const T* x, const T* y, const T* z, const T* w, uint32_t seed,
                                          T* value, T* const* grad) {
    gradient4DerivLoop(n, x, y, z, w, seed, value, grad[0], grad[1], grad[2], grad[3]);
}

template <class T>
GALE_NOISE_INLINE void cell3Body(int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds,
                                 T* const* out) {
    if (channels >= 3) cell3Loop<T, 3>(n, x, y, z, seeds[0], seeds[1], seeds[2], out[0], out[1], out[2]);
    else if (channels == 2) cell3Loop<T, 2>(n, x, y, z, seeds[0], seeds[1], 0u, out[0], out[1], nullptr);
    else cell3Loop<T, 1>(n, x, y, z, seeds[0], 0u, 0u, out[0], nullptr, nullptr);
}

template <class T>
GALE_NOISE_INLINE void sinCosBody(int n, const T* x, T* s, T* c) {
    sinCosLoop(n, x, s, c);
}

// One neighbour cell (ox, oy, oz) of every lane: its feature point, relative to the lane's
// cell, against the nearest and second nearest so far. Strict comparisons: on a tie the cell
// visited first wins (x outermost, then y, then z, as in SeExpr2).
template <class T>
GALE_NOISE_INLINE void voronoiStep(int m, int ox, int oy, int oz, const int32_t* __restrict cx,
                                   const int32_t* __restrict cy, const int32_t* __restrict cz,
                                   const T* __restrict fx, const T* __restrict fy, const T* __restrict fz,
                                   const T* __restrict jit, T* __restrict f1, T* __restrict f2, T* __restrict p1x,
                                   T* __restrict p1y, T* __restrict p1z, T* __restrict p2x, T* __restrict p2y,
                                   T* __restrict p2z, T* __restrict k1x, T* __restrict k1y, T* __restrict k1z,
                                   uint32_t s0, uint32_t s1, uint32_t s2) {
    const T tx = T(ox), ty = T(oy), tz = T(oz);
    for (int i = 0; i < m; ++i) {
        const int32_t X = cx[i] + ox, Y = cy[i] + oy, Z = cz[i] + oz;
        const T j = jit[i];
        const T px = tx + T(0.5) + j * (cellValue<T>(X, Y, Z, s0) - T(0.5));
        const T py = ty + T(0.5) + j * (cellValue<T>(X, Y, Z, s1) - T(0.5));
        const T pz = tz + T(0.5) + j * (cellValue<T>(X, Y, Z, s2) - T(0.5));
        const T dx = px - fx[i], dy = py - fy[i], dz = pz - fz[i];
        const T d = dx * dx + dy * dy + dz * dz;
        const T a1 = f1[i], a2 = f2[i];
        using U = typename BitsOf<T>::U;
        const U near1 = maskIf<T>(d < a1), near2 = maskIf<T>(d < a2);
        f2[i] = pick(near1, a1, pick(near2, d, a2));
        p2x[i] = pick(near1, p1x[i], pick(near2, px, p2x[i]));
        p2y[i] = pick(near1, p1y[i], pick(near2, py, p2y[i]));
        p2z[i] = pick(near1, p1z[i], pick(near2, pz, p2z[i]));
        f1[i] = pick(near1, d, a1);
        p1x[i] = pick(near1, px, p1x[i]);
        p1y[i] = pick(near1, py, p1y[i]);
        p1z[i] = pick(near1, pz, p1z[i]);
        k1x[i] = pick(near1, tx, k1x[i]);
        k1y[i] = pick(near1, ty, k1y[i]);
        k1z[i] = pick(near1, tz, k1z[i]);
    }
}

template <class T>
GALE_NOISE_INLINE void voronoi3Body(int n, const T* x, const T* y, const T* z, const T* jitter,
                                    const VoronoiLanes<T>& out) {
    const uint32_t s0 = channelSeed(0), s1 = channelSeed(1), s2 = channelSeed(2);
    for (int base = 0; base < n; base += kPass) {
        const int m = n - base < kPass ? n - base : kPass;
        alignas(64) int32_t cx[kPass], cy[kPass], cz[kPass];
        alignas(64) T fx[kPass], fy[kPass], fz[kPass], jit[kPass], f1[kPass], f2[kPass];
        alignas(64) T p1x[kPass], p1y[kPass], p1z[kPass], p2x[kPass], p2y[kPass], p2z[kPass];
        alignas(64) T k1x[kPass], k1y[kPass], k1z[kPass];
        for (int i = 0; i < m; ++i) {
            split(x[base + i], cx[i], fx[i]);
            split(y[base + i], cy[i], fy[i]);
            split(z[base + i], cz[i], fz[i]);
            jit[i] = jitter[base + i];
            f1[i] = f2[i] = T(1000);
            p1x[i] = p1y[i] = p1z[i] = p2x[i] = p2y[i] = p2z[i] = T(0);
            k1x[i] = k1y[i] = k1z[i] = T(0);
        }
        for (int ox = -1; ox <= 1; ++ox)
            for (int oy = -1; oy <= 1; ++oy)
                for (int oz = -1; oz <= 1; ++oz)
                    voronoiStep(m, ox, oy, oz, cx, cy, cz, fx, fy, fz, jit, f1, f2, p1x, p1y, p1z, p2x, p2y, p2z, k1x,
                                k1y, k1z, s0, s1, s2);
        for (int i = 0; i < m; ++i) {
            const int o = base + i;
            out.f1[o] = sqrtOf(f1[i]);
            out.f2[o] = sqrtOf(f2[i]);
            out.pos1[0][o] = T(cx[i]) + p1x[i];
            out.pos1[1][o] = T(cy[i]) + p1y[i];
            out.pos1[2][o] = T(cz[i]) + p1z[i];
            out.pos2[0][o] = T(cx[i]) + p2x[i];
            out.pos2[1][o] = T(cy[i]) + p2y[i];
            out.pos2[2][o] = T(cz[i]) + p2z[i];
            out.cell1[0][o] = cx[i] + static_cast<int32_t>(k1x[i]);
            out.cell1[1][o] = cy[i] + static_cast<int32_t>(k1y[i]);
            out.cell1[2][o] = cz[i] + static_cast<int32_t>(k1z[i]);
        }
    }
}

} // namespace

// ---- Entry points --------------------------------------------------------------------------

GALE_NOISE_DISPATCH(gradient2, (int n, const T* x, const T* y, uint32_t seed, T* out), (n, x, y, seed, out))
GALE_NOISE_DISPATCH(gradient3,
                    (int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds, T* const* out),
                    (n, x, y, z, channels, seeds, out))
GALE_NOISE_DISPATCH(gradient3Deriv, (int n, const T* x, const T* y, const T* z, uint32_t seed, T* value, T* const* grad),
                    (n, x, y, z, seed, value, grad))
GALE_NOISE_DISPATCH(gradient3Rotated,
                    (int n, const T* x, const T* y, const T* z, const T* const* rot, uint32_t seed, T* value,
                     T* const* grad),
                    (n, x, y, z, rot, seed, value, grad))
GALE_NOISE_DISPATCH(gradient4,
                    (int n, const T* x, const T* y, const T* z, const T* w, int channels, const uint32_t* seeds,
                     T* const* out),
                    (n, x, y, z, w, channels, seeds, out))
GALE_NOISE_DISPATCH(gradient4Deriv,
                    (int n, const T* x, const T* y, const T* z, const T* w, uint32_t seed, T* value, T* const* grad),
                    (n, x, y, z, w, seed, value, grad))
GALE_NOISE_DISPATCH(cell3, (int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds, T* const* out),
                    (n, x, y, z, channels, seeds, out))
GALE_NOISE_DISPATCH(voronoi3, (int n, const T* x, const T* y, const T* z, const T* jitter, const VoronoiLanes<T>& out),
                    (n, x, y, z, jitter, out))
GALE_NOISE_DISPATCH(sinCos, (int n, const T* x, T* s, T* c), (n, x, s, c))

// Periodic noise is rare: one lane at a time (integer remainders do not vectorise on SSE2).
template <class T>
void gradient3Periodic(int n, const T* x, const T* y, const T* z, const int32_t* px, const int32_t* py,
                       const int32_t* pz, uint32_t seed, T* out) {
    auto wrap = [](int32_t i, int32_t p, uint32_t& c0, uint32_t& c1) {
        if (p < 1) p = 1;
        int32_t r = i % p;
        if (r < 0) r += p;
        c0 = static_cast<uint32_t>(r);
        c1 = r + 1 == p ? 0u : static_cast<uint32_t>(r + 1);
    };
    for (int i = 0; i < n; ++i) {
        int32_t ix, iy, iz;
        T fx, fy, fz;
        split(x[i], ix, fx);
        split(y[i], iy, fy);
        split(z[i], iz, fz);
        uint32_t xa, xb, ya, yb, za, zb;
        wrap(ix, px[i], xa, xb);
        wrap(iy, py[i], ya, yb);
        wrap(iz, pz[i], za, zb);
        const uint32_t x0 = xa * kPrimeX, x1 = xb * kPrimeX;
        const uint32_t y0 = ya * kPrimeY, y1 = yb * kPrimeY;
        const uint32_t z0 = (za * kPrimeZ) ^ seed, z1 = (zb * kPrimeZ) ^ seed;
        out[i] = value3(x0 ^ y0, x1 ^ y0, x0 ^ y1, x1 ^ y1, z0, z1, fx, fy, fz, fx - T(1), fy - T(1), fz - T(1),
                        fade(fx), fade(fy), fade(fz));
    }
}

#define GALE_NOISE_INSTANTIATE(T)                                                                                 \
    template void gradient2<T>(int, const T*, const T*, uint32_t, T*);                                             \
    template void gradient3<T>(int, const T*, const T*, const T*, int, const uint32_t*, T* const*);               \
    template void gradient3Deriv<T>(int, const T*, const T*, const T*, uint32_t, T*, T* const*);                  \
    template void gradient3Rotated<T>(int, const T*, const T*, const T*, const T* const*, uint32_t, T*, T* const*); \
    template void gradient3Periodic<T>(int, const T*, const T*, const T*, const int32_t*, const int32_t*,          \
                                       const int32_t*, uint32_t, T*);                                              \
    template void gradient4<T>(int, const T*, const T*, const T*, const T*, int, const uint32_t*, T* const*);     \
    template void gradient4Deriv<T>(int, const T*, const T*, const T*, const T*, uint32_t, T*, T* const*);        \
    template void cell3<T>(int, const T*, const T*, const T*, int, const uint32_t*, T* const*);                   \
    template void voronoi3<T>(int, const T*, const T*, const T*, const T*, const VoronoiLanes<T>&);               \
    template void sinCos<T>(int, const T*, T*, T*);

GALE_NOISE_INSTANTIATE(float)
GALE_NOISE_INSTANTIATE(double)
#undef GALE_NOISE_INSTANTIATE

} // namespace gale::runtime::noise
