// Scalar math and remapping built-ins (SeExpr2's formulas, evaluation order included), applied
// per component over FP[n]. The vector, selection and colour families are registered from here
// too.
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"
#include "runtime/fastmath.h"

#include <cmath>

namespace gale::runtime {
namespace {

// SeExpr2 computes these constants in double; the float kernels round them once.
constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180 / kPi;
constexpr double kDegToRad = kPi / 180;

// ---- C math ----------------------------------------------------------------------------------
template <class T> struct Abs { static T apply(T x) { return std::fabs(x); } };
template <class T> struct Acos { static T apply(T x) { return std::acos(x); } };
template <class T> struct Asin { static T apply(T x) { return std::asin(x); } };
template <class T> struct Atan { static T apply(T x) { return std::atan(x); } };
template <class T> struct Atan2 { static T apply(T y, T x) { return std::atan2(y, x); } };
template <class T> struct Ceil { static T apply(T x) { return std::ceil(x); } };
template <class T> struct Cos { static T apply(T x) { return std::cos(x); } };
template <class T> struct Cosh { static T apply(T x) { return std::cosh(x); } };
template <class T> struct Exp { static T apply(T x) { return std::exp(x); } };
template <class T> struct Floor { static T apply(T x) { return std::floor(x); } };
template <class T> struct Fmod { static T apply(T x, T y) { return std::fmod(x, y); } };
template <class T> struct Log { static T apply(T x) { return std::log(x); } };
template <class T> struct Log10 { static T apply(T x) { return std::log10(x); } };
template <class T> struct Pow { static T apply(T x, T y) { return std::pow(x, y); } };
template <class T> struct Sin { static T apply(T x) { return std::sin(x); } };
template <class T> struct Sinh { static T apply(T x) { return std::sinh(x); } };
template <class T> struct Sqrt { static T apply(T x) { return std::sqrt(x); } };
template <class T> struct Tan { static T apply(T x) { return std::tan(x); } };
template <class T> struct Tanh { static T apply(T x) { return std::tanh(x); } };
template <class T> struct Cbrt { static T apply(T x) { return std::cbrt(x); } };
template <class T> struct Asinh { static T apply(T x) { return std::asinh(x); } };
template <class T> struct Acosh { static T apply(T x) { return std::acosh(x); } };
template <class T> struct Atanh { static T apply(T x) { return std::atanh(x); } };
template <class T> struct Trunc { static T apply(T x) { return std::trunc(x); } };

// Float lanes of sin, cos, exp and log go through the vectorised fastmath arrays (uniform
// operands too, so a value gives the same bits whichever way it is computed); double lanes use
// libm, as SeExpr2 does.
template <template <class> class F, void (*Array)(const float*, float*, int)>
struct FastMap {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        if constexpr (std::is_same_v<T, float>) {
            const Operand<float>& a = f.args[0];
            for (int k = 0; k < f.outWidth; ++k) {
                float* __restrict o = f.outComp(k);
                if (a.uniform()) {
                    float v;
                    Array(a.comp(k), &v, 1);
                    for (int i = 0; i < f.n; ++i) o[i] = v;
                } else {
                    Array(a.comp(k), o, f.n);
                }
            }
        } else {
            mapKernel1<F, T>(f);
        }
    }
};

// ---- Angles ----------------------------------------------------------------------------------
template <class T> struct Deg { static T apply(T a) { return a * T(kRadToDeg); } };
template <class T> struct Rad { static T apply(T a) { return a * T(kDegToRad); } };
template <class T> struct Cosd { static T apply(T a) { return std::cos(a * T(kDegToRad)); } };
template <class T> struct Sind { static T apply(T a) { return std::sin(a * T(kDegToRad)); } };
template <class T> struct Tand { static T apply(T a) { return std::tan(a * T(kDegToRad)); } };
template <class T> struct Acosd { static T apply(T x) { return std::acos(x) * T(kRadToDeg); } };
template <class T> struct Asind { static T apply(T x) { return std::asin(x) * T(kRadToDeg); } };
template <class T> struct Atand { static T apply(T x) { return std::atan(x) * T(kRadToDeg); } };
template <class T> struct Atan2d { static T apply(T y, T x) { return std::atan2(y, x) * T(kRadToDeg); } };

// ---- Clamping and rounding -------------------------------------------------------------------
// SeExpr2's comparisons, so NaN behaves the same (max(NaN, 1) = 1, max(1, NaN) = NaN).
template <class T> struct Clamp {
    static T apply(T x, T lo, T hi) { return x < lo ? lo : (x > hi ? hi : x); }
};
// Half away from zero. SeExpr2's floor(x + 0.5) misrounds 0.49999999999999994 and odd
// integers above 2^52; std::round does not (documented fix).
template <class T> struct Round { static T apply(T x) { return std::round(x); } };
template <class T> struct Max { static T apply(T x, T y) { return x > y ? x : y; } };
template <class T> struct Min { static T apply(T x, T y) { return x < y ? x : y; } };
// -1, 0 or 1 (zero keeps its sign, NaN passes through).
template <class T> struct Sign { static T apply(T x) { return x > 0 ? T(1) : (x < 0 ? T(-1) : x); } };
// SeExpr2's hypot is sqrt(x*x + y*y), not C's overflow-safe hypot.
template <class T> struct Hypot { static T apply(T x, T y) { return std::sqrt(x * x + y * y); } };

// ---- Remapping -------------------------------------------------------------------------------
template <class T> T boxstep(T x, T a) { return x < a ? T(0) : T(1); }

template <class T> T linearstep(T x, T a, T b) {
    if (a < b) return x < a ? T(0) : (x > b ? T(1) : (x - a) / (b - a));
    if (a > b) return 1 - (x < b ? T(0) : (x > a ? T(1) : (x - b) / (a - b)));
    return boxstep(x, a);
}

template <class T> T smoothstep(T x, T a, T b) {
    if (a < b) {
        if (x < a) return 0;
        if (x >= b) return 1;
        x = (x - a) / (b - a);
    } else if (a > b) {
        if (x <= b) return 1;
        if (x > a) return 0;
        x = 1 - (x - b) / (a - b);
    } else {
        return boxstep(x, a);
    }
    return x * x * (3 - 2 * x);
}

template <class T> T gaussstep(T x, T a, T b) {
    if (a < b) {
        if (x < a) return 0;
        if (x >= b) return 1;
        x = 1 - (x - a) / (b - a);
    } else if (a > b) {
        if (x <= b) return 1;
        if (x > a) return 0;
        x = (x - b) / (a - b);
    } else {
        return boxstep(x, a);
    }
    return std::pow(T(2), -8 * x * x);
}

// x^(log b / log 0.5), computed as SeExpr2 does: log(b) times the constant 1/log(0.5)
// (-0x1.71547652b82fep+0 is that quotient in double).
constexpr double kInvLogHalf = -0x1.71547652b82fep+0;
template <class T> T bias(T x, T b) { return std::pow(x, std::log(b) * T(kInvLogHalf)); }

template <class T> struct Invert { static T apply(T x) { return 1 - x; } };
template <class T> struct Compress { static T apply(T x, T lo, T hi) { return (hi - lo) * x + lo; } };
template <class T> struct Expand {
    static T apply(T x, T lo, T hi) {
        if (lo == hi) return x < lo ? T(0) : T(1);
        return (x - lo) / (hi - lo);
    }
};
template <class T> struct Fit {
    static T apply(T x, T a1, T b1, T a2, T b2) { return (x * (b2 - a2) - a1 * b2 + b1 * a2) / (b1 - a1); }
};
template <class T> struct Gamma { static T apply(T x, T g) { return std::pow(x, 1 / g); } };
template <class T> struct Bias { static T apply(T x, T b) { return bias(x, b); } };
// SeExpr2's contrast: note that it biases (1 - c) by 2x, in that argument order. So x outside
// [0, 1] takes the log of a negative number and gives NaN (pow(1, NaN) = 1 when c = 0); kept
// on purpose, for SeExpr2's numbers.
template <class T> struct Contrast {
    static T apply(T x, T c) {
        if (x < T(0.5)) return T(0.5) * bias(1 - c, 2 * x);
        return 1 - T(0.5) * bias(1 - c, 2 - 2 * x);
    }
};
template <class T> struct Boxstep { static T apply(T x, T a) { return boxstep(x, a); } };
template <class T> struct Linearstep { static T apply(T x, T a, T b) { return linearstep(x, a, b); } };
template <class T> struct Smoothstep { static T apply(T x, T a, T b) { return smoothstep(x, a, b); } };
template <class T> struct Gaussstep { static T apply(T x, T a, T b) { return gaussstep(x, a, b); } };

// 1 within +/-range of source, falling to 0 over `falloff`; interp 0 linear, 1 smooth, any other
// value (gaussian = 2, box = 3) gaussian, exactly as SeExpr2.
template <class T> struct Remap {
    static T apply(T x, T source, T range, T falloff, T interp) {
        range = std::fabs(range);
        falloff = std::fabs(falloff);
        if (falloff == 0) return std::fabs(x - source) < range ? T(1) : T(0);
        T a, b;
        if (x > source) {
            a = source + range;
            b = a + falloff;
        } else {
            a = source - range;
            b = a - falloff;
        }
        switch (detail::truncToInt(double(interp))) {
        case 0: return linearstep(x, b, a);
        case 1: return smoothstep(x, b, a);
        default: return gaussstep(x, b, a);
        }
    }
};
template <class T> struct Mix { static T apply(T a, T b, T alpha) { return a * (1 - alpha) + b * alpha; } };

} // namespace

double detail::remapValue(double x, double source, double range, double falloff, double interp) {
    return Remap<double>::apply(x, source, range, falloff, interp);
}

void addMathBuiltins(FunctionTable& t) {
    // C math
    t.add(mapBuiltin1<Abs>("abs", "FP[n] abs(FP[n] x)", "absolute value"));
    t.add(mapBuiltin1<Acos>("acos", "FP[n] acos(FP[n] x)", "arc cosine, in radians"));
    t.add(mapBuiltin1<Asin>("asin", "FP[n] asin(FP[n] x)", "arc sine, in radians"));
    t.add(mapBuiltin1<Atan>("atan", "FP[n] atan(FP[n] x)", "arc tangent, in radians"));
    t.add(mapBuiltin2<Atan2>("atan2", "FP[n] atan2(FP[n] y, FP[n] x)", "arc tangent of y/x in [-PI, PI]"));
    t.add(mapBuiltin1<Ceil>("ceil", "FP[n] ceil(FP[n] x)", "smallest integer not below x"));
    t.add(kernelBuiltin<FastMap<Cos, &fastmath::cosArray>>("cos", "FP[n] cos(FP[n] angle)", "cosine (radians)"));
    t.add(mapBuiltin1<Cosh>("cosh", "FP[n] cosh(FP[n] x)", "hyperbolic cosine"));
    t.add(kernelBuiltin<FastMap<Exp, &fastmath::expArray>>("exp", "FP[n] exp(FP[n] x)", "E raised to the power x"));
    t.add(mapBuiltin1<Floor>("floor", "FP[n] floor(FP[n] x)", "largest integer not above x"));
    t.add(mapBuiltin2<Fmod>("fmod", "FP[n] fmod(FP[n] x, FP[n] y)", "C's remainder of x/y (sign of x; % is floored)"));
    t.add(kernelBuiltin<FastMap<Log, &fastmath::logArray>>("log", "FP[n] log(FP[n] x)", "natural logarithm"));
    t.add(mapBuiltin1<Log10>("log10", "FP[n] log10(FP[n] x)", "base-10 logarithm"));
    t.add(mapBuiltin2<Pow>("pow", "FP[n] pow(FP[n] x, FP[n] y)", "x to the power y (also x^y)"));
    t.add(kernelBuiltin<FastMap<Sin, &fastmath::sinArray>>("sin", "FP[n] sin(FP[n] angle)", "sine (radians)"));
    t.add(mapBuiltin1<Sinh>("sinh", "FP[n] sinh(FP[n] x)", "hyperbolic sine"));
    t.add(mapBuiltin1<Sqrt>("sqrt", "FP[n] sqrt(FP[n] x)", "square root"));
    t.add(mapBuiltin1<Tan>("tan", "FP[n] tan(FP[n] angle)", "tangent (radians)"));
    t.add(mapBuiltin1<Tanh>("tanh", "FP[n] tanh(FP[n] x)", "hyperbolic tangent"));
    t.add(mapBuiltin1<Cbrt>("cbrt", "FP[n] cbrt(FP[n] x)", "cube root"));
    t.add(mapBuiltin1<Asinh>("asinh", "FP[n] asinh(FP[n] x)", "inverse hyperbolic sine"));
    t.add(mapBuiltin1<Acosh>("acosh", "FP[n] acosh(FP[n] x)", "inverse hyperbolic cosine"));
    t.add(mapBuiltin1<Atanh>("atanh", "FP[n] atanh(FP[n] x)", "inverse hyperbolic tangent"));
    t.add(mapBuiltin1<Trunc>("trunc", "FP[n] trunc(FP[n] x)", "nearest integer towards zero"));

    // angles
    t.add(mapBuiltin1<Deg>("deg", "FP[n] deg(FP[n] angle)", "radians to degrees"));
    t.add(mapBuiltin1<Rad>("rad", "FP[n] rad(FP[n] angle)", "degrees to radians"));
    t.add(mapBuiltin1<Cosd>("cosd", "FP[n] cosd(FP[n] angle)", "cosine of an angle in degrees"));
    t.add(mapBuiltin1<Sind>("sind", "FP[n] sind(FP[n] angle)", "sine of an angle in degrees"));
    t.add(mapBuiltin1<Tand>("tand", "FP[n] tand(FP[n] angle)", "tangent of an angle in degrees"));
    t.add(mapBuiltin1<Acosd>("acosd", "FP[n] acosd(FP[n] x)", "arc cosine, in degrees"));
    t.add(mapBuiltin1<Asind>("asind", "FP[n] asind(FP[n] x)", "arc sine, in degrees"));
    t.add(mapBuiltin1<Atand>("atand", "FP[n] atand(FP[n] x)", "arc tangent, in degrees"));
    t.add(mapBuiltin2<Atan2d>("atan2d", "FP[n] atan2d(FP[n] y, FP[n] x)", "arc tangent of y/x in degrees, in [-180, 180]"));

    // clamping, rounding
    t.add(mapBuiltin3<Clamp>("clamp", "FP[n] clamp(FP[n] x, FP[n] lo, FP[n] hi)", "x constrained to [lo, hi]"));
    t.add(mapBuiltin1<Round>("round", "FP[n] round(FP[n] x)", "nearest integer, halves away from zero"));
    t.add(mapBuiltin2<Max>("max", "FP[n] max(FP[n] a, FP[n] b)", "the greater of a and b"));
    t.add(mapBuiltin2<Min>("min", "FP[n] min(FP[n] a, FP[n] b)", "the lesser of a and b"));
    t.add(mapBuiltin2<Hypot>("hypot", "FP[n] hypot(FP[n] x, FP[n] y)", "length of the 2D vector [x, y]"));
    t.add(mapBuiltin1<Sign>("sign", "FP[n] sign(FP[n] x)", "-1, 0 or 1 by the sign of x"));

    // remapping
    t.add(mapBuiltin1<Invert>("invert", "FP[n] invert(FP[n] x)", "1 - x"));
    t.add(mapBuiltin3<Compress>("compress", "FP[n] compress(FP[n] x, FP[n] lo, FP[n] hi)",
                                "remaps x in [0, 1] to [lo, hi]: (hi - lo) x + lo"));
    t.add(mapBuiltin3<Expand>("expand", "FP[n] expand(FP[n] x, FP[n] lo, FP[n] hi)",
                              "remaps x in [lo, hi] to [0, 1] (lo == hi: a step at lo)"));
    t.add(mapBuiltin5<Fit>("fit", "FP[n] fit(FP[n] x, FP[n] a1, FP[n] b1, FP[n] a2, FP[n] b2)",
                           "linearly remaps x in [a1, b1] to [a2, b2] (no clamping)"));
    t.add(mapBuiltin2<Gamma>("gamma", "FP[n] gamma(FP[n] x, FP[n] g)", "gamma correction: x^(1/g)"));
    t.add(mapBuiltin2<Bias>("bias", "FP[n] bias(FP[n] x, FP[n] b)", "x^(log b / log 0.5): b < 0.5 pulls down, b > 0.5 up"));
    t.add(mapBuiltin2<Contrast>(
        "contrast", "FP[n] contrast(FP[n] x, FP[n] c)",
        "contrast around 0.5: c < 0.5 decreases it, c > 0.5 increases it; x outside [0, 1] "
        "gives NaN (0.5 if c = 0), as in SeExpr2"));
    t.add(mapBuiltin2<Boxstep>("boxstep", "FP[n] boxstep(FP[n] x, FP[n] a)", "0 if x < a, else 1"));
    t.add(mapBuiltin3<Linearstep>("linearstep", "FP[n] linearstep(FP[n] x, FP[n] a, FP[n] b)",
                                  "0 below a, 1 above b, linear between (a > b reverses)"));
    t.add(mapBuiltin3<Smoothstep>("smoothstep", "FP[n] smoothstep(FP[n] x, FP[n] a, FP[n] b)",
                                  "0 below a, 1 above b, 3t^2 - 2t^3 between (a > b reverses)"));
    t.add(mapBuiltin3<Gaussstep>("gaussstep", "FP[n] gaussstep(FP[n] x, FP[n] a, FP[n] b)",
                                 "0 below a, 1 above b, 2^(-8(1-t)^2) between (a > b reverses)"));
    t.add(mapBuiltin5<Remap>("remap", "FP[n] remap(FP[n] x, FP[n] source, FP[n] range, FP[n] falloff, FP[n] interp)",
                             "1 within range of source, falling to 0 over falloff; interp 0 linear, 1 smooth, 2 gaussian"));
    t.add(mapBuiltin3<Mix>("mix", "FP[n] mix(FP[n] a, FP[n] b, FP[n] alpha)", "blend a (1 - alpha) + b alpha"));

    detail::addVectorBuiltins(t);
    detail::addSelectionBuiltins(t);
    detail::addColorBuiltins(t);
}

} // namespace gale::runtime
