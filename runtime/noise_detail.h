// Inline building blocks of the noise core shared by noise*.cpp: lattice split, fade curves,
// integer hashes and gradient selection. Everything here is branch-free scalar code meant to be
// inlined into lane loops, using only operations that round identically in vector and scalar code.
#pragma once

#include <cstdint>

#define GALE_NOISE_INLINE inline __attribute__((always_inline))

namespace gale::runtime::noise::detail {

// Multipliers that spread integer lattice coordinates over 32 bits (large odd constants).
constexpr uint32_t kPrimeX = 0x9E3779B1u;
constexpr uint32_t kPrimeY = 0x85EBCA77u;
constexpr uint32_t kPrimeZ = 0xC2B2AE3Du;
constexpr uint32_t kPrimeW = 0x27D4EB2Fu;
constexpr uint32_t kHashMul = 0x5BD1E995u;

constexpr double kPhi = 1.61803398874989484820; // golden ratio: icosahedron vertices (0, ±1, ±phi)

// Amplitude scales: raw gradient noise times these has rms ~0.19 (SeExpr2's snoise).
constexpr double kScale1 = 0.5200;
constexpr double kScale2 = 0.4150;
constexpr double kScale3 = 0.2235;
constexpr double kScale4 = 0.2400;

// Coordinates are clamped to ±2^30 before taking the lattice cell (keeps the cell in int32).
constexpr double kCoordLimit = 1073741824.0;

// The lattice cell floor(x) and the offset x - floor(x) in [0, 1). NaN gives cell 0 and a NaN
// offset, so NaN propagates to the result.
template <class T>
GALE_NOISE_INLINE void split(T x, int32_t& cell, T& frac) {
    const T lim = T(kCoordLimit);
    const T c = x < -lim ? -lim : (x > lim ? lim : x);
    const T safe = c == c ? c : T(0);
    int32_t i = static_cast<int32_t>(safe);
    i -= safe < static_cast<T>(i) ? 1 : 0;
    cell = i;
    frac = c - static_cast<T>(i);
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

// 3D gradients: the 12 vertices of an icosahedron, cyclic permutations of (0, ±1, ±phi). They
// form a spherical 5-design, so second and fourth moments are isotropic (unlike the cube-edge
// set of improved Perlin noise). Bits 16..31 pick the permutation, bits 0 and 1 the signs.
GALE_NOISE_INLINE uint32_t perm3(uint32_t h) {
    const uint32_t r = h >> 16;
    return (r + (r << 1)) >> 16; // floor(3 r / 2^16): 0, 1 or 2
}

template <class T>
GALE_NOISE_INLINE T dot3(uint32_t h, T dx, T dy, T dz) {
    const uint32_t sel = perm3(h);
    T a = sel == 0 ? dy : (sel == 1 ? dx : dz);
    T b = sel == 0 ? dz : (sel == 1 ? dy : dx);
    a = (h & 1u) ? -a : a;
    b = (h & 2u) ? -b : b;
    return a + T(kPhi) * b;
}

// The gradient vector dot3 uses (for analytic derivatives).
template <class T>
GALE_NOISE_INLINE void grad3(uint32_t h, T& gx, T& gy, T& gz) {
    const uint32_t sel = perm3(h);
    const T s1 = (h & 1u) ? T(-1) : T(1);
    const T s2 = (h & 2u) ? T(-kPhi) : T(kPhi);
    gx = sel == 1 ? s1 : (sel == 2 ? s2 : T(0));
    gy = sel == 0 ? s1 : (sel == 1 ? s2 : T(0));
    gz = sel == 0 ? s2 : (sel == 2 ? s1 : T(0));
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
    a = (h & 1u) ? -a : a;
    b = (h & 2u) ? -b : b;
    return a + b;
}

template <class T>
GALE_NOISE_INLINE void grad4(uint32_t h, T& gx, T& gy, T& gz, T& gw) {
    const uint32_t p = pair4(h);
    const T sa = (h & 1u) ? T(-1) : T(1);
    const T sb = (h & 2u) ? T(-1) : T(1);
    gx = p < 3 ? sa : T(0);
    gy = p == 0 ? sb : ((p == 3 || p == 4) ? sa : T(0));
    gz = (p == 1 || p == 3) ? sb : (p == 5 ? sa : T(0));
    gw = (p == 2 || p == 4 || p == 5) ? sb : T(0);
}

} // namespace gale::runtime::noise::detail
