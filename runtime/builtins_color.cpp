// Colour built-ins: rgbtohsl, hsltorgb, hsi, midhsi, saturate, with SeExpr2's formulas (HSL after
// Foley-van Dam, extended to values outside [0, 1]) and evaluation order. Computed in double for
// both kernels. swatch, SeExpr2's choose() for colours, is registered with choose.
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"

#include <cmath>

namespace gale::runtime {
namespace {

struct Color {
    double c[3];
};

// RGB to HSL: lightness is the mean of the smallest and largest component; a spread below 1e-6
// is grey (hue and saturation 0). Outside [0, 1] the saturation is 1 - min (dark side, min < 0)
// or max (light side, max > 1), which keeps the conversion reversible. Hue in [0, 1).
Color rgbToHsl(const Color& rgb) {
    const double r = rgb.c[0], g = rgb.c[1], b = rgb.c[2];
    const double lo = r < g ? (r < b ? r : b) : (g < b ? g : b);
    const double hi = r > g ? (r > b ? r : b) : (g > b ? g : b);
    const double sum = lo + hi;
    const double diff = hi - lo;
    const double l = sum / 2;
    if (diff < 1e-6) return {{0, 0, l}};
    double s;
    if (l <= 0.5)
        s = lo < 0 ? 1 - lo : diff / sum;
    else
        s = hi > 1 ? hi : diff / (2 - sum);
    double h;
    if (r == hi)
        h = (g - b) / diff;
    else if (g == hi)
        h = (b - r) / diff + 2;
    else
        h = (r - g) / diff + 4;
    h *= 1 / 6.;
    h -= std::floor(h);
    return {{h, s, l}};
}

// One channel of HSL to RGB: the channel's hue (wrapped into [0, 1)) picks a point on the
// trapezoid rising from lo to hi over the first sixth, flat to one half, falling by two thirds.
double hslChannel(double lo, double hi, double h) {
    h -= std::floor(h);
    if (h < 1 / 6.) return lo + (hi - lo) * h * 6;
    if (h < 3 / 6.) return hi;
    if (h < 4 / 6.) return lo + (hi - lo) * (4 / 6. - h) * 6;
    return lo;
}

// HSL to RGB, the inverse of rgbToHsl: s <= 0 is grey; s > 1 gives a component above 1
// (l >= 0.5) or below 0 (l < 0.5).
Color hslToRgb(const Color& hsl) {
    const double h = hsl.c[0], s = hsl.c[1], l = hsl.c[2];
    if (s <= 0) return {{l, l, l}};
    double hi;
    if (l < 0.5)
        hi = s > 1 ? 2 * l + s - 1 : l + l * s;
    else
        hi = s > 1 ? s : l + s - l * s;
    const double lo = 2 * l - hi;
    return {
        {hslChannel(lo, hi, h + 1 / 3.), hslChannel(lo, hi, h), hslChannel(lo, hi, h - 1 / 3.)}};
}

// Shifts the hue by h degrees, scales saturation by s and the resulting RGB by i.
Color hsiAdjust(const Color& rgb, double h, double s, double i) {
    Color hsl = rgbToHsl(rgb);
    hsl.c[0] += h * (1.0 / 360);
    hsl.c[1] *= s;
    Color out = hslToRgb(hsl);
    for (double& c : out.c) c *= i;
    return out;
}

template <class T>
Color colorAt(const Operand<T>& o, int i) {
    return {{double(o.at(0, i)), double(o.at(1, i)), double(o.at(2, i))}};
}

template <class T>
void setColor(const KernelFrame<T>& f, int i, const Color& v) {
    for (int k = 0; k < 3; ++k) f.outComp(k)[i] = T(v.c[k]);
}

struct RgbToHslK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        for (int i = 0; i < f.n; ++i) setColor(f, i, rgbToHsl(colorAt(f.args[0], i)));
    }
};

struct HslToRgbK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        for (int i = 0; i < f.n; ++i) setColor(f, i, hslToRgb(colorAt(f.args[0], i)));
    }
};

// hsi(color, h, s, i, map): the map scales the adjustment back towards none (map 0). map = 1,
// the default, leaves h, s, i exactly as given (SeExpr2 skips the map when it is left out).
struct HsiK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        for (int i = 0; i < f.n; ++i) {
            double h = double(a[1].at(0, i)), s = double(a[2].at(0, i)), v = double(a[3].at(0, i));
            const double m = double(a[4].at(0, i));
            if (m != 1) {
                h *= m;
                s = (s - 1) * m + 1;
                v = (v - 1) * m + 1;
            }
            setColor(f, i, hsiAdjust(colorAt(a[0], i), h, s, v));
        }
    }
};

// midhsi(color, h, s, i, map, falloff, interp): map 0.5 is no change; towards 1 the adjustment
// grows to the full (h, s, i), towards 0 to the opposite (-h, 1/s, 1/i). The signed distance
// 2 map - 1 is shaped by remap(|d|, 1, 0, falloff, interp), its magnitude rounded to float for
// the s and i blends, as SeExpr2 does.
struct MidhsiK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        for (int i = 0; i < f.n; ++i) {
            double h = double(a[1].at(0, i)), s = double(a[2].at(0, i)), v = double(a[3].at(0, i));
            double m = double(a[4].at(0, i)) * 2 - 1;
            const double falloff = double(a[5].at(0, i)), interp = double(a[6].at(0, i));
            if (m < 0)
                m = -detail::remapValue(-m, 1, 0, falloff, interp);
            else
                m = detail::remapValue(m, 1, 0, falloff, interp);
            h *= m;
            const double absm = std::fabs(static_cast<float>(m)); // m is in [-1, 1] or NaN
            s = s * absm + 1 - absm;
            v = v * absm + 1 - absm;
            if (m < 0) {
                s = 1 / s;
                v = 1 / v;
            }
            setColor(f, i, hsiAdjust(colorAt(a[0], i), h, s, v));
        }
    }
};

// saturate(color, amt): mixes the rec709 luminance grey and the colour by amt; negative
// components are clamped to 0.
struct SaturateK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        for (int i = 0; i < f.n; ++i) {
            const Color c = colorAt(a[0], i);
            const double amt = double(a[1].at(0, i));
            const double lum = c.c[0] * .2126 + c.c[1] * .7152 + c.c[2] * .0722;
            Color out;
            for (int k = 0; k < 3; ++k) {
                out.c[k] = lum * (1 - amt) + c.c[k] * amt;
                if (out.c[k] < 0) out.c[k] = 0;
            }
            setColor(f, i, out);
        }
    }
};

Builtin colorBuiltin(Builtin b) {
    b.info.firstComponent = true; // SeExpr2 reads the first component of a vector h, s, i, map...
    return b;
}

} // namespace

namespace detail {

void addColorBuiltins(FunctionTable& t) {
    t.add(colorBuiltin(kernelBuiltin<RgbToHslK>("rgbtohsl", "FP[3] rgbtohsl(FP[3] rgb)",
                                                "RGB to [hue, saturation, lightness], hue in [0, "
                                                "1); extended reversibly to rgb outside [0, 1]")));
    t.add(colorBuiltin(kernelBuiltin<HslToRgbK>("hsltorgb", "FP[3] hsltorgb(FP[3] hsl)",
                                                "[hue, saturation, lightness] to RGB, the inverse "
                                                "of rgbtohsl (hue wraps; s <= 0 is grey)")));
    t.add(colorBuiltin(kernelBuiltin<HsiK>(
        "hsi", "FP[3] hsi(FP[3] color, FP[1] h, FP[1] s, FP[1] i, FP[1] map = 1)",
        "shifts the hue by h degrees, scales saturation by s and intensity by i; map 0..1 scales "
        "the change")));
    t.add(colorBuiltin(kernelBuiltin<MidhsiK>("midhsi",
                                              "FP[3] midhsi(FP[3] color, FP[1] h, FP[1] s, FP[1] "
                                              "i, FP[1] map, FP[1] falloff = 1, FP[1] interp = 0)",
                                              "hsi() with the map centred on 0.5: 1 gives (h, s, "
                                              "i), 0 the opposite (-h, 1/s, 1/i), shaped by "
                                              "remap(falloff, interp)")));
    t.add(
        colorBuiltin(kernelBuiltin<SaturateK>("saturate", "FP[3] saturate(FP[3] color, FP[1] amt)",
                                              "scales saturation by amt around the rec709 "
                                              "luminance; negative results are clamped to 0")));
}

} // namespace detail
} // namespace gale::runtime
