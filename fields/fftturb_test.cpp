// FFT turbulence: the analytic spectrum's normalisation, the synthesised grid's spectrum,
// divergence, variance, mean, periodicity, determinism and resolution nesting; interpolation
// accuracy on a single mode; time evolution; the cache; and fftturb/fftturb4 end to end.
#include "fields/fftturb.h"

#include "fields/expression_field.h"
#include "runtime/program.h"

#include <catch2/catch.hpp>

#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <random>
#include <thread>

using namespace gale;
using namespace gale::fields;

namespace {

constexpr double kPi = 3.14159265358979323846;

TurbulenceSpec makeSpec(int res, int64_t seed = 7, float l = 1.0f, float tile = 8.0f) {
    TurbulenceSpec s;
    s.lengthScale = l;
    s.tile = tile;
    s.res = res;
    s.seed = seed;
    return s;
}

// ∫_0^∞ f(k) dk by the substitution k = e^s (trapezoid on s in [-30, 90]: the integrands here
// decay exponentially in s both ways, where the trapezoid rule converges geometrically).
template <class F>
double integrateHalfLine(const F& f, int steps = 24000) {
    const double a = -30.0, b = 90.0, h = (b - a) / steps;
    double sum = 0.0;
    for (int i = 0; i <= steps; ++i) {
        const double k = std::exp(a + i * h);
        sum += (i == 0 || i == steps ? 0.5 : 1.0) * f(k) * k;
    }
    return sum * h;
}

std::shared_ptr<const runtime::FunctionTable> turbulenceTable(std::shared_ptr<TurbulenceCache> cache = nullptr) {
    auto t = std::make_shared<runtime::FunctionTable>(*runtime::FunctionTable::standard());
    if (cache) addTurbulenceBuiltins(*t, cache);
    else addTurbulenceBuiltins(*t);
    return t;
}

std::vector<lang::HostVariable> variablesWithMinScale() {
    auto v = runtime::standardVariables();
    v.push_back({"turbMinScale", lang::Type::fp(1, lang::Lifetime::Uniform)});
    return v;
}

std::shared_ptr<const runtime::Program> compileTurb(const std::string& text, lang::DiagnosticSink& sink,
                                                    std::vector<lang::HostVariable> vars = runtime::standardVariables()) {
    lang::SourceFile src("<test>", text);
    runtime::CompileSettings settings;
    settings.variables = std::move(vars);
    settings.functions = turbulenceTable();
    return runtime::Program::compile(src, settings, sink);
}

std::vector<double> randomPoints(size_t n, uint64_t seed, double extent) {
    std::mt19937_64 rng(seed);
    std::vector<double> p(3 * n);
    for (double& v : p) v = extent * (static_cast<double>(rng() >> 11) * 0x1.0p-53 * 2.0 - 1.0);
    return p;
}

template <class T>
std::vector<T> evaluateProgram(const runtime::Program& prog, const std::vector<double>& pts, double t,
                               std::vector<runtime::UniformValue> extra = {}) {
    runtime::EvalRequest req;
    req.count = pts.size() / 3;
    req.uniforms = {{"t", {t}, {}}, {"frame", {1}, {}}, {"fps", {24}, {}}};
    for (auto& u : extra) req.uniforms.push_back(u);
    req.varyings = {{"P", 3, pts.data(), 3, 1}};
    std::vector<T> out(pts.size());
    runtime::EvalOutput<T> o;
    o.data = out.data();
    o.pointStride = 3;
    o.compStride = 1;
    runtime::EvalResult r = runtime::evaluate<T>(prog, req, o);
    INFO(r.error);
    REQUIRE(r.ok);
    return out;
}

// Correlation ⟨a·b⟩ / ⟨a·a⟩ over the grid points.
double correlation(const TurbulenceGrid& a, const TurbulenceGrid& b) {
    const size_t n = static_cast<size_t>(a.res()) * a.res() * a.res() * 3;
    double ab = 0.0, aa = 0.0;
    for (size_t i = 0; i < n; ++i) {
        ab += static_cast<double>(a.data()[i]) * b.data()[i];
        aa += static_cast<double>(a.data()[i]) * a.data()[i];
    }
    return ab / aa;
}

} // namespace

TEST_CASE("von Karman spectrum: 3/2 sigma^2 of energy, longitudinal integral scale L", "[fftturb]") {
    for (double l : {0.5, 1.0, 3.0}) {
        const double sigma = 1.7;
        const double energy = integrateHalfLine([&](double k) { return vonKarmanEnergy(k, l, sigma); });
        CHECK(energy == Approx(1.5 * sigma * sigma).epsilon(1e-6));
        // L11 = π/(2σ²) ∫ E(k)/k dk
        const double l11 = kPi / (2 * sigma * sigma) *
                           integrateHalfLine([&](double k) { return k > 0 ? vonKarmanEnergy(k, l, sigma) / k : 0.0; });
        CHECK(l11 == Approx(l).epsilon(1e-6));
    }
}

TEST_CASE("grid size rule: 4 cells per L, or eddies no shorter than turbMinScale", "[fftturb]") {
    const double nan = std::nan("");
    CHECK(resolveTurbulenceRes(0, 1.0, 8.0, nan) == 32);   // 4 · 8 / 1
    CHECK(resolveTurbulenceRes(0, 1.0, 9.0, nan) == 36);   // 36 = 2² 3²
    CHECK(resolveTurbulenceRes(0, 10.0, 8.0, nan) == 16);  // clamped below
    CHECK(resolveTurbulenceRes(0, 0.01, 8.0, nan) == 256); // clamped above
    CHECK(resolveTurbulenceRes(0, 1.0, 8.0, 0.5) == 32);   // 2 · 8 / 0.5
    CHECK(resolveTurbulenceRes(0, 1.0, 8.0, 0.3) == 50);   // largest smooth even <= 53.3
    CHECK(resolveTurbulenceRes(0, 1.0, 8.0, 4.0) == 16);
    CHECK(resolveTurbulenceRes(0, 1.0, 8.0, 1e-4) == 256);
    CHECK(resolveTurbulenceRes(33, 1.0, 8.0, nan) == 34);  // explicit: even
    CHECK(resolveTurbulenceRes(2, 1.0, 8.0, nan) == 8);
}

TEST_CASE("synthesised grid: spectrum, divergence, variance, mean", "[fftturb]") {
    for (int res : {32, 48, 64}) {
        for (int64_t seed : {1, 2}) {
            INFO("res " << res << " seed " << seed);
            auto g = TurbulenceGrid::synthesize(makeSpec(res, seed));
            double mean[3], var[3];
            turbulenceMoments(*g, mean, var);
            for (int c = 0; c < 3; ++c) {
                CHECK(std::abs(mean[c]) < 1e-5);
                CHECK(var[c] == Approx(1.0).epsilon(0.03));
                CHECK(var[c] == Approx(1.0).epsilon(1e-4)); // in fact exact up to float rounding
            }
            TurbulenceSpectrum spec(*g);
            CHECK(spec.divergence() <= 1e-6);
            const auto shells = spec.shells(1.0);
            REQUIRE(static_cast<int>(shells.size()) == g->maxMode());
            for (const TurbulenceShell& s : shells) {
                INFO("shell " << s.index << " k " << s.k << " modes " << s.modes);
                CHECK(s.measured == Approx(s.expected).epsilon(0.05));
            }
            // Nothing outside the truncation sphere, and nothing at k = 0.
            double outside = 0.0, inside = 0.0;
            const int nyq = res / 2;
            for (int mz = -nyq + 1; mz <= nyq; ++mz)
                for (int my = -nyq + 1; my <= nyq; ++my)
                    for (int mx = 0; mx <= nyq; ++mx) {
                        double e = 0.0;
                        for (int c = 0; c < 3; ++c) e += std::norm(spec.coefficient(mx, my, mz, c));
                        (mx * mx + my * my + mz * mz > g->maxMode() * g->maxMode() ? outside : inside) += e;
                    }
            CHECK(outside < 1e-10 * inside);
        }
    }
}

TEST_CASE("the energy scale is the analytic variance over the resolved modes", "[fftturb]") {
    auto g = TurbulenceGrid::synthesize(makeSpec(32, 3, 0.7f, 5.0f));
    const double dk = 2 * kPi / 5.0;
    const int mmax = g->maxMode();
    double resolved = 0.0; // Σ E(|k|)/(4π|k|²) Δk³ over the kept modes of all of k-space
    for (int mz = -mmax; mz <= mmax; ++mz)
        for (int my = -mmax; my <= mmax; ++my)
            for (int mx = -mmax; mx <= mmax; ++mx) {
                const int m2 = mx * mx + my * my + mz * mz;
                if (m2 == 0 || m2 > mmax * mmax) continue;
                const double k = std::sqrt(static_cast<double>(m2)) * dk;
                resolved += vonKarmanEnergy(k, 0.7, 1.0) / (4 * kPi * k * k) * dk * dk * dk;
            }
    CHECK(g->energyScale() == Approx(1.5 / resolved).epsilon(1e-7));
    CHECK(g->energyScale() > 1.0);
}

TEST_CASE("grids are deterministic by seed, independent of threads, nested in resolution", "[fftturb]") {
    auto a = TurbulenceGrid::synthesize(makeSpec(32, 11), 1);
    auto b = TurbulenceGrid::synthesize(makeSpec(32, 11), 2);
    auto c = TurbulenceGrid::synthesize(makeSpec(32, 12), 1);
    CHECK(std::memcmp(a->data(), b->data(), a->bytes()) == 0);
    CHECK(std::memcmp(a->data(), c->data(), a->bytes()) != 0);
    CHECK(std::abs(correlation(*a, *c)) < 0.3);

    // The large eddies stay when the resolution changes: same coefficients up to the
    // ratio of the energy scales.
    auto fine = TurbulenceGrid::synthesize(makeSpec(64, 11));
    TurbulenceSpectrum sa(*a), sf(*fine);
    const double ratio = std::sqrt(fine->energyScale() / a->energyScale());
    for (auto m : {std::array<int, 3>{1, 0, 0}, {0, 1, -2}, {3, -2, 1}, {0, 0, 5}, {7, 4, -9}})
        for (int comp = 0; comp < 3; ++comp) {
            const auto ca = sa.coefficient(m[0], m[1], m[2], comp) * ratio;
            const auto cf = sf.coefficient(m[0], m[1], m[2], comp);
            CHECK(std::abs(ca - cf) <= 1e-4 * std::abs(cf) + 1e-6);
        }
}

TEST_CASE("sampling is periodic and passes through the grid values", "[fftturb]") {
    auto g = TurbulenceGrid::synthesize(makeSpec(32, 5, 0.5f, 4.0f));
    const double h = g->cellSize();
    for (auto interp : {TurbulenceInterp::Trilinear, TurbulenceInterp::Tricubic}) {
        float v[3], w[3];
        g->sample(3 * h, 7 * h, 30 * h, interp, v);
        const float* node = g->data() + ((30 * 32 + 7) * 32 + 3) * 3;
        for (int c = 0; c < 3; ++c) CHECK(v[c] == Approx(node[c]).margin(1e-6));
        const auto pts = randomPoints(50, 3, 3.0);
        for (size_t i = 0; i < 50; ++i) {
            const double x = pts[3 * i], y = pts[3 * i + 1], z = pts[3 * i + 2];
            g->sample(x, y, z, interp, v);
            g->sample(x + 4.0, y - 8.0, z + 12.0, interp, w);
            for (int c = 0; c < 3; ++c) CHECK(v[c] == Approx(w[c]).margin(2e-5));
        }
    }
    float v[3];
    g->sample(std::nan(""), 0, 0, TurbulenceInterp::Tricubic, v);
    CHECK(std::isnan(v[0]));
}

TEST_CASE("trilinear and tricubic interpolation of a single mode against its closed form", "[fftturb]") {
    // u = (sin(k y + 0.3), sin(k z + 1.1), sin(k x - 0.7)), divergence-free, k = 2π m / T.
    const double tile = 2.0;
    const int m = 2;
    const double k = 2 * kPi * m / tile;
    auto exact = [&](double x, double y, double z, double out[3]) {
        out[0] = std::sin(k * y + 0.3);
        out[1] = std::sin(k * z + 1.1);
        out[2] = std::sin(k * x - 0.7);
    };
    auto maxError = [&](int res, TurbulenceInterp interp) {
        std::vector<float> data(static_cast<size_t>(res) * res * res * 3);
        const double h = tile / res;
        for (int iz = 0; iz < res; ++iz)
            for (int iy = 0; iy < res; ++iy)
                for (int ix = 0; ix < res; ++ix) {
                    double v[3];
                    exact(ix * h, iy * h, iz * h, v);
                    for (int c = 0; c < 3; ++c) data[((static_cast<size_t>(iz) * res + iy) * res + ix) * 3 + c] = float(v[c]);
                }
        auto g = TurbulenceGrid::fromData(res, tile, std::move(data));
        const auto pts = randomPoints(2000, 17, 5.0);
        double err = 0.0;
        for (size_t i = 0; i < 2000; ++i) {
            float v[3];
            double e[3];
            g->sample(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], interp, v);
            exact(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], e);
            for (int c = 0; c < 3; ++c) err = std::max(err, std::abs(v[c] - e[c]));
        }
        return err;
    };
    const double lin16 = maxError(16, TurbulenceInterp::Trilinear), lin32 = maxError(32, TurbulenceInterp::Trilinear);
    const double cub16 = maxError(16, TurbulenceInterp::Tricubic), cub32 = maxError(32, TurbulenceInterp::Tricubic);
    // Trilinear: |err| <= (kh)²/8; Catmull-Rom: third order.
    const double kh16 = k * tile / 16;
    CHECK(lin16 <= kh16 * kh16 / 8 * 1.01);
    CHECK(lin16 / lin32 > 3.5);
    CHECK(cub16 / cub32 > 7.0);
    CHECK(cub16 < lin16 / 3);
    CHECK(cub32 < 2e-3);
}

TEST_CASE("mode evolution keeps variance, spectrum and zero divergence; decorrelates in tau", "[fftturb]") {
    const float tau = 0.8f;
    // At t = 0 the animated grid is the frozen one.
    TurbulenceSpec frozen = makeSpec(32, 4);
    TurbulenceSpec s = frozen;
    s.tau = tau;
    s.time = 0.0f;
    auto g0 = TurbulenceGrid::synthesize(frozen);
    auto a0 = TurbulenceGrid::synthesize(s);
    CHECK(std::memcmp(g0->data(), a0->data(), g0->bytes()) == 0);
    for (float t : {0.37f * tau, 1.3f * tau, 5.0f * tau, 1000.0f}) {
        s.time = t;
        auto g = TurbulenceGrid::synthesize(s);
        double mean[3], var[3];
        turbulenceMoments(*g, mean, var);
        for (int c = 0; c < 3; ++c) {
            CHECK(std::abs(mean[c]) < 1e-5);
            CHECK(var[c] == Approx(1.0).epsilon(1e-4));
        }
        TurbulenceSpectrum sp(*g);
        CHECK(sp.divergence() <= 1e-6);
        for (const TurbulenceShell& sh : sp.shells(1.0)) CHECK(sh.measured == Approx(sh.expected).epsilon(0.05));
    }
    // ρ(lag) averaged over seeds: expected exp(-π lag² / (4 τ²)), integral time τ.
    const int lags = 12;
    const double dlag = 0.25 * tau;
    std::vector<double> rho(lags + 1, 0.0);
    const int seeds = 4;
    for (int seed = 0; seed < seeds; ++seed) {
        TurbulenceSpec base = makeSpec(32, 100 + seed);
        base.tau = tau;
        base.time = 3.0f;
        auto start = TurbulenceGrid::synthesize(base);
        for (int j = 0; j <= lags; ++j) {
            TurbulenceSpec later = base;
            later.time = static_cast<float>(3.0 + j * dlag);
            rho[j] += correlation(*start, *TurbulenceGrid::synthesize(later)) / seeds;
        }
    }
    double integral = 0.0; // trapezoid over [0, 3τ]
    for (int j = 0; j < lags; ++j) integral += 0.5 * (rho[j] + rho[j + 1]) * dlag;
    INFO("rho(tau) = " << rho[4] << ", integral time / tau = " << integral / tau);
    CHECK(rho[0] == Approx(1.0));
    CHECK(rho[4] == Approx(std::exp(-kPi / 4)).margin(0.1));
    CHECK(integral / tau == Approx(1.0).margin(0.15));
}

TEST_CASE("the cache synthesises once, shares grids and evicts the least recently used", "[fftturb]") {
    auto cache = std::make_shared<TurbulenceCache>(size_t(1) << 30, 2);
    std::vector<std::shared_ptr<const TurbulenceGrid>> got(4);
    std::vector<std::thread> threads;
    for (int i = 0; i < 4; ++i) threads.emplace_back([&, i] { got[i] = cache->get(makeSpec(32, 9)); });
    for (auto& t : threads) t.join();
    for (int i = 1; i < 4; ++i) CHECK(got[i] == got[0]);
    CHECK(cache->stats().misses == 1);
    CHECK(cache->stats().hits == 3);
    TurbulenceSpec frozenLater = makeSpec(32, 9); // tau = 0: the instant does not matter
    frozenLater.time = 5.0f;
    CHECK(cache->get(frozenLater) == got[0]);
    auto b = cache->get(makeSpec(16, 1));
    cache->get(makeSpec(32, 9)); // touch: 16³ seed 1 is now least recently used
    cache->get(makeSpec(16, 2));
    CHECK(cache->stats().entries == 2);
    CHECK(cache->stats().bytes == (size_t(32 * 32 * 32) + 16 * 16 * 16) * 3 * sizeof(float));
    CHECK(cache->get(makeSpec(32, 9)) == got[0]);
    CHECK(cache->get(makeSpec(16, 1)) != b); // evicted, made again
    // A byte budget smaller than one grid still keeps the newest.
    TurbulenceCache tiny(1000, 8);
    CHECK(tiny.get(makeSpec(16, 1)));
    CHECK(tiny.stats().entries == 1);
}

TEST_CASE("fftturb end to end: the grid sampled at P, sigma-scaled, in float and double", "[fftturb]") {
    lang::DiagnosticSink sink;
    auto prog = compileTurb("fftturb($P, 0.5, 2.0, 3, 4, 32)", sink);
    REQUIRE(prog);
    REQUIRE(prog->resultWidth() == 3);
    const auto pts = randomPoints(600, 5, 10.0);
    const auto f = evaluateProgram<float>(*prog, pts, 0.0);
    const auto d = evaluateProgram<double>(*prog, pts, 0.0);
    TurbulenceSpec spec = makeSpec(32, 3, 0.5f, 4.0f);
    auto g = TurbulenceGrid::synthesize(spec);
    for (size_t i = 0; i < 600; ++i) {
        float v[3];
        g->sample(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], TurbulenceInterp::Tricubic, v);
        for (int c = 0; c < 3; ++c) {
            CHECK(f[3 * i + c] == Approx(2.0 * v[c]).margin(2e-4)); // P rounded to float
            CHECK(d[3 * i + c] == Approx(2.0 * v[c]).margin(1e-5));
        }
    }
    // Trilinear selectable; defaults (tile 8 L, res from L) match the explicit call.
    auto lin = compileTurb("fftturb($P, 0.5, 1, 3, 0, 0, 0)", sink);
    auto linExplicit = compileTurb("fftturb($P, 0.5, 1, 3, 4, 32, 0)", sink);
    REQUIRE(lin);
    REQUIRE(linExplicit);
    CHECK(evaluateProgram<double>(*lin, pts, 0.0) == evaluateProgram<double>(*linExplicit, pts, 0.0));
}

TEST_CASE("fftturb4 on many threads: one synthesis per instant, results independent of threads", "[fftturb]") {
    auto cache = std::make_shared<TurbulenceCache>();
    lang::SourceFile src("<test>", "fftturb4($P, $t, 0.8, 1, 5, 0, 40, [1, 0, 0], 0.3)");
    lang::DiagnosticSink sink;
    runtime::CompileSettings settings;
    settings.variables = runtime::standardVariables();
    settings.functions = turbulenceTable(cache);
    auto prog = runtime::Program::compile(src, settings, sink);
    REQUIRE(prog);
    const auto pts = randomPoints(20000, 4, 8.0);
    auto run = [&](double t, int threads) {
        runtime::EvalRequest req;
        req.count = pts.size() / 3;
        req.threads = threads;
        req.uniforms = {{"t", {t}, {}}, {"frame", {1}, {}}, {"fps", {24}, {}}};
        req.varyings = {{"P", 3, pts.data(), 3, 1}};
        std::vector<float> out(pts.size());
        runtime::EvalOutput<float> o;
        o.data = out.data();
        o.pointStride = 3;
        o.compStride = 1;
        REQUIRE(runtime::evaluate<float>(*prog, req, o).ok);
        return out;
    };
    const auto many = run(0.7, 4); // every block asks for the new grid at once
    CHECK(cache->stats().misses == 1);
    cache->clear();
    CHECK(run(0.7, 1) == many);
    CHECK(run(0.9, 3) != many);
    CHECK(cache->stats().misses == 3);
}

TEST_CASE("fftturb takes its resolution from $turbMinScale", "[fftturb]") {
    lang::DiagnosticSink sink;
    auto prog = compileTurb("fftturb($P, 1, 1)", sink, variablesWithMinScale());
    REQUIRE(prog);
    const auto pts = randomPoints(300, 8, 5.0);
    const auto out = evaluateProgram<double>(*prog, pts, 0.0, {{"turbMinScale", {0.3}, {}}});
    auto g = TurbulenceGrid::synthesize(makeSpec(50, 0)); // largest smooth even <= 2·8/0.3
    for (size_t i = 0; i < 300; ++i) {
        float v[3];
        g->sample(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], TurbulenceInterp::Tricubic, v);
        for (int c = 0; c < 3; ++c) CHECK(out[3 * i + c] == Approx(v[c]).margin(1e-5));
    }
}

TEST_CASE("fftturb4: Taylor advection by the mean wind and mode evolution", "[fftturb]") {
    lang::DiagnosticSink sink;
    auto adv = compileTurb("fftturb4($P, $t, 1, 1.5, 2, 0, 32, [3, 0, -1])", sink);
    auto still = compileTurb("fftturb($P - [3, 0, -1] * $t, 1, 1.5, 2, 0, 32)", sink);
    REQUIRE(adv);
    REQUIRE(still);
    const auto pts = randomPoints(400, 2, 6.0);
    for (double t : {0.0, 0.25, 1.5}) {
        const auto a = evaluateProgram<double>(*adv, pts, t);
        const auto b = evaluateProgram<double>(*still, pts, t);
        for (size_t i = 0; i < a.size(); ++i) CHECK(a[i] == Approx(b[i]).margin(1e-5));
    }
    auto evolve = compileTurb("fftturb4($P, $t, 1, 1, 2, 0, 32, 0, 0.5)", sink);
    REQUIRE(evolve);
    const auto e0 = evaluateProgram<double>(*evolve, pts, 0.0);
    const auto e1 = evaluateProgram<double>(*evolve, pts, 0.05);
    const auto e2 = evaluateProgram<double>(*evolve, pts, 5.0);
    const auto s0 = evaluateProgram<double>(*still, pts, 0.0);
    // rms change over a lag: sqrt(2 (1 - ρ)), ρ = exp(-π lag² / (4 τ²)): 0.125 at 0.05, 1.41 at 5.
    double d01 = 0.0, d02 = 0.0;
    for (size_t i = 0; i < e0.size(); ++i) {
        CHECK(e0[i] == Approx(s0[i] / 1.5).margin(1e-5)); // t = 0: the frozen grid
        d01 += (e1[i] - e0[i]) * (e1[i] - e0[i]) / e0.size();
        d02 += (e2[i] - e0[i]) * (e2[i] - e0[i]) / e0.size();
    }
    CHECK(std::sqrt(d01) > 0.05);
    CHECK(std::sqrt(d01) < 0.25);
    CHECK(std::sqrt(d02) > 1.0);
}

TEST_CASE("fftturb arguments other than P must be constant or uniform and in range", "[fftturb]") {
    struct Case {
        const char* text;
        const char* message;
        const char* underlined; // the span the error points at
    };
    const Case cases[] = {
        {"fftturb($P, $P[0] + 1, 1)", "argument 'L' must be constant or uniform", "$P[0] + 1"},
        {"fftturb($P, 1, 1, $id)", "argument 'seed' must be constant or uniform", "$id"},
        {"fftturb4($P, $P[1], 1, 1, 0, 0, 0, [1, 0, 0])", "argument 't' must be constant or uniform", "$P[1]"},
        {"fftturb4($P, $t, 1, 1, 0, 0, 0, $P)", "argument 'advect' must be constant or uniform", "$P"},
        {"fftturb($P, 0, 1)", "argument 'L' must be positive", "0"},
        {"fftturb($P, 1, -1)", "argument 'sigma' must be zero or positive", "-1"},
        {"fftturb($P, 1, 1, 0, 0, 33)", "argument 'res' must be 0 (automatic) or an even integer", "33"},
        {"fftturb($P, 1, 1, 0, 0, 0, 2)", "argument 'interp' must be 0 (trilinear) or 1 (tricubic)", "2"},
        {"fftturb($P, [1, 2, 3], 1)", "", ""},
    };
    for (const Case& c : cases) {
        INFO(c.text);
        lang::DiagnosticSink sink;
        lang::SourceFile src("<test>", c.text);
        runtime::CompileSettings settings;
        settings.variables = runtime::standardVariables();
        settings.functions = turbulenceTable();
        CHECK_FALSE(runtime::Program::compile(src, settings, sink));
        REQUIRE(sink.hasErrors());
        const lang::Diagnostic& d = sink.diagnostics().front();
        CHECK_THAT(d.message, Catch::Contains(c.message));
        if (*c.underlined)
            CHECK(std::string(c.text).substr(d.span.begin, d.span.end - d.span.begin) == c.underlined);
    }
    // Uniform arguments are fine; a still fftturb4 compiles with a warning.
    lang::DiagnosticSink ok;
    CHECK(compileTurb("fftturb($P, 1 + $t, 2 * $t, $frame)", ok));
    CHECK_FALSE(ok.hasErrors());
    lang::DiagnosticSink warn;
    CHECK(compileTurb("fftturb4($P, $t, 1, 1)", warn));
    REQUIRE(warn.diagnostics().size() == 1);
    CHECK(warn.diagnostics()[0].severity == lang::Severity::Warning);
}
