// Float sin, cos, exp and log over arrays of lanes, written branch-free so the compiler
// vectorises them (SSE2 at the x86-64 baseline, wider with -march=native). Cephes-style
// range reduction and minimax polynomials; accuracy within 2 ulp of the correctly rounded
// result (fastmath_test.cpp measures it). Inputs outside a polynomial's range fall back to libm.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace gale::runtime::fastmath {

namespace detail {

inline float bitsToFloat(int32_t i) {
    float f;
    std::memcpy(&f, &i, sizeof f);
    return f;
}
inline int32_t floatToBits(float f) {
    int32_t i;
    std::memcpy(&i, &f, sizeof i);
    return i;
}

// sin(x) or cos(x) for |x| < kTrigLimit: reduce by multiples of pi/4 (three-part Cody-Waite
// constants), then the sine or cosine polynomial on [-pi/4, pi/4] by octant.
constexpr float kTrigLimit = 8192.0f;

template <bool Cosine>
inline float sinCosLane(float x) {
    const float fopi = 1.27323954473516f; // 4/pi
    const float dp1 = 0.78515625f, dp2 = 2.4187564849853515625e-4f, dp3 = 3.77489497744594108e-8f;
    // Out-of-range and non-finite lanes reduce 0 (their result is replaced by the caller).
    const float ax = std::fabs(x) < kTrigLimit ? std::fabs(x) : 0.0f;
    int32_t j = static_cast<int32_t>(ax * fopi);
    j += j & 1; // to an even octant
    const float y = static_cast<float>(j);
    const float r = ((ax - y * dp1) - y * dp2) - y * dp3;
    const float z = r * r;
    const float s = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * r + r;
    const float c = ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z -
                    0.5f * z + 1.0f;
    int32_t q = j & 7; // 0, 2, 4 or 6
    if (Cosine) q = (q + 2) & 7;
    // Octants 2 and 6 use the other polynomial; 4 and 6 flip the sign (for cos, shifted).
    const float v = (q & 2) ? c : s;
    const float signed_ = (q & 4) ? -v : v;
    if (Cosine) return signed_;
    // sin is odd: take x's sign bit (so sin(-0) = -0).
    return bitsToFloat(floatToBits(signed_) ^ (floatToBits(x) & static_cast<int32_t>(0x80000000u)));
}

inline float expLane(float x) {
    const float log2e = 1.44269504088896341f;
    const float c1 = 0.693359375f, c2 = -2.12194440e-4f;
    // Clamp into the range the reconstruction handles; results outside are fixed up below.
    // NaN clamps too (to the low end), so the int conversion below is always defined.
    const float xc = x > 88.7228f ? 88.7228f : (x >= -103.9721f ? x : -103.9721f);
    const float t = xc * log2e + (xc >= 0.0f ? 0.5f : -0.5f);
    const int32_t n = static_cast<int32_t>(t); // round to nearest
    const float fn = static_cast<float>(n);
    float r = xc - fn * c1;
    r = r - fn * c2;
    const float z = r * r;
    float p = ((((1.9875691500e-4f * r + 1.3981999507e-3f) * r + 8.3334519073e-3f) * r + 4.1665795894e-2f) * r +
               1.6666665459e-1f) * r + 5.0000001201e-1f;
    p = p * z + r + 1.0f;
    // 2^n in two factors so that subnormal results come out right.
    const int32_t n1 = n >> 1, n2 = n - n1;
    const float s1 = bitsToFloat((n1 + 127) << 23), s2 = bitsToFloat((n2 + 127) << 23);
    float e = p * s1 * s2;
    e = x > 88.7228f ? HUGE_VALF : e;
    e = x < -103.9721f ? 0.0f : e;
    return x != x ? x : e;
}

inline float logLane(float x) {
    const float sqrthf = 0.707106781186547524f;
    // Normalise subnormals.
    const bool sub = x < 1.17549435e-38f;
    const float xs = sub ? x * 8388608.0f : x; // 2^23
    const int32_t bits = floatToBits(xs);
    int32_t e = ((bits >> 23) & 0xff) - 126;
    float m = bitsToFloat((bits & 0x807fffff) | 0x3f000000); // mantissa in [0.5, 1)
    e -= sub ? 23 : 0;
    const bool small = m < sqrthf;
    e -= small ? 1 : 0;
    m = small ? m + m - 1.0f : m - 1.0f;
    const float z = m * m;
    float y = ((((((((7.0376836292e-2f * m - 1.1514610310e-1f) * m + 1.1676998740e-1f) * m - 1.2420140846e-1f) * m +
                   1.4249322787e-1f) * m - 1.6668057665e-1f) * m + 2.0000714765e-1f) * m - 2.4999993993e-1f) * m +
               3.3333331174e-1f) * m * z;
    const float fe = static_cast<float>(e);
    y += -2.12194440e-4f * fe;
    y += -0.5f * z;
    float r = m + y;
    r += 0.693359375f * fe;
    // Special values: log(0) = -inf, log(<0) = nan, log(inf) = inf, log(nan) = nan.
    r = x == 0.0f ? -HUGE_VALF : r;
    r = x < 0.0f ? std::numeric_limits<float>::quiet_NaN() : r;
    r = x == HUGE_VALF ? HUGE_VALF : r;
    return x != x ? x : r;
}

} // namespace detail

// out[i] = sin(in[i]) for i < n. Lanes with |x| >= 8192 or non-finite use libm.
inline void sinArray(const float* __restrict in, float* __restrict out, int n) {
    int outside = 0;
    for (int i = 0; i < n; ++i) {
        out[i] = detail::sinCosLane<false>(in[i]);
        outside |= !(std::fabs(in[i]) < detail::kTrigLimit);
    }
    if (outside)
        for (int i = 0; i < n; ++i)
            if (!(std::fabs(in[i]) < detail::kTrigLimit)) out[i] = std::sin(in[i]);
}

inline void cosArray(const float* __restrict in, float* __restrict out, int n) {
    int outside = 0;
    for (int i = 0; i < n; ++i) {
        out[i] = detail::sinCosLane<true>(in[i]);
        outside |= !(std::fabs(in[i]) < detail::kTrigLimit);
    }
    if (outside)
        for (int i = 0; i < n; ++i)
            if (!(std::fabs(in[i]) < detail::kTrigLimit)) out[i] = std::cos(in[i]);
}

inline void expArray(const float* __restrict in, float* __restrict out, int n) {
    for (int i = 0; i < n; ++i) out[i] = detail::expLane(in[i]);
}

inline void logArray(const float* __restrict in, float* __restrict out, int n) {
    for (int i = 0; i < n; ++i) out[i] = detail::logLane(in[i]);
}

} // namespace gale::runtime::fastmath
