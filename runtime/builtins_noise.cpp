// The SeExpr2 noise family (snoise noise vnoise cnoise, 4D forms, fbm, turbulence, cellnoise,
// pnoise, hash, voronoi) and gale's curlnoise, curlnoise4 and flownoise as built-ins: signatures,
// defaults, SeExpr2's output mappings, and float/double kernels over the lane-batched core.
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"
#include "runtime/noise.h"

#include <cmath>
#include <string>
#include <vector>

namespace gale::runtime {
namespace {

using noise::FractalLanes;

// Component k of an operand as n lane values: the operand's own storage when it is varying (or
// there is one lane), else its value broadcast into `tmp`.
template <class T>
const T* lanes(const Operand<T>& o, int k, int n, T* tmp) {
    if (o.laneStride != 0 || n == 1) return o.comp(k);
    const T v = o.comp(k)[0];
    for (int i = 0; i < n; ++i) tmp[i] = v;
    return tmp;
}

// An FP[3] (or broadcast FP[1]) operand as three lane arrays.
template <class T>
struct Point3 {
    T buf[3][kBlockSize];
    const T* p[3];
    Point3(const Operand<T>& o, int n) {
        for (int k = 0; k < 3; ++k) p[k] = lanes(o, k, n, buf[k]);
    }
};

// The octaves, lacunarity and gain operands starting at args[first].
template <class T>
struct Fractal {
    T buf[3][kBlockSize];
    FractalLanes<T> lanes3;
    Fractal(const KernelFrame<T>& f, int first) {
        lanes3.octaves = lanes(f.args[first], 0, f.n, buf[0]);
        lanes3.lacunarity = lanes(f.args[first + 1], 0, f.n, buf[1]);
        lanes3.gain = lanes(f.args[first + 2], 0, f.n, buf[2]);
    }
};

// SeExpr2's colour mapping 0.5 * x + 0.5 of the first `width` output components.
template <class T>
void mapToUnit(const KernelFrame<T>& f, int width) {
    for (int k = 0; k < width; ++k) {
        T* __restrict o = f.outComp(k);
        for (int i = 0; i < f.n; ++i) o[i] = T(0.5) * o[i] + T(0.5);
    }
}

// The seeds of channels 0, 1, 2 (initialised on first use, never during static initialisation).
const uint32_t* channelSeeds() {
    static const uint32_t seeds[3] = {noise::channelSeed(0), noise::channelSeed(1), noise::channelSeed(2)};
    return seeds;
}

// ---- Gradient noise ------------------------------------------------------------------------

// snoise / vnoise (Mapped = false) and cnoise (Mapped = true): C channels at v.
template <int C, bool Mapped>
struct Noise3K {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        T* out[3] = {f.outComp(0), C > 1 ? f.outComp(1) : nullptr, C > 2 ? f.outComp(2) : nullptr};
        noise::gradient3<T>(f.n, v.p[0], v.p[1], v.p[2], C, channelSeeds(), out);
        if (Mapped) mapToUnit(f, C);
    }
};

template <int C, bool Mapped>
struct Noise4K {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        T tb[kBlockSize];
        const T* t = lanes(f.args[1], 0, f.n, tb);
        T* out[3] = {f.outComp(0), C > 1 ? f.outComp(1) : nullptr, C > 2 ? f.outComp(2) : nullptr};
        noise::gradient4<T>(f.n, v.p[0], v.p[1], v.p[2], t, C, channelSeeds(), out);
        if (Mapped) mapToUnit(f, C);
    }
};

// noise(v): 0.5 * snoise(v) + 0.5; noise(x, y), noise(x, y, z), noise(x, y, z, w): 2-4D noise of
// the arguments' first components (a fifth argument and more are ignored, as in SeExpr2).
struct NoiseK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        T* out[1] = {f.outComp(0)};
        if (f.nargs == 1) {
            const Point3<T> v(f.args[0], f.n);
            noise::gradient3<T>(f.n, v.p[0], v.p[1], v.p[2], 1, channelSeeds(), out);
        } else {
            T buf[4][kBlockSize];
            const T* c[4] = {};
            const int dims = f.nargs < 4 ? f.nargs : 4;
            for (int k = 0; k < dims; ++k) c[k] = lanes(f.args[k], 0, f.n, buf[k]);
            if (dims == 2) noise::gradient2<T>(f.n, c[0], c[1], channelSeeds()[0], out[0]);
            else if (dims == 3) noise::gradient3<T>(f.n, c[0], c[1], c[2], 1, channelSeeds(), out);
            else noise::gradient4<T>(f.n, c[0], c[1], c[2], c[3], 1, channelSeeds(), out);
        }
        mapToUnit(f, 1);
    }
};

bool validateNoise(lang::CallSite& site) {
    bool ok = true;
    for (size_t i = 0; i < site.argTypes.size(); ++i) {
        const lang::Type& t = site.argTypes[i];
        if (t.isError()) {
            ok = false;
        } else if (!t.isFloat()) {
            site.sink->error(site.argSpans[i], "noise expects numbers, got " + lang::typeName(t));
            ok = false;
        }
    }
    if (ok && site.argTypes.size() > 4)
        site.sink->warning(site.argSpans[4], "noise uses at most four coordinates; the rest are ignored");
    return ok;
}

// fbm, vfbm, cfbm, turbulence, vturbulence, cturbulence: C channels of the fractal sum.
template <int C, bool Turbulence, bool Mapped>
struct FbmK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        const Fractal<T> fr(f, 1);
        T* out[3] = {f.outComp(0), C > 1 ? f.outComp(1) : nullptr, C > 2 ? f.outComp(2) : nullptr};
        noise::fbm3<T>(f.n, v.p[0], v.p[1], v.p[2], fr.lanes3, Turbulence, C, out);
        if (Mapped) mapToUnit(f, C);
    }
};

template <int C, bool Mapped>
struct Fbm4K {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        T tb[kBlockSize];
        const T* t = lanes(f.args[1], 0, f.n, tb);
        const Fractal<T> fr(f, 2);
        T* out[3] = {f.outComp(0), C > 1 ? f.outComp(1) : nullptr, C > 2 ? f.outComp(2) : nullptr};
        noise::fbm4<T>(f.n, v.p[0], v.p[1], v.p[2], t, fr.lanes3, C, out);
        if (Mapped) mapToUnit(f, C);
    }
};

// ---- Cells, periodic noise, hash -----------------------------------------------------------

template <int C>
struct CellK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        T* out[3] = {f.outComp(0), C > 1 ? f.outComp(1) : nullptr, C > 2 ? f.outComp(2) : nullptr};
        noise::cell3<T>(f.n, v.p[0], v.p[1], v.p[2], C, channelSeeds(), out);
    }
};

// pnoise(v, period): snoise whose lattice wraps every max(1, int(period)) cells per axis, plus
// 0.5 (SeExpr2's mapping for pnoise: not 0.5 * n + 0.5).
struct PNoiseK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        const Point3<T> period(f.args[1], f.n);
        int32_t p[3][kBlockSize];
        for (int k = 0; k < 3; ++k)
            for (int i = 0; i < f.n; ++i) {
                const int q = detail::truncToInt(static_cast<double>(period.p[k][i]));
                p[k][i] = q < 1 ? 1 : q;
            }
        T* o = f.outComp(0);
        noise::gradient3Periodic<T>(f.n, v.p[0], v.p[1], v.p[2], p[0], p[1], p[2], channelSeeds()[0], o);
        for (int i = 0; i < f.n; ++i) o[i] = o[i] + T(0.5);
    }
};

struct HashK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        std::vector<double> seeds(static_cast<size_t>(f.nargs));
        T* o = f.outComp(0);
        for (int i = 0; i < f.n; ++i) {
            for (int k = 0; k < f.nargs; ++k) seeds[static_cast<size_t>(k)] = static_cast<double>(f.args[k].at(0, i));
            o[i] = T(detail::seHash(seeds.data(), f.nargs));
        }
    }
};

// ---- Voronoi -------------------------------------------------------------------------------

// SeExpr2's clamp: max(lo, min(v, hi)) with NaN giving lo.
template <class T>
T seClamp(T v, T lo, T hi) {
    const T m = hi < v ? hi : v;
    return m > lo ? m : lo;
}

// SeExpr2's smoothstep(x, 0, b).
template <class T>
T smoothFrom0(T x, T b) {
    if (T(0) < b) {
        if (x < T(0)) return T(0);
        if (x >= b) return T(1);
        const T t = x / b;
        return t * t * (T(3) - T(2) * t);
    }
    if (T(0) > b) {
        if (x <= b) return T(1);
        if (x > T(0)) return T(0);
        const T t = T(1) - (x - b) / (T(0) - b);
        return t * t * (T(3) - T(2) * t);
    }
    return x < T(0) ? T(0) : T(1);
}

enum class VoronoiKind { Scalar, Color, Point };

// voronoi / cvoronoi (v, type, jitter, fbmScale, fbmOctaves, fbmLacunarity, fbmGain) and
// pvoronoi (v, jitter, fbmScale, fbmOctaves, fbmLacunarity, fbmGain).
template <VoronoiKind Kind>
struct VoronoiK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const int n = f.n;
        const int jitterArg = Kind == VoronoiKind::Point ? 1 : 2;
        T p[3][kBlockSize] = {}; // (zeroed: GCC cannot see that n lanes are filled)
        {
            const Point3<T> v(f.args[0], n);
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < n; ++i) p[k][i] = v.p[k][i];
        }
        T jit[kBlockSize] = {}, sb[kBlockSize];
        {
            T jb[kBlockSize];
            const T* j = lanes(f.args[jitterArg], 0, n, jb);
            for (int i = 0; i < n; ++i) jit[i] = seClamp(j[i], T(1e-3), T(1));
        }
        // Domain distortion: p += fbmScale * vfbm(2 p, fbmOctaves, fbmLacunarity, fbmGain).
        const T* scale = lanes(f.args[jitterArg + 1], 0, n, sb);
        bool distort = false;
        for (int i = 0; i < n; ++i) distort = distort || scale[i] > T(0);
        if (distort) {
            T q[3][kBlockSize], d[3][kBlockSize];
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < n; ++i) q[k][i] = T(2) * p[k][i];
            const Fractal<T> fr(f, jitterArg + 2);
            T* out[3] = {d[0], d[1], d[2]};
            noise::fbm3<T>(n, q[0], q[1], q[2], fr.lanes3, false, 3, out);
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < n; ++i)
                    if (scale[i] > T(0)) p[k][i] = p[k][i] + scale[i] * d[k][i];
        }
        T f1[kBlockSize], f2[kBlockSize], pos1[3][kBlockSize], pos2[3][kBlockSize];
        int32_t cell1[3][kBlockSize];
        const noise::VoronoiLanes<T> vl{f1, f2, {pos1[0], pos1[1], pos1[2]}, {pos2[0], pos2[1], pos2[2]},
                                        {cell1[0], cell1[1], cell1[2]}};
        noise::voronoi3<T>(n, p[0], p[1], p[2], jit, vl);
        if constexpr (Kind == VoronoiKind::Point) {
            for (int k = 0; k < f.outWidth && k < 3; ++k) {
                T* o = f.outComp(k);
                for (int i = 0; i < n; ++i) o[i] = pos1[k][i];
            }
            return;
        }
        // Type 1 is the cell value at the nearest feature point, SeExpr2's cellnoise(pos1 +
        // [10, 0, 0]) for voronoi and ccellnoise(pos1) for cvoronoi.
        T cv[3][kBlockSize];
        {
            T shifted[kBlockSize];
            for (int i = 0; i < n; ++i) shifted[i] = Kind == VoronoiKind::Scalar ? pos1[0][i] + T(10) : pos1[0][i];
            T* out[3] = {cv[0], cv[1], cv[2]};
            noise::cell3<T>(n, shifted, pos1[1], pos1[2], Kind == VoronoiKind::Color ? 3 : 1, channelSeeds(), out);
        }
        T tb[kBlockSize];
        const T* type = lanes(f.args[1], 0, n, tb);
        T value[kBlockSize];
        for (int i = 0; i < n; ++i) {
            const T a = f1[i], b = f2[i];
            switch (detail::truncToInt(static_cast<double>(type[i]))) {
            case 1: value[i] = Kind == VoronoiKind::Scalar ? cv[0][i] : T(1); break;
            case 2: value[i] = a; break;
            case 3: value[i] = b; break;
            case 4: value[i] = b - a; break;
            case 5: {
                T len12 = T(0), len1 = T(0), len2 = T(0);
                for (int k = 0; k < 3; ++k) {
                    const T d12 = pos2[k][i] - pos1[k][i], d1 = pos1[k][i] - p[k][i], d2 = pos2[k][i] - p[k][i];
                    len12 += d12 * d12;
                    len1 += d1 * d1;
                    len2 += d2 * d2;
                }
                const float sf = static_cast<float>(std::sqrt(len12) / (std::sqrt(len1) + std::sqrt(len2)));
                value[i] = smoothFrom0(b - a, T(0.1) * T(sf));
                break;
            }
            default: value[i] = T(0); break;
            }
        }
        for (int k = 0; k < f.outWidth; ++k) {
            T* o = f.outComp(k);
            if constexpr (Kind == VoronoiKind::Color)
                for (int i = 0; i < n; ++i) o[i] = value[i] * cv[k < 3 ? k : 0][i];
            else
                for (int i = 0; i < n; ++i) o[i] = value[i];
        }
    }
};

bool validateVoronoi(lang::CallSite& site) {
    if (site.constValues.size() > 1 && !site.constValues[1].empty()) {
        const double type = site.constValues[1][0];
        if (!(type >= 1 && type < 6))
            site.sink->warning(site.argSpans[1], "voronoi type is 1 to 5; other values give 0");
    }
    return true;
}

// ---- Curl and flow noise (ext) -------------------------------------------------------------

struct CurlK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        const Fractal<T> fr(f, 1);
        T* out[3] = {f.outComp(0), f.outComp(1), f.outComp(2)};
        noise::curl3<T>(f.n, v.p[0], v.p[1], v.p[2], fr.lanes3, out);
    }
};

template <bool Flow>
struct CurlTimeK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const Point3<T> v(f.args[0], f.n);
        T tb[kBlockSize];
        const T* t = lanes(f.args[1], 0, f.n, tb);
        const Fractal<T> fr(f, 2);
        T* out[3] = {f.outComp(0), f.outComp(1), f.outComp(2)};
        if (Flow) noise::flow3<T>(f.n, v.p[0], v.p[1], v.p[2], t, fr.lanes3, out);
        else noise::curl4<T>(f.n, v.p[0], v.p[1], v.p[2], t, fr.lanes3, out);
    }
};

#define GALE_FRACTAL_PARAMS "FP[1] octaves = 6, FP[1] lacunarity = 2, FP[1] gain = 0.5"
#define GALE_CURL_PARAMS "FP[1] octaves = 1, FP[1] lacunarity = 2, FP[1] gain = 0.5"
#define GALE_VORONOI_PARAMS                                                                                       \
    "FP[1] jitter = 0.5, FP[1] fbmScale = 0, FP[1] fbmOctaves = 4, FP[1] fbmLacunarity = 2, FP[1] fbmGain = 0.5"

} // namespace

void addNoiseBuiltins(FunctionTable& t) {
    t.add(kernelBuiltin<Noise3K<1, false>>("snoise", "FP[1] snoise(FP[3] v)",
                                           "signed gradient noise: 0 on integer points, about ±0.7, rms 0.19"));
    Builtin noiseFn = kernelBuiltin<NoiseK>("noise", "FP[1] noise(ANY v, ANY more...)",
                                            "0.5*snoise(v)+0.5; noise(x, y[, z[, w]]) is 2D to 4D noise of scalars");
    noiseFn.info.validate = &validateNoise;
    t.add(noiseFn);
    t.add(kernelBuiltin<Noise3K<3, false>>("vnoise", "FP[3] vnoise(FP[3] v)", "three independent snoise channels"));
    t.add(kernelBuiltin<Noise3K<3, true>>("cnoise", "FP[3] cnoise(FP[3] v)", "0.5*vnoise(v)+0.5"));
    t.add(kernelBuiltin<Noise4K<1, false>>("snoise4", "FP[1] snoise4(FP[3] v, FP[1] t)", "4D signed gradient noise"));
    t.add(kernelBuiltin<Noise4K<3, false>>("vnoise4", "FP[3] vnoise4(FP[3] v, FP[1] t)",
                                           "three independent snoise4 channels"));
    t.add(kernelBuiltin<Noise4K<3, true>>("cnoise4", "FP[3] cnoise4(FP[3] v, FP[1] t)", "0.5*vnoise4(v, t)+0.5"));

    t.add(kernelBuiltin<FbmK<1, false, true>>("fbm", "FP[1] fbm(FP[3] v, " GALE_FRACTAL_PARAMS ")",
                                              "fractal sum of snoise octaves, 0.5*sum+0.5"));
    t.add(kernelBuiltin<FbmK<3, false, false>>("vfbm", "FP[3] vfbm(FP[3] v, " GALE_FRACTAL_PARAMS ")",
                                               "fractal sum of vnoise octaves (raw, signed)"));
    t.add(kernelBuiltin<FbmK<3, false, true>>("cfbm", "FP[3] cfbm(FP[3] v, " GALE_FRACTAL_PARAMS ")",
                                              "0.5*vfbm(v, ...)+0.5"));
    t.add(kernelBuiltin<Fbm4K<1, true>>("fbm4", "FP[1] fbm4(FP[3] v, FP[1] t, " GALE_FRACTAL_PARAMS ")",
                                        "fractal sum of snoise4 octaves, 0.5*sum+0.5"));
    t.add(kernelBuiltin<Fbm4K<3, false>>("vfbm4", "FP[3] vfbm4(FP[3] v, FP[1] t, " GALE_FRACTAL_PARAMS ")",
                                         "fractal sum of vnoise4 octaves (raw, signed)"));
    t.add(kernelBuiltin<Fbm4K<3, true>>("cfbm4", "FP[3] cfbm4(FP[3] v, FP[1] t, " GALE_FRACTAL_PARAMS ")",
                                        "0.5*vfbm4(v, t, ...)+0.5"));
    t.add(kernelBuiltin<FbmK<1, true, true>>("turbulence", "FP[1] turbulence(FP[3] v, " GALE_FRACTAL_PARAMS ")",
                                             "fractal sum of |snoise| octaves, 0.5*sum+0.5 (billowy)"));
    t.add(kernelBuiltin<FbmK<3, true, false>>("vturbulence", "FP[3] vturbulence(FP[3] v, " GALE_FRACTAL_PARAMS ")",
                                              "fractal sum of |vnoise| octaves (raw)"));
    t.add(kernelBuiltin<FbmK<3, true, true>>("cturbulence", "FP[3] cturbulence(FP[3] v, " GALE_FRACTAL_PARAMS ")",
                                             "0.5*vturbulence(v, ...)+0.5"));

    t.add(kernelBuiltin<CellK<1>>("cellnoise", "FP[1] cellnoise(FP[3] v)",
                                  "a random value in [0, 1] per integer cell floor(v)"));
    t.add(kernelBuiltin<CellK<3>>("ccellnoise", "FP[3] ccellnoise(FP[3] v)",
                                  "three random values in [0, 1] per integer cell floor(v)"));
    t.add(kernelBuiltin<PNoiseK>("pnoise", "FP[1] pnoise(FP[3] v, FP[3] period)",
                                 "snoise+0.5 on a lattice that repeats every int(period) cells per axis"));
    t.add(kernelBuiltin<HashK>("hash", "FP[1] hash(FP[1] seed, FP[1] seeds...)",
                               "a random value in [0, 1] determined by all the seeds"));

    Builtin voronoi = kernelBuiltin<VoronoiK<VoronoiKind::Scalar>>(
        "voronoi", "FP[1] voronoi(FP[3] v, FP[1] type = 1, " GALE_VORONOI_PARAMS ")",
        "cellular noise: 1 cell value, 2 f1, 3 f2, 4 f2-f1, 5 smoothed cell borders");
    voronoi.info.validate = &validateVoronoi;
    t.add(voronoi);
    Builtin cvoronoi = kernelBuiltin<VoronoiK<VoronoiKind::Color>>(
        "cvoronoi", "FP[3] cvoronoi(FP[3] v, FP[1] type = 1, " GALE_VORONOI_PARAMS ")",
        "cellular noise in colour: the nearest cell's colour (type 1) or voronoi's value times it");
    cvoronoi.info.validate = &validateVoronoi;
    t.add(cvoronoi);
    t.add(kernelBuiltin<VoronoiK<VoronoiKind::Point>>("pvoronoi", "FP[3] pvoronoi(FP[3] v, " GALE_VORONOI_PARAMS ")",
                                                      "the feature point of the voronoi cell containing v"));

    t.add(kernelBuiltin<CurlK>("curlnoise", "FP[3] curlnoise(FP[3] P, " GALE_CURL_PARAMS ")",
                               "ext: divergence-free curl of a gradient-noise vector potential"));
    t.add(kernelBuiltin<CurlTimeK<false>>("curlnoise4", "FP[3] curlnoise4(FP[3] P, FP[1] t, " GALE_CURL_PARAMS ")",
                                          "ext: curlnoise of a 4D potential, evolving with t"));
    t.add(kernelBuiltin<CurlTimeK<true>>("flownoise", "FP[3] flownoise(FP[3] P, FP[1] t, " GALE_CURL_PARAMS ")",
                                         "ext: curlnoise whose lattice gradients turn with t (swirls in place)"));
}

} // namespace gale::runtime
