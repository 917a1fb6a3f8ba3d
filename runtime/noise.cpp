// Gradient noise in 1-4 dimensions, value and analytic derivatives, as branch-free lane loops:
// lattice coordinates by truncation, an integer multiply-xorshift hash of primed coordinates,
// gradients chosen by bit selects (icosahedron vertices in 3D, 24-cell vertices in 4D).
#include "runtime/noise.h"
#include "runtime/noise_detail.h"

namespace gale::runtime::noise {

using namespace detail;

uint32_t channelSeed(int channel, int octave) {
    return mixStrong(static_cast<uint32_t>(channel) * 0x9E3779B9u + static_cast<uint32_t>(octave) * 0x632BE5ABu +
                     0x1B873593u);
}

namespace {

// ---- 1D and 2D -----------------------------------------------------------------------------

template <class T>
GALE_NOISE_INLINE T dot1(uint32_t h, T d) {
    // A gradient uniform in [-1, 1].
    return static_cast<T>(static_cast<int32_t>(h)) * T(1.0 / 2147483648.0) * d;
}

template <class T>
GALE_NOISE_INLINE T dot2(uint32_t h, T dx, T dy) {
    // The eight directions of a regular octagon: axes and unit diagonals.
    const T a = (h & 1u) ? -dx : dx;
    const T b = (h & 2u) ? -dy : dy;
    const T axis = (h & 4u) ? a : b;
    const T diag = (a + b) * T(0.70710678118654752);
    return (h & 8u) ? diag : axis;
}

} // namespace

template <class T>
void gradient1(int n, const T* __restrict x, uint32_t seed, T* __restrict out) {
    for (int i = 0; i < n; ++i) {
        int32_t ix;
        T fx;
        split(x[i], ix, fx);
        const uint32_t x0 = static_cast<uint32_t>(ix) * kPrimeX ^ seed;
        const uint32_t x1 = (static_cast<uint32_t>(ix) * kPrimeX + kPrimeX) ^ seed;
        const T a = dot1(mixHash(x0), fx);
        const T b = dot1(mixHash(x1), fx - T(1));
        out[i] = lerp(a, b, fade(fx)) * T(kScale1);
    }
}

template <class T>
void gradient2(int n, const T* __restrict x, const T* __restrict y, uint32_t seed, T* __restrict out) {
    for (int i = 0; i < n; ++i) {
        int32_t ix, iy;
        T fx, fy;
        split(x[i], ix, fx);
        split(y[i], iy, fy);
        const uint32_t x0 = static_cast<uint32_t>(ix) * kPrimeX, x1 = x0 + kPrimeX;
        const uint32_t y0 = (static_cast<uint32_t>(iy) * kPrimeY) ^ seed, y1 = (static_cast<uint32_t>(iy) * kPrimeY + kPrimeY) ^ seed;
        const T gx = fx - T(1), gy = fy - T(1);
        const T n00 = dot2(mixHash(x0 ^ y0), fx, fy);
        const T n10 = dot2(mixHash(x1 ^ y0), gx, fy);
        const T n01 = dot2(mixHash(x0 ^ y1), fx, gy);
        const T n11 = dot2(mixHash(x1 ^ y1), gx, gy);
        const T u = fade(fx), v = fade(fy);
        out[i] = lerp(lerp(n00, n10, u), lerp(n01, n11, u), v) * T(kScale2);
    }
}

// ---- 3D ------------------------------------------------------------------------------------

namespace {

// One channel of 3D noise at a point whose lattice terms are already known.
template <class T>
GALE_NOISE_INLINE T value3(uint32_t a00, uint32_t a10, uint32_t a01, uint32_t a11, uint32_t z0, uint32_t z1, T fx,
                           T fy, T fz, T gx, T gy, T gz, T u, T v, T w) {
    const T n000 = dot3(mixHash(a00 ^ z0), fx, fy, fz);
    const T n100 = dot3(mixHash(a10 ^ z0), gx, fy, fz);
    const T n010 = dot3(mixHash(a01 ^ z0), fx, gy, fz);
    const T n110 = dot3(mixHash(a11 ^ z0), gx, gy, fz);
    const T n001 = dot3(mixHash(a00 ^ z1), fx, fy, gz);
    const T n101 = dot3(mixHash(a10 ^ z1), gx, fy, gz);
    const T n011 = dot3(mixHash(a01 ^ z1), fx, gy, gz);
    const T n111 = dot3(mixHash(a11 ^ z1), gx, gy, gz);
    const T c0 = lerp(lerp(n000, n100, u), lerp(n010, n110, u), v);
    const T c1 = lerp(lerp(n001, n101, u), lerp(n011, n111, u), v);
    return lerp(c0, c1, w) * T(kScale3);
}

template <class T, int C>
void gradient3Pass(int n, const T* __restrict x, const T* __restrict y, const T* __restrict z, const uint32_t* seeds,
                   T* const* out) {
    const uint32_t s0 = seeds[0];
    const uint32_t s1 = C > 1 ? seeds[1] : 0u;
    const uint32_t s2 = C > 2 ? seeds[2] : 0u;
    T* __restrict o0 = out[0];
    T* __restrict o1 = C > 1 ? out[1] : nullptr;
    T* __restrict o2 = C > 2 ? out[2] : nullptr;
    for (int i = 0; i < n; ++i) {
        int32_t ix, iy, iz;
        T fx, fy, fz;
        split(x[i], ix, fx);
        split(y[i], iy, fy);
        split(z[i], iz, fz);
        const uint32_t x0 = static_cast<uint32_t>(ix) * kPrimeX, x1 = x0 + kPrimeX;
        const uint32_t y0 = static_cast<uint32_t>(iy) * kPrimeY, y1 = y0 + kPrimeY;
        const uint32_t z0 = static_cast<uint32_t>(iz) * kPrimeZ, z1 = z0 + kPrimeZ;
        const uint32_t a00 = x0 ^ y0, a10 = x1 ^ y0, a01 = x0 ^ y1, a11 = x1 ^ y1;
        const T gx = fx - T(1), gy = fy - T(1), gz = fz - T(1);
        const T u = fade(fx), v = fade(fy), w = fade(fz);
        o0[i] = value3(a00, a10, a01, a11, z0 ^ s0, z1 ^ s0, fx, fy, fz, gx, gy, gz, u, v, w);
        if constexpr (C > 1) o1[i] = value3(a00, a10, a01, a11, z0 ^ s1, z1 ^ s1, fx, fy, fz, gx, gy, gz, u, v, w);
        if constexpr (C > 2) o2[i] = value3(a00, a10, a01, a11, z0 ^ s2, z1 ^ s2, fx, fy, fz, gx, gy, gz, u, v, w);
    }
}

// A corner's value and gradient, then multilinear interpolation carrying the derivative
// (forward mode through each lerp: d(a + u(b - a)) = da + u(db - da) + du (b - a)).
template <class T>
struct VG {
    T v, gx, gy, gz;
};

template <class T>
GALE_NOISE_INLINE VG<T> corner3(uint32_t h, T dx, T dy, T dz) {
    VG<T> r;
    r.v = dot3(h, dx, dy, dz);
    grad3(h, r.gx, r.gy, r.gz);
    return r;
}

// Axis 0, 1, 2: which component receives du * (b - a).
template <int Axis, class T>
GALE_NOISE_INLINE VG<T> lerpVG(const VG<T>& a, const VG<T>& b, T u, T du) {
    VG<T> r;
    r.v = lerp(a.v, b.v, u);
    r.gx = lerp(a.gx, b.gx, u);
    r.gy = lerp(a.gy, b.gy, u);
    r.gz = lerp(a.gz, b.gz, u);
    const T slope = du * (b.v - a.v);
    if constexpr (Axis == 0) r.gx = r.gx + slope;
    if constexpr (Axis == 1) r.gy = r.gy + slope;
    if constexpr (Axis == 2) r.gz = r.gz + slope;
    return r;
}

template <class T>
GALE_NOISE_INLINE VG<T> interpolate3(const VG<T>* c, T fx, T fy, T fz) {
    const T u = fade(fx), v = fade(fy), w = fade(fz);
    const T du = fadeDeriv(fx), dv = fadeDeriv(fy), dw = fadeDeriv(fz);
    const VG<T> x00 = lerpVG<0>(c[0], c[1], u, du);
    const VG<T> x10 = lerpVG<0>(c[2], c[3], u, du);
    const VG<T> x01 = lerpVG<0>(c[4], c[5], u, du);
    const VG<T> x11 = lerpVG<0>(c[6], c[7], u, du);
    const VG<T> y0 = lerpVG<1>(x00, x10, v, dv);
    const VG<T> y1 = lerpVG<1>(x01, x11, v, dv);
    return lerpVG<2>(y0, y1, w, dw);
}

} // namespace

template <class T>
void gradient3(int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds, T* const* out) {
    if (channels >= 3) gradient3Pass<T, 3>(n, x, y, z, seeds, out);
    else if (channels == 2) gradient3Pass<T, 2>(n, x, y, z, seeds, out);
    else gradient3Pass<T, 1>(n, x, y, z, seeds, out);
}

template <class T>
void gradient3Deriv(int n, const T* __restrict x, const T* __restrict y, const T* __restrict z, uint32_t seed,
                    T* __restrict value, T* const* grad) {
    T* __restrict ox = grad[0];
    T* __restrict oy = grad[1];
    T* __restrict oz = grad[2];
    for (int i = 0; i < n; ++i) {
        int32_t ix, iy, iz;
        T fx, fy, fz;
        split(x[i], ix, fx);
        split(y[i], iy, fy);
        split(z[i], iz, fz);
        const uint32_t x0 = static_cast<uint32_t>(ix) * kPrimeX, x1 = x0 + kPrimeX;
        const uint32_t y0 = static_cast<uint32_t>(iy) * kPrimeY, y1 = y0 + kPrimeY;
        const uint32_t z0 = (static_cast<uint32_t>(iz) * kPrimeZ) ^ seed, z1 = (static_cast<uint32_t>(iz) * kPrimeZ + kPrimeZ) ^ seed;
        const T gx = fx - T(1), gy = fy - T(1), gz = fz - T(1);
        VG<T> c[8];
        c[0] = corner3(mixHash(x0 ^ y0 ^ z0), fx, fy, fz);
        c[1] = corner3(mixHash(x1 ^ y0 ^ z0), gx, fy, fz);
        c[2] = corner3(mixHash(x0 ^ y1 ^ z0), fx, gy, fz);
        c[3] = corner3(mixHash(x1 ^ y1 ^ z0), gx, gy, fz);
        c[4] = corner3(mixHash(x0 ^ y0 ^ z1), fx, fy, gz);
        c[5] = corner3(mixHash(x1 ^ y0 ^ z1), gx, fy, gz);
        c[6] = corner3(mixHash(x0 ^ y1 ^ z1), fx, gy, gz);
        c[7] = corner3(mixHash(x1 ^ y1 ^ z1), gx, gy, gz);
        const VG<T> r = interpolate3(c, fx, fy, fz);
        value[i] = r.v * T(kScale3);
        ox[i] = r.gx * T(kScale3);
        oy[i] = r.gy * T(kScale3);
        oz[i] = r.gz * T(kScale3);
    }
}

template <class T>
void gradient3Rotated(int n, const T* __restrict x, const T* __restrict y, const T* __restrict z,
                      const T* const* rot, uint32_t seed, T* __restrict value, T* const* grad) {
    const T* __restrict r00 = rot[0];
    const T* __restrict r01 = rot[1];
    const T* __restrict r02 = rot[2];
    const T* __restrict r10 = rot[3];
    const T* __restrict r11 = rot[4];
    const T* __restrict r12 = rot[5];
    const T* __restrict r20 = rot[6];
    const T* __restrict r21 = rot[7];
    const T* __restrict r22 = rot[8];
    T* __restrict ox = grad[0];
    T* __restrict oy = grad[1];
    T* __restrict oz = grad[2];
    for (int i = 0; i < n; ++i) {
        int32_t ix, iy, iz;
        T fx, fy, fz;
        split(x[i], ix, fx);
        split(y[i], iy, fy);
        split(z[i], iz, fz);
        const uint32_t x0 = static_cast<uint32_t>(ix) * kPrimeX, x1 = x0 + kPrimeX;
        const uint32_t y0 = static_cast<uint32_t>(iy) * kPrimeY, y1 = y0 + kPrimeY;
        const uint32_t z0 = (static_cast<uint32_t>(iz) * kPrimeZ) ^ seed, z1 = (static_cast<uint32_t>(iz) * kPrimeZ + kPrimeZ) ^ seed;
        // The rotated gradient R g dotted with d equals g dotted with R^T d: rotate the offsets.
        const T a00 = r00[i], a01 = r01[i], a02 = r02[i];
        const T a10 = r10[i], a11 = r11[i], a12 = r12[i];
        const T a20 = r20[i], a21 = r21[i], a22 = r22[i];
        // q = R^T f, and the corner offsets R^T (f - corner) = q - R^T corner.
        const T qx = a00 * fx + a10 * fy + a20 * fz;
        const T qy = a01 * fx + a11 * fy + a21 * fz;
        const T qz = a02 * fx + a12 * fy + a22 * fz;
        T dx[8], dy[8], dz[8];
        for (int k = 0; k < 8; ++k) {
            // Corner k is (k & 1, (k >> 1) & 1, (k >> 2) & 1); R^T e_j is row j of R.
            T cx = qx, cy = qy, cz = qz;
            if (k & 1) { cx = cx - a00; cy = cy - a01; cz = cz - a02; }
            if (k & 2) { cx = cx - a10; cy = cy - a11; cz = cz - a12; }
            if (k & 4) { cx = cx - a20; cy = cy - a21; cz = cz - a22; }
            dx[k] = cx; dy[k] = cy; dz[k] = cz;
        }
        const uint32_t h[8] = {mixHash(x0 ^ y0 ^ z0), mixHash(x1 ^ y0 ^ z0), mixHash(x0 ^ y1 ^ z0),
                               mixHash(x1 ^ y1 ^ z0), mixHash(x0 ^ y0 ^ z1), mixHash(x1 ^ y0 ^ z1),
                               mixHash(x0 ^ y1 ^ z1), mixHash(x1 ^ y1 ^ z1)};
        VG<T> c[8];
        for (int k = 0; k < 8; ++k) {
            T gxl, gyl, gzl;
            grad3(h[k], gxl, gyl, gzl);
            c[k].v = dot3(h[k], dx[k], dy[k], dz[k]);
            c[k].gx = a00 * gxl + a01 * gyl + a02 * gzl;
            c[k].gy = a10 * gxl + a11 * gyl + a12 * gzl;
            c[k].gz = a20 * gxl + a21 * gyl + a22 * gzl;
        }
        const VG<T> r = interpolate3(c, fx, fy, fz);
        value[i] = r.v * T(kScale3);
        ox[i] = r.gx * T(kScale3);
        oy[i] = r.gy * T(kScale3);
        oz[i] = r.gz * T(kScale3);
    }
}

template <class T>
void gradient3Periodic(int n, const T* x, const T* y, const T* z, const int32_t* px, const int32_t* py,
                       const int32_t* pz, uint32_t seed, T* out) {
    // Rarely used: one lane at a time (integer remainders do not vectorise on SSE2).
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
    template void gradient1<T>(int, const T*, uint32_t, T*);                                                       \
    template void gradient2<T>(int, const T*, const T*, uint32_t, T*);                                             \
    template void gradient3<T>(int, const T*, const T*, const T*, int, const uint32_t*, T* const*);               \
    template void gradient3Deriv<T>(int, const T*, const T*, const T*, uint32_t, T*, T* const*);                  \
    template void gradient3Rotated<T>(int, const T*, const T*, const T*, const T* const*, uint32_t, T*, T* const*); \
    template void gradient3Periodic<T>(int, const T*, const T*, const T*, const int32_t*, const int32_t*,          \
                                       const int32_t*, uint32_t, T*);

GALE_NOISE_INSTANTIATE(float)
GALE_NOISE_INSTANTIATE(double)
#undef GALE_NOISE_INSTANTIATE

} // namespace gale::runtime::noise
