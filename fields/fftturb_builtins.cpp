// The fftturb and fftturb4 built-ins: their uniform arguments decoded and checked, the cached
// turbulence grid (fftturb.cpp) sampled per block of lanes, scaled, shifted and blended.
#include "fields/fftturb.h"

#include "fields/expression_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace gale::fields {

// ---- Built-ins ------------------------------------------------------------------------------

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The uniform arguments of a call, decoded; false when a value is out of range.
struct TurbCall {
    TurbulenceSpec spec;
    double sigma = 1.0;
    double shift[3] = {0, 0, 0}; // advect · t
    TurbulenceInterp interp = TurbulenceInterp::Tricubic;
};

bool decode(double l, double sigma, double seed, double tile, double res, double interp, double minScale,
            TurbCall& call) {
    if (!(std::isfinite(l) && l > 0.0) || !(std::isfinite(sigma) && sigma >= 0.0) || !std::isfinite(seed) ||
        !(std::isfinite(tile) && tile >= 0.0) || !(std::isfinite(res) && res >= 0.0 && res <= 512.0) ||
        !std::isfinite(interp))
        return false;
    const float lf = static_cast<float>(l);
    const float tf = static_cast<float>(tile > 0.0 ? tile : defaultTurbulenceTile(lf));
    call.spec.lengthScale = lf;
    call.spec.tile = tf;
    call.spec.res = resolveTurbulenceRes(res, lf, tf, minScale);
    call.spec.seed = static_cast<int64_t>(std::llround(std::clamp(seed, -9.0e18, 9.0e18)));
    call.sigma = sigma;
    call.interp = interp < 0.5 ? TurbulenceInterp::Trilinear : TurbulenceInterp::Tricubic;
    return true;
}

template <class T>
void fillNaN(const runtime::KernelFrame<T>& f) {
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < f.n; ++i) f.outComp(c)[i] = std::numeric_limits<T>::quiet_NaN();
}

template <class T>
void sampleLanes(const runtime::KernelFrame<T>& f, const TurbCall& call) {
    const auto* cache = static_cast<const TurbulenceCache*>(f.user);
    if (!cache) cache = TurbulenceCache::global().get();
    std::shared_ptr<const TurbulenceGrid> grid;
    try {
        grid = cache->get(call.spec);
    } catch (...) {
        fillNaN(f);
        return;
    }
    const runtime::Operand<T>& p = f.args[0];
    const float sigma = static_cast<float>(call.sigma);
    T* o0 = f.outComp(0);
    T* o1 = f.outComp(1);
    T* o2 = f.outComp(2);
    for (int i = 0; i < f.n; ++i) {
        float v[3];
        grid->sample(static_cast<double>(p.at(0, i)) - call.shift[0], static_cast<double>(p.at(1, i)) - call.shift[1],
                     static_cast<double>(p.at(2, i)) - call.shift[2], call.interp, v);
        o0[i] = static_cast<T>(sigma * v[0]);
        o1[i] = static_cast<T>(sigma * v[1]);
        o2[i] = static_cast<T>(sigma * v[2]);
    }
}

// sigma = 0 (a preset with its turbulence turned off): zero velocity, and no grid is made or
// sampled — a scene pays nothing for turbulence it does not use.
template <class T>
bool zeroWhenSilent(const runtime::KernelFrame<T>& f, int sigmaArg) {
    if (f.args[sigmaArg].at(0, 0) != T(0)) return false;
    for (int c = 0; c < 3; ++c) {
        T* __restrict o = f.outComp(c);
        for (int i = 0; i < f.n; ++i) o[i] = T(0);
    }
    return true;
}

// fftturb(P, L, sigma, seed, tile, res, interp) + implicit $turbMinScale.
struct FftTurbK {
    template <class T>
    static void run(const runtime::KernelFrame<T>& f) {
        if (zeroWhenSilent(f, 2)) return;
        auto u = [&](int k) { return static_cast<double>(f.args[k].at(0, 0)); };
        TurbCall call;
        if (!decode(u(1), u(2), u(3), u(4), u(5), u(6), u(7), call)) return fillNaN(f);
        sampleLanes(f, call);
    }
};

// fftturb4(P, t, L, sigma, seed, tile, res, advect, tau, interp) + implicit $turbMinScale.
struct FftTurb4K {
    template <class T>
    static void run(const runtime::KernelFrame<T>& f) {
        if (zeroWhenSilent(f, 3)) return;
        auto u = [&](int k) { return static_cast<double>(f.args[k].at(0, 0)); };
        TurbCall call;
        const double t = static_cast<double>(static_cast<float>(u(1))), tau = u(8);
        if (!std::isfinite(t) || !(std::isfinite(tau) && tau >= 0.0) ||
            !decode(u(2), u(3), u(4), u(5), u(6), u(9), u(10), call))
            return fillNaN(f);
        for (int c = 0; c < 3; ++c) {
            const double a = static_cast<double>(f.args[7].at(c, 0));
            if (!std::isfinite(a)) return fillNaN(f);
            call.shift[c] = a * t;
        }
        if (tau > 0.0) {
            call.spec.tau = static_cast<float>(tau);
            call.spec.time = static_cast<float>(t);
        }
        sampleLanes(f, call);
    }
};

enum class Rule { Any, Positive, NonNegative, Res, Interp, Finite };

struct ArgRule {
    const char* name;
    Rule rule;
};

// Every argument but P selects the grid: constant or uniform only. Constant values are
// range-checked here; uniform ones out of range give NaN at run time.
bool validateArgs(lang::CallSite& site, const ArgRule* rules, size_t count) {
    const std::string fn(site.name);
    bool ok = true;
    for (size_t i = 1; i < site.argTypes.size() && i < count; ++i) {
        const ArgRule& r = rules[i];
        if (site.argTypes[i].lifetime == lang::Lifetime::Varying) {
            site.sink->error(site.argSpans[i], fn + ": argument '" + r.name +
                                                   "' must be constant or uniform (it selects the synthesised grid), "
                                                   "not varying");
            ok = false;
            continue;
        }
        for (double v : site.constValues[i]) {
            const char* why = nullptr;
            switch (r.rule) {
            case Rule::Positive: if (!(std::isfinite(v) && v > 0.0)) why = "must be positive"; break;
            case Rule::NonNegative: if (!(std::isfinite(v) && v >= 0.0)) why = "must be zero or positive"; break;
            case Rule::Res:
                if (!(v == 0.0 || (v >= 8.0 && v <= 512.0 && v == std::floor(v) && std::fmod(v, 2.0) == 0.0)))
                    why = "must be 0 (automatic) or an even integer from 8 to 512";
                break;
            case Rule::Interp: if (v != 0.0 && v != 1.0) why = "must be 0 (trilinear) or 1 (tricubic)"; break;
            case Rule::Finite: if (!std::isfinite(v)) why = "must be finite"; break;
            case Rule::Any: break;
            }
            if (why) {
                site.sink->error(site.argSpans[i], fn + ": argument '" + r.name + "' " + why);
                ok = false;
                break;
            }
        }
    }
    return ok;
}

const ArgRule kTurbRules[] = {{"P", Rule::Any},        {"L", Rule::Positive},    {"sigma", Rule::NonNegative},
                              {"seed", Rule::Finite},  {"tile", Rule::NonNegative}, {"res", Rule::Res},
                              {"interp", Rule::Interp}};
const ArgRule kTurb4Rules[] = {{"P", Rule::Any},           {"t", Rule::Finite},      {"L", Rule::Positive},
                               {"sigma", Rule::NonNegative}, {"seed", Rule::Finite},   {"tile", Rule::NonNegative},
                               {"res", Rule::Res},           {"advect", Rule::Finite}, {"tau", Rule::NonNegative},
                               {"interp", Rule::Interp}};

bool validateFftturb(lang::CallSite& site) { return validateArgs(site, kTurbRules, std::size(kTurbRules)); }

bool validateFftturb4(lang::CallSite& site) {
    if (!validateArgs(site, kTurb4Rules, std::size(kTurb4Rules))) return false;
    const auto& advect = site.constValues[7];
    const auto& tau = site.constValues[8];
    const bool still = !advect.empty() && std::all_of(advect.begin(), advect.end(), [](double v) { return v == 0.0; }) &&
                       !tau.empty() && tau[0] == 0.0;
    if (still)
        site.sink->warning(site.span, "fftturb4 with advect = 0 and tau = 0 does not change with t "
                                      "(give a mean wind 'advect', a correlation time 'tau', or use fftturb)");
    return true;
}

} // namespace

void addTurbulenceBuiltins(runtime::FunctionTable& t, std::shared_ptr<TurbulenceCache> cache) {
    if (!cache) cache = TurbulenceCache::global();
    const lang::FunctionInfo::Implicit minScale{"turbMinScale", kNaN};
    runtime::Builtin turb = runtime::kernelBuiltin<FftTurbK>(
        "fftturb", "FP[3] fftturb(FP[3] P, FP[1] L, FP[1] sigma, FP[1] seed = 0, FP[1] tile = 0, FP[1] res = 0, FP[1] interp = 1)",
        "periodic divergence-free von Karman turbulence: integral scale L, rms sigma per component; tile 0 = 8 L, "
        "res 0 = from $turbMinScale or L; interp 0 trilinear, 1 tricubic");
    turb.info.validate = &validateFftturb;
    turb.info.implicitArgs = {minScale};
    turb.data = cache;
    t.add(turb);
    runtime::Builtin turb4 = runtime::kernelBuiltin<FftTurb4K>(
        "fftturb4",
        "FP[3] fftturb4(FP[3] P, FP[1] t, FP[1] L, FP[1] sigma, FP[1] seed = 0, FP[1] tile = 0, FP[1] res = 0, "
        "FP[3] advect = 0, FP[1] tau = 0, FP[1] interp = 1)",
        "fftturb evolving in time: carried by the mean wind advect (sampled at P - advect t) and decorrelating with "
        "integral time tau (0 = frozen)");
    turb4.info.validate = &validateFftturb4;
    turb4.info.implicitArgs = {minScale};
    turb4.data = cache;
    t.add(turb4);
}

void addTurbulenceBuiltins(runtime::FunctionTable& t) { addTurbulenceBuiltins(t, TurbulenceCache::global()); }

} // namespace gale::fields
