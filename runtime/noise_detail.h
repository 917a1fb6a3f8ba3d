// Inline building blocks of the noise core shared by noise*.cpp: lattice split, fade curves,
// integer hashes, gradient selection, a polynomial sin/cos, and the SIMD-level dispatch macro.
// Branch-free scalar code meant to be inlined into lane loops; every operation rounds the same
// in vector and scalar code, at every SIMD level. Not part of the runtime's public interface.
#pragma once

#include "runtime/noise.h"

#include <cstdint>

#define GALE_NOISE_INLINE inline __attribute__((always_inline))

// Lane loops must be if-converted to vectorise, and at baseline SSE2 GCC will not speculate a
// float operation that "could trap". The project builds with -fno-trapping-math; the pragma
// keeps the noise loops vectorised whatever the flags. Results do not change: it only drops the
// assumption that FP exceptions are observable (no reassociation, no contraction, NaN and
// signed zeros kept). Every noise*.cpp includes this header after its standard headers and calls
// no std:: function in lane code (GCC will not inline those across an option change).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-trapping-math")
#endif

// Runtime SIMD dispatch on x86-64: each entry point is compiled for SSE2 (the build's
// baseline), SSE4.2 (x86-64-v2: pmulld, blendv, round), AVX2 and AVX-512 and picked by CPUID.
// No FMA: every level gives the same bits.
#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
#define GALE_NOISE_X86 1
#define GALE_NOISE_SSE42 __attribute__((target("sse4.2,popcnt")))
#define GALE_NOISE_AVX2 __attribute__((target("avx2")))
#define GALE_NOISE_AVX512 __attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq,prefer-vector-width=512")))
#define GALE_NOISE_DISPATCH(Name, Params, Args)                                                   \
    template <class T>                                                                            \
    GALE_NOISE_AVX512 void Name##Avx512 Params {                                                  \
        Name##Body<T> Args;                                                                       \
    }                                                                                             \
    template <class T>                                                                            \
    GALE_NOISE_AVX2 void Name##Avx2 Params {                                                      \
        Name##Body<T> Args;                                                                       \
    }                                                                                             \
    template <class T>                                                                            \
    GALE_NOISE_SSE42 void Name##Sse42 Params {                                                    \
        Name##Body<T> Args;                                                                       \
    }                                                                                             \
    template <class T>                                                                            \
    void Name##Base Params {                                                                      \
        Name##Body<T> Args;                                                                       \
    }                                                                                             \
    template <class T>                                                                            \
    void Name Params {                                                                            \
        switch (simdLevel()) {                                                                    \
        case Simd::Avx512: Name##Avx512<T> Args; break;                                           \
        case Simd::Avx2: Name##Avx2<T> Args; break;                                               \
        case Simd::Sse42: Name##Sse42<T> Args; break;                                             \
        default: Name##Base<T> Args; break;                                                       \
        }                                                                                         \
    }
#else
#define GALE_NOISE_DISPATCH(Name, Params, Args)                                                   \
    template <class T>                                                                            \
    void Name Params {                                                                            \
        Name##Body<T> Args;                                                                       \
    }
#endif

namespace gale::runtime::noise::detail {

// Multipliers that spread integer lattice coordinates over 32 bits (large odd constants).
constexpr uint32_t kPrimeX = 0x9E3779B1u;
constexpr uint32_t kPrimeY = 0x85EBCA77u;
constexpr uint32_t kPrimeZ = 0xC2B2AE3Du;
constexpr uint32_t kPrimeW = 0x27D4EB2Fu;
constexpr uint32_t kHashMul = 0x5BD1E995u;

constexpr double kPhi = 1.61803398874989484820; // golden ratio: icosahedron vertices (0, ±1, ±phi)

// Amplitude scales: raw gradient noise times these has rms ~0.19 (SeExpr2's snoise).
constexpr double kScale2 = 0.8801;
constexpr double kScale3 = 0.5233;
constexpr double kScale4 = 0.7951;

// Coordinates are clamped to ±2^30 before taking the lattice cell (keeps the cell in int32).
constexpr double kCoordLimit = 1073741824.0;

// The fixed offset added after each octave's lacunarity scaling (fractional, so that octave
// lattices never line up; small, so that float keeps its precision over eight octaves).
constexpr double kOctaveShift[4] = {0.3183098861837907, 0.6180339887498949, 0.1415926535897932,
                                    0.7320508075688772};

// |x| and copysign as compiler builtins (bit operations).
template <class T>
GALE_NOISE_INLINE T absOf(T x) {
    if constexpr (sizeof(T) == 4) return __builtin_fabsf(x);
    else return __builtin_fabs(x);
}
template <class T>
GALE_NOISE_INLINE T copySign(T mag, T sgn) {
    if constexpr (sizeof(T) == 4) return __builtin_copysignf(mag, sgn);
    else return __builtin_copysign(mag, sgn);
}
template <class T>
GALE_NOISE_INLINE T sqrtOf(T x) {
    if constexpr (sizeof(T) == 4) return __builtin_sqrtf(x);
    else return __builtin_sqrt(x);
}

// The lattice cell floor(x) and the offset x - floor(x) in [0, 1). NaN and infinities give a
// NaN offset, so they propagate to the result. Written so that no select has a constant arm:
// GCC would otherwise fold through it and split the loop body into branches.
template <class T>
GALE_NOISE_INLINE void split(T x, int32_t& cell, T& frac) {
    const T lim = T(kCoordLimit);
    const T c = absOf(x) < lim ? x : copySign(lim, x);   // NaN, ±inf -> ±lim
    const T t = static_cast<T>(static_cast<int32_t>(c)); // truncated toward zero
    const T fl = c < t ? t - T(1) : t;                   // floor
    cell = static_cast<int32_t>(fl);
    frac = (c - fl) + (x - x); // x - x: 0, or NaN for NaN and infinite x
}

// Perlin's quintic fade 6t^5 - 15t^4 + 10t^3 (C2: zero first and second derivative at 0, 1).
template <class T>
GALE_NOISE_INLINE T fade(T t) {
    return t * t * t * (t * (t * T(6) - T(15)) + T(10));
}
// Its derivative 30 t^2 (t - 1)^2.
template <class T>
GALE_NOISE_INLINE T fadeDeriv(T t) {
    const T s = t * (t - T(1));
    return T(30) * s * s;
}

template <class T>
GALE_NOISE_INLINE T lerp(T a, T b, T u) {
    return a + u * (b - a);
}

// Lattice hash: the xor of primed coordinates and a seed, multiplied and folded so that the
// low bits depend on the high ones. Cheap (one multiply) for the gradient corners.
GALE_NOISE_INLINE uint32_t mixHash(uint32_t v) {
    v *= kHashMul;
    return v ^ (v >> 15);
}

// A stronger finaliser (two multiplies) for cell values, where the bits are the output.
GALE_NOISE_INLINE uint32_t mixStrong(uint32_t v) {
    v ^= v >> 16;
    v *= 0x7FEB352Du;
    v ^= v >> 15;
    v *= 0x846CA68Bu;
    v ^= v >> 16;
    return v;
}

// A hash as a value in [0, 1] (24 bits for float, 31 bits for double; both reach 0 and 1).
template <class T>
GALE_NOISE_INLINE T unitFromHash(uint32_t h) {
    if constexpr (sizeof(T) == 4) return static_cast<T>(static_cast<int32_t>(h >> 8)) * T(1.0 / 16777215.0);
    else return static_cast<T>(static_cast<int32_t>(h >> 1)) * T(1.0 / 2147483647.0);
}

// The cell value of integer cell (x, y, z) for a seed: cellnoise.
template <class T>
GALE_NOISE_INLINE T cellValue(int32_t x, int32_t y, int32_t z, uint32_t seed) {
    const uint32_t h = (static_cast<uint32_t>(x) * kPrimeX) ^ (static_cast<uint32_t>(y) * kPrimeY) ^
                       (static_cast<uint32_t>(z) * kPrimeZ) ^ seed;
    return unitFromHash<T>(mixStrong(h));
}

// Bit patterns of T (uint32_t for float, uint64_t for double), for building values from
// masks without selects whose arms are constants.
template <class T>
struct BitsOf {
    using U = uint32_t;
};
template <>
struct BitsOf<double> {
    using U = uint64_t;
};
template <class T>
GALE_NOISE_INLINE typename BitsOf<T>::U bitsOf(T x) {
    typename BitsOf<T>::U b;
    __builtin_memcpy(&b, &x, sizeof b);
    return b;
}
template <class T>
GALE_NOISE_INLINE T fromBits(typename BitsOf<T>::U b) {
    T x;
    __builtin_memcpy(&x, &b, sizeof x);
    return x;
}
// All ones when c, else zero.
template <class T>
GALE_NOISE_INLINE typename BitsOf<T>::U maskIf(bool c) {
    using U = typename BitsOf<T>::U;
    return U(0) - static_cast<U>(c);
}
// a where the mask is set, else b: bit operations, so GCC cannot thread several selects on one
// condition into a branch (whose stores it would then not if-convert).
template <class T>
GALE_NOISE_INLINE T pick(typename BitsOf<T>::U mask, T a, T b) {
    return fromBits<T>((bitsOf(a) & mask) | (bitsOf(b) & ~mask));
}
// ±v (bit pattern) with the sign taken from bit `bit` of h.
template <class T>
GALE_NOISE_INLINE typename BitsOf<T>::U signedBits(T v, uint32_t h, int bit) {
    using U = typename BitsOf<T>::U;
    return bitsOf(v) | (static_cast<U>((h >> bit) & 1u) << (8 * sizeof(U) - 1));
}

// 3D gradients: the 12 vertices of an icosahedron, cyclic permutations of (0, ±1, ±phi). They
// form a spherical 5-design, so second and fourth moments are isotropic (unlike the cube-edge
// set of improved Perlin noise). The permutation is floor(3 r / 2^16) with r = bits 16..31 of
// the hash (equal odds), bits 0 and 1 give the signs. Masks of the permutation (all ones where
// it is 0, 1, 2), found by comparing r with 2^16/3 and 2^17/3:
template <class T>
GALE_NOISE_INLINE void perm3Masks(uint32_t h, typename BitsOf<T>::U& m0, typename BitsOf<T>::U& m1,
                                  typename BitsOf<T>::U& m2) {
    const int32_t r = static_cast<int32_t>(h >> 16);
    m0 = maskIf<T>(r < 21846);
    m2 = maskIf<T>(r > 43690);
    m1 = ~(m0 | m2);
}

// g . (dx, dy, dz) = ±a ± phi b with (a, b) = (dy, dz), (dx, dy) or (dz, dx): selects and sign
// flips as bit operations (cheaper than blends at SSE2 and AVX2).
template <class T>
GALE_NOISE_INLINE T dot3(uint32_t h, T dx, T dy, T dz) {
    using U = typename BitsOf<T>::U;
    U m0, m1, m2;
    perm3Masks<T>(h, m0, m1, m2);
    const U bx = bitsOf(dx), by = bitsOf(dy), bz = bitsOf(dz);
    constexpr int top = 8 * sizeof(U) - 1;
    const U sa = static_cast<U>(h & 1u) << top, sb = static_cast<U>((h >> 1) & 1u) << top;
    const U a = ((by & m0) | (bx & m1) | (bz & m2)) ^ sa;
    const U b = ((bz & m0) | (by & m1) | (bx & m2)) ^ sb;
    return fromBits<T>(a) + T(kPhi) * fromBits<T>(b);
}

// The gradient vector dot3 uses (for analytic derivatives), built from the same masks.
template <class T>
GALE_NOISE_INLINE void grad3(uint32_t h, T& gx, T& gy, T& gz) {
    using U = typename BitsOf<T>::U;
    U m0, m1, m2;
    perm3Masks<T>(h, m0, m1, m2);
    const U v1 = signedBits(T(1), h, 0), v2 = signedBits(T(kPhi), h, 1);
    gx = fromBits<T>((m1 & v1) | (m2 & v2));
    gy = fromBits<T>((m0 & v1) | (m1 & v2));
    gz = fromBits<T>((m0 & v2) | (m2 & v1));
}

// 4D gradients: the 24 vertices of the 24-cell, permutations of (±1, ±1, 0, 0) (a 5-design in
// 4D). Bits 16..31 pick the pair of non-zero axes, bits 0 and 1 the signs.
GALE_NOISE_INLINE uint32_t pair4(uint32_t h) {
    const uint32_t r = h >> 16;
    return ((r << 2) + (r << 1)) >> 16; // floor(6 r / 2^16): 0..5
}

// Pairs: 0 (x,y) 1 (x,z) 2 (x,w) 3 (y,z) 4 (y,w) 5 (z,w).
template <class T>
GALE_NOISE_INLINE T dot4(uint32_t h, T dx, T dy, T dz, T dw) {
    const uint32_t p = pair4(h);
    T a = p < 3 ? dx : (p < 5 ? dy : dz);
    T b = p == 0 ? dy : ((p == 1 || p == 3) ? dz : dw);
    a = static_cast<int32_t>(h << 31) < 0 ? -a : a;
    b = static_cast<int32_t>(h << 30) < 0 ? -b : b;
    return a + b;
}

template <class T>
GALE_NOISE_INLINE void grad4(uint32_t h, T& gx, T& gy, T& gz, T& gw) {
    using U = typename BitsOf<T>::U;
    const uint32_t p = pair4(h);
    const U va = signedBits(T(1), h, 0), vb = signedBits(T(1), h, 1);
    const U m0 = maskIf<T>(p == 0), m1 = maskIf<T>(p == 1), m2 = maskIf<T>(p == 2);
    const U m3 = maskIf<T>(p == 3), m4 = maskIf<T>(p == 4), m5 = maskIf<T>(p == 5);
    gx = fromBits<T>((m0 | m1 | m2) & va);
    gy = fromBits<T>((m0 & vb) | ((m3 | m4) & va));
    gz = fromBits<T>(((m1 | m3) & vb) | (m5 & va));
    gw = fromBits<T>((m2 | m4 | m5) & vb);
}

// sin and cos of x: Cody-Waite reduction by pi/2, then Taylor polynomials on [-pi/4, pi/4]
// (error ~1e-11 in double; float rounds). |x| beyond ~1e9 gives a finite, meaningless angle.
template <class T>
GALE_NOISE_INLINE void sinCosOf(T x, T& s, T& c) {
    int32_t k;
    T unused;
    split(x * T(0.63661977236758134308) + T(0.5), k, unused); // nearest multiple of pi/2
    const T kf = static_cast<T>(k);
    const T r = (x - kf * T(1.5703125)) - kf * T(4.8382679489661923e-4);
    const T r2 = r * r;
    const T sp = r + r * r2 * (T(-1.0 / 6) + r2 * (T(1.0 / 120) + r2 * (T(-1.0 / 5040) +
                                     r2 * (T(1.0 / 362880) + r2 * T(-1.0 / 39916800)))));
    const T cp = T(1) + r2 * (T(-0.5) + r2 * (T(1.0 / 24) + r2 * (T(-1.0 / 720) + r2 * (T(1.0 / 40320) +
                                     r2 * (T(-1.0 / 3628800) + r2 * T(1.0 / 479001600))))));
    const uint32_t q = static_cast<uint32_t>(k) & 3u;
    s = q == 0 ? sp : (q == 1 ? cp : (q == 2 ? -sp : -cp));
    c = q == 0 ? cp : (q == 1 ? -sp : (q == 2 ? -cp : sp));
}

// SeExpr2's octave count: int(clamp(octaves, 1, 8)), NaN giving 1.
template <class T>
inline int octaveCount(T octaves) {
    const T m = T(kMaxOctaves) < octaves ? T(kMaxOctaves) : octaves; // NaN stays NaN
    const T c = m > T(1) ? m : T(1);                                  // NaN -> 1
    return static_cast<int>(c);
}

} // namespace gale::runtime::noise::detail
