// The lane loops of the noise core: one pass of gradient noise (2-4D, value or value and
// gradient, rotated gradients), cell values and sin/cos over arrays of lanes. Each is an
// always-inline template so that it is compiled into every SIMD-level entry point that uses it.
#pragma once

#include "runtime/noise_detail.h"

namespace gale::runtime::noise::detail {

// One axis of a point's lattice cell: the primed coordinates of its lower and upper corners
// (floor(p) * prime, the next one) and the offset f = p - floor(p) in [0, 1).
template <class T>
struct LatticeAxis {
    uint32_t lo, hi;
    T f;
};
template <class T>
GALE_NOISE_INLINE LatticeAxis<T> latticeAxis(T p, uint32_t prime) {
    int32_t ip;
    LatticeAxis<T> a;
    split(p, ip, a.f);
    a.lo = static_cast<uint32_t>(ip) * prime;
    a.hi = a.lo + prime;
    return a;
}

// ---- 2D -----------------------------------------------------------------------------

// The eight directions of a regular octagon: axes and unit diagonals (a 7-design on the circle).
template <class T>
GALE_NOISE_INLINE T dot2(uint32_t h, T dx, T dy) {
    const T a = (h & 1u) ? -dx : dx;
    const T b = (h & 2u) ? -dy : dy;
    const T axis = (h & 4u) ? a : b;
    const T diag = (a + b) * T(0.70710678118654752);
    return (h & 8u) ? diag : axis;
}

template <class T>
GALE_NOISE_INLINE void gradient2Loop(int n, const T* __restrict x, const T* __restrict y,
                                     uint32_t seed, T* __restrict out) {
    for (int i = 0; i < n; ++i) {
        const LatticeAxis<T> X = latticeAxis(x[i], kPrimeX), Y = latticeAxis(y[i], kPrimeY);
        const T fx = X.f, fy = Y.f;
        const uint32_t x0 = X.lo, x1 = X.hi, y0 = Y.lo ^ seed, y1 = Y.hi ^ seed;
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

// One channel at a point whose lattice terms are known: a.. = primed x ^ primed y of the four
// x-y corners, z0/z1 = primed z ^ seed.
template <class T>
GALE_NOISE_INLINE T value3(uint32_t a00, uint32_t a10, uint32_t a01, uint32_t a11, uint32_t z0,
                           uint32_t z1, T fx, T fy, T fz, T gx, T gy, T gz, T u, T v, T w) {
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

// C channels (1..3) with seeds s[c], sharing the lattice work.
template <class T, int C>
GALE_NOISE_INLINE void gradient3Loop(int n, const T* __restrict x, const T* __restrict y,
                                     const T* __restrict z, uint32_t s0, uint32_t s1, uint32_t s2,
                                     T* __restrict o0, T* __restrict o1, T* __restrict o2) {
    for (int i = 0; i < n; ++i) {
        const LatticeAxis<T> X = latticeAxis(x[i], kPrimeX), Y = latticeAxis(y[i], kPrimeY),
                             Z = latticeAxis(z[i], kPrimeZ);
        const T fx = X.f, fy = Y.f, fz = Z.f;
        const uint32_t x0 = X.lo, x1 = X.hi, y0 = Y.lo, y1 = Y.hi, z0 = Z.lo, z1 = Z.hi;
        const uint32_t a00 = x0 ^ y0, a10 = x1 ^ y0, a01 = x0 ^ y1, a11 = x1 ^ y1;
        const T gx = fx - T(1), gy = fy - T(1), gz = fz - T(1);
        const T u = fade(fx), v = fade(fy), w = fade(fz);
        o0[i] = value3(a00, a10, a01, a11, z0 ^ s0, z1 ^ s0, fx, fy, fz, gx, gy, gz, u, v, w);
        if constexpr (C > 1)
            o1[i] = value3(a00, a10, a01, a11, z0 ^ s1, z1 ^ s1, fx, fy, fz, gx, gy, gz, u, v, w);
        if constexpr (C > 2)
            o2[i] = value3(a00, a10, a01, a11, z0 ^ s2, z1 ^ s2, fx, fy, fz, gx, gy, gz, u, v, w);
    }
}

// A corner's value and gradient; multilinear interpolation carries the derivative in forward
// mode through each lerp: d(a + u (b - a)) = da + u (db - da) + du (b - a) along u's axis.
template <class T>
struct VG3 {
    T v, gx, gy, gz;
};

template <int Axis, class T>
GALE_NOISE_INLINE VG3<T> lerpVG(const VG3<T>& a, const VG3<T>& b, T u, T du) {
    VG3<T> r;
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

// Corners in the order x fastest: c[k] is corner (k & 1, (k >> 1) & 1, (k >> 2) & 1).
template <class T>
GALE_NOISE_INLINE VG3<T> interpolate3(const VG3<T>* c, T fx, T fy, T fz) {
    const T u = fade(fx), v = fade(fy), w = fade(fz);
    const T du = fadeDeriv(fx), dv = fadeDeriv(fy), dw = fadeDeriv(fz);
    const VG3<T> x00 = lerpVG<0>(c[0], c[1], u, du);
    const VG3<T> x10 = lerpVG<0>(c[2], c[3], u, du);
    const VG3<T> x01 = lerpVG<0>(c[4], c[5], u, du);
    const VG3<T> x11 = lerpVG<0>(c[6], c[7], u, du);
    const VG3<T> y0 = lerpVG<1>(x00, x10, v, dv);
    const VG3<T> y1 = lerpVG<1>(x01, x11, v, dv);
    return lerpVG<2>(y0, y1, w, dw);
}

// The hashes of a cell's eight corners, x fastest (the order of interpolate3).
template <class T>
GALE_NOISE_INLINE void cornerHashes3(const LatticeAxis<T>& X, const LatticeAxis<T>& Y,
                                     const LatticeAxis<T>& Z, uint32_t seed, uint32_t* h) {
    const uint32_t z0 = Z.lo ^ seed, z1 = Z.hi ^ seed;
    h[0] = mixHash(X.lo ^ Y.lo ^ z0);
    h[1] = mixHash(X.hi ^ Y.lo ^ z0);
    h[2] = mixHash(X.lo ^ Y.hi ^ z0);
    h[3] = mixHash(X.hi ^ Y.hi ^ z0);
    h[4] = mixHash(X.lo ^ Y.lo ^ z1);
    h[5] = mixHash(X.hi ^ Y.lo ^ z1);
    h[6] = mixHash(X.lo ^ Y.hi ^ z1);
    h[7] = mixHash(X.hi ^ Y.hi ^ z1);
}

template <class T>
GALE_NOISE_INLINE void storeVG3(const VG3<T>& r, int i, T* __restrict value, T* __restrict ox,
                                T* __restrict oy, T* __restrict oz) {
    value[i] = r.v * T(kScale3);
    ox[i] = r.gx * T(kScale3);
    oy[i] = r.gy * T(kScale3);
    oz[i] = r.gz * T(kScale3);
}

// Value (bit-identical to gradient3Loop's) and gradient.
template <class T>
GALE_NOISE_INLINE void gradient3DerivLoop(int n, const T* __restrict x, const T* __restrict y,
                                          const T* __restrict z, uint32_t seed, T* __restrict value,
                                          T* __restrict ox, T* __restrict oy, T* __restrict oz) {
    for (int i = 0; i < n; ++i) {
        const LatticeAxis<T> X = latticeAxis(x[i], kPrimeX), Y = latticeAxis(y[i], kPrimeY),
                             Z = latticeAxis(z[i], kPrimeZ);
        const T fx = X.f, fy = Y.f, fz = Z.f;
        const T gx = fx - T(1), gy = fy - T(1), gz = fz - T(1);
        uint32_t h[8];
        cornerHashes3(X, Y, Z, seed, h);
        VG3<T> c[8];
#pragma GCC unroll 8
        for (int k = 0; k < 8; ++k) {
            const T dx = (k & 1) ? gx : fx, dy = (k & 2) ? gy : fy, dz = (k & 4) ? gz : fz;
            c[k].v = dot3(h[k], dx, dy, dz);
            grad3(h[k], c[k].gx, c[k].gy, c[k].gz);
        }
        const VG3<T> r = interpolate3(c, fx, fy, fz);
        storeVG3(r, i, value, ox, oy, oz);
    }
}

// Every lattice gradient g turned by the per-lane rotation R (row-major r00..r22): the value
// sums (R g) . d = g . (R^T d), and the gradient interpolates R g.
template <class T>
GALE_NOISE_INLINE void
gradient3RotatedLoop(int n, const T* __restrict x, const T* __restrict y, const T* __restrict z,
                     const T* __restrict r00, const T* __restrict r01, const T* __restrict r02,
                     const T* __restrict r10, const T* __restrict r11, const T* __restrict r12,
                     const T* __restrict r20, const T* __restrict r21, const T* __restrict r22,
                     uint32_t seed, T* __restrict value, T* __restrict ox, T* __restrict oy,
                     T* __restrict oz) {
    for (int i = 0; i < n; ++i) {
        const LatticeAxis<T> X = latticeAxis(x[i], kPrimeX), Y = latticeAxis(y[i], kPrimeY),
                             Z = latticeAxis(z[i], kPrimeZ);
        const T fx = X.f, fy = Y.f, fz = Z.f;
        const T a00 = r00[i], a01 = r01[i], a02 = r02[i];
        const T a10 = r10[i], a11 = r11[i], a12 = r12[i];
        const T a20 = r20[i], a21 = r21[i], a22 = r22[i];
        // q = R^T f; corner k's offset R^T (f - k) subtracts row j of R for each set bit j.
        const T qx = a00 * fx + a10 * fy + a20 * fz;
        const T qy = a01 * fx + a11 * fy + a21 * fz;
        const T qz = a02 * fx + a12 * fy + a22 * fz;
        uint32_t h[8];
        cornerHashes3(X, Y, Z, seed, h);
        VG3<T> c[8];
#pragma GCC unroll 8
        for (int k = 0; k < 8; ++k) {
            T dx = qx, dy = qy, dz = qz;
            if (k & 1) {
                dx = dx - a00;
                dy = dy - a01;
                dz = dz - a02;
            }
            if (k & 2) {
                dx = dx - a10;
                dy = dy - a11;
                dz = dz - a12;
            }
            if (k & 4) {
                dx = dx - a20;
                dy = dy - a21;
                dz = dz - a22;
            }
            T gxl, gyl, gzl;
            grad3(h[k], gxl, gyl, gzl);
            c[k].v = dot3(h[k], dx, dy, dz);
            c[k].gx = a00 * gxl + a01 * gyl + a02 * gzl;
            c[k].gy = a10 * gxl + a11 * gyl + a12 * gzl;
            c[k].gz = a20 * gxl + a21 * gyl + a22 * gzl;
        }
        const VG3<T> r = interpolate3(c, fx, fy, fz);
        storeVG3(r, i, value, ox, oy, oz);
    }
}

// ---- 4D ------------------------------------------------------------------------------------

// One channel of 4D noise: 16 corners, x fastest; xy[k & 3] = primed x ^ primed y of the four
// x-y corners, zw[k >> 2] = primed z ^ primed w ^ seed of the four z-w corners.
template <class T>
GALE_NOISE_INLINE T value4(const uint32_t* xy, const uint32_t* zw, const T* d0, const T* d1,
                           const T* d2, const T* d3, T u0, T u1, T u2, T u3) {
    T v[16];
#pragma GCC unroll 16
    for (int k = 0; k < 16; ++k)
        v[k] = dot4(mixHash(xy[k & 3] ^ zw[k >> 2]), d0[k & 1], d1[(k >> 1) & 1], d2[(k >> 2) & 1],
                    d3[k >> 3]);
    T a[8];
#pragma GCC unroll 8
    for (int k = 0; k < 8; ++k) a[k] = lerp(v[2 * k], v[2 * k + 1], u0);
    T b[4];
#pragma GCC unroll 4
    for (int k = 0; k < 4; ++k) b[k] = lerp(a[2 * k], a[2 * k + 1], u1);
    const T c0 = lerp(b[0], b[1], u2), c1 = lerp(b[2], b[3], u2);
    return lerp(c0, c1, u3) * T(kScale4);
}

// A point's 4D cell: the primed x ^ y of its four x-y corners, the primed z ^ w of its four z-w
// corners (x and z fastest), and the offsets from the lower (d[0]) and upper (d[1]) corner.
template <class T>
struct Cell4 {
    uint32_t xy[4], zw[4];
    T d0[2], d1[2], d2[2], d3[2];
};
template <class T>
GALE_NOISE_INLINE Cell4<T> cell4(T x, T y, T z, T w) {
    const LatticeAxis<T> X = latticeAxis(x, kPrimeX), Y = latticeAxis(y, kPrimeY),
                         Z = latticeAxis(z, kPrimeZ), W = latticeAxis(w, kPrimeW);
    Cell4<T> c;
    c.xy[0] = X.lo ^ Y.lo;
    c.xy[1] = X.hi ^ Y.lo;
    c.xy[2] = X.lo ^ Y.hi;
    c.xy[3] = X.hi ^ Y.hi;
    c.zw[0] = Z.lo ^ W.lo;
    c.zw[1] = Z.hi ^ W.lo;
    c.zw[2] = Z.lo ^ W.hi;
    c.zw[3] = Z.hi ^ W.hi;
    c.d0[0] = X.f, c.d0[1] = X.f - T(1);
    c.d1[0] = Y.f, c.d1[1] = Y.f - T(1);
    c.d2[0] = Z.f, c.d2[1] = Z.f - T(1);
    c.d3[0] = W.f, c.d3[1] = W.f - T(1);
    return c;
}

template <class T, int C>
GALE_NOISE_INLINE void gradient4Loop(int n, const T* __restrict x, const T* __restrict y,
                                     const T* __restrict z, const T* __restrict w, uint32_t s0,
                                     uint32_t s1, uint32_t s2, T* __restrict o0, T* __restrict o1,
                                     T* __restrict o2) {
    for (int i = 0; i < n; ++i) {
        const Cell4<T> q = cell4(x[i], y[i], z[i], w[i]);
        const uint32_t* xy = q.xy;
        const T fx = q.d0[0], fy = q.d1[0], fz = q.d2[0], fw = q.d3[0];
        const uint32_t* zw = q.zw;
        const T *d0 = q.d0, *d1 = q.d1, *d2 = q.d2, *d3 = q.d3;
        const T u0 = fade(fx), u1 = fade(fy), u2 = fade(fz), u3 = fade(fw);
        {
            const uint32_t zs[4] = {zw[0] ^ s0, zw[1] ^ s0, zw[2] ^ s0, zw[3] ^ s0};
            o0[i] = value4(xy, zs, d0, d1, d2, d3, u0, u1, u2, u3);
        }
        if constexpr (C > 1) {
            const uint32_t zs[4] = {zw[0] ^ s1, zw[1] ^ s1, zw[2] ^ s1, zw[3] ^ s1};
            o1[i] = value4(xy, zs, d0, d1, d2, d3, u0, u1, u2, u3);
        }
        if constexpr (C > 2) {
            const uint32_t zs[4] = {zw[0] ^ s2, zw[1] ^ s2, zw[2] ^ s2, zw[3] ^ s2};
            o2[i] = value4(xy, zs, d0, d1, d2, d3, u0, u1, u2, u3);
        }
    }
}

template <class T>
struct VG4 {
    T v, g[4];
};

template <int Axis, class T>
GALE_NOISE_INLINE VG4<T> lerpVG4(const VG4<T>& a, const VG4<T>& b, T u, T du) {
    VG4<T> r;
    r.v = lerp(a.v, b.v, u);
    r.g[0] = lerp(a.g[0], b.g[0], u);
    r.g[1] = lerp(a.g[1], b.g[1], u);
    r.g[2] = lerp(a.g[2], b.g[2], u);
    r.g[3] = lerp(a.g[3], b.g[3], u);
    r.g[Axis] = r.g[Axis] + du * (b.v - a.v);
    return r;
}

// Value (bit-identical to gradient4Loop's) and gradient.
template <class T>
GALE_NOISE_INLINE void gradient4DerivLoop(int n, const T* __restrict x, const T* __restrict y,
                                          const T* __restrict z, const T* __restrict w,
                                          uint32_t seed, T* __restrict value, T* __restrict ox,
                                          T* __restrict oy, T* __restrict oz, T* __restrict ow) {
    for (int i = 0; i < n; ++i) {
        const Cell4<T> q = cell4(x[i], y[i], z[i], w[i]);
        const uint32_t* xy = q.xy;
        const T fx = q.d0[0], fy = q.d1[0], fz = q.d2[0], fw = q.d3[0];
        const uint32_t zw[4] = {q.zw[0] ^ seed, q.zw[1] ^ seed, q.zw[2] ^ seed, q.zw[3] ^ seed};
        const T *d0 = q.d0, *d1 = q.d1, *d2 = q.d2, *d3 = q.d3;
        VG4<T> c[16];
#pragma GCC unroll 16
        for (int k = 0; k < 16; ++k) {
            const uint32_t h = mixHash(xy[k & 3] ^ zw[k >> 2]);
            c[k].v = dot4(h, d0[k & 1], d1[(k >> 1) & 1], d2[(k >> 2) & 1], d3[k >> 3]);
            grad4(h, c[k].g[0], c[k].g[1], c[k].g[2], c[k].g[3]);
        }
        const T u[4] = {fade(fx), fade(fy), fade(fz), fade(fw)};
        const T du[4] = {fadeDeriv(fx), fadeDeriv(fy), fadeDeriv(fz), fadeDeriv(fw)};
        VG4<T> a[8];
#pragma GCC unroll 8
        for (int k = 0; k < 8; ++k) a[k] = lerpVG4<0>(c[2 * k], c[2 * k + 1], u[0], du[0]);
        VG4<T> b[4];
#pragma GCC unroll 4
        for (int k = 0; k < 4; ++k) b[k] = lerpVG4<1>(a[2 * k], a[2 * k + 1], u[1], du[1]);
        const VG4<T> e0 = lerpVG4<2>(b[0], b[1], u[2], du[2]),
                     e1 = lerpVG4<2>(b[2], b[3], u[2], du[2]);
        const VG4<T> r = lerpVG4<3>(e0, e1, u[3], du[3]);
        value[i] = r.v * T(kScale4);
        ox[i] = r.g[0] * T(kScale4);
        oy[i] = r.g[1] * T(kScale4);
        oz[i] = r.g[2] * T(kScale4);
        ow[i] = r.g[3] * T(kScale4);
    }
}

// ---- Cells and angles ----------------------------------------------------------------------

template <class T, int C>
GALE_NOISE_INLINE void cell3Loop(int n, const T* __restrict x, const T* __restrict y,
                                 const T* __restrict z, uint32_t s0, uint32_t s1, uint32_t s2,
                                 T* __restrict o0, T* __restrict o1, T* __restrict o2) {
    for (int i = 0; i < n; ++i) {
        int32_t ix, iy, iz;
        T fx, fy, fz;
        split(x[i], ix, fx);
        split(y[i], iy, fy);
        split(z[i], iz, fz);
        const T nan = (fx + fy + fz) * T(0); // 0, or NaN for NaN and infinite coordinates
        o0[i] = cellValue<T>(ix, iy, iz, s0) + nan;
        if constexpr (C > 1) o1[i] = cellValue<T>(ix, iy, iz, s1) + nan;
        if constexpr (C > 2) o2[i] = cellValue<T>(ix, iy, iz, s2) + nan;
    }
}

template <class T>
GALE_NOISE_INLINE void sinCosLoop(int n, const T* __restrict x, T* __restrict s, T* __restrict c) {
    for (int i = 0; i < n; ++i) sinCosOf(x[i], s[i], c[i]);
}

} // namespace gale::runtime::noise::detail
