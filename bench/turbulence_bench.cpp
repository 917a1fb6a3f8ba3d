// FFT turbulence: synthesis time against resolution and spectral error, and sampling
// throughput (trilinear, tricubic; direct and through the VM) against interpolation error.
// Usage: gale_bench_turbulence [maxRes=256] [points=400000] [threads=0 (all)]
#include "fields/expression_field.h"
#include "fields/fftturb.h"
#include "runtime/program.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>

using namespace gale;
using namespace gale::fields;

namespace {

double seconds(const std::function<void()>& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double bestSeconds(int repeats, const std::function<void()>& f) {
    double best = 1e30;
    for (int r = 0; r < repeats; ++r) best = std::min(best, seconds(f));
    return best;
}

TurbulenceSpec specFor(int res, float tau = 0.0f, float time = 0.0f) {
    TurbulenceSpec s;
    s.lengthScale = 1.0f;
    s.tile = 8.0f;
    s.res = res;
    s.seed = 1;
    s.tau = tau;
    s.time = time;
    return s;
}

std::vector<double> randomPoints(size_t n, double extent, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<double> p(3 * n);
    for (double& v : p) v = extent * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
    return p;
}

void synthesisTable(int maxRes, int threads) {
    std::printf("## Synthesis (L = 1, tile = 8 L, unit sigma, %s threads)\n\n", threads ? std::to_string(threads).c_str() : "all");
    std::printf("| res | grid MiB | synthesis ms | frame ms (tau > 0) | k_max L | resolved variance | "
                "max shell error | divergence | max |var - 1| |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int res : {32, 64, 128, 256}) {
        if (res > maxRes) break;
        TurbulenceGrid::synthesize(specFor(res), threads); // plan once
        const int repeats = res <= 64 ? 5 : (res <= 128 ? 3 : 1);
        std::shared_ptr<const TurbulenceGrid> g;
        const double t = bestSeconds(repeats, [&] { g = TurbulenceGrid::synthesize(specFor(res), threads); });
        const double tf = bestSeconds(repeats, [&] { TurbulenceGrid::synthesize(specFor(res, 0.5f, 1.25f), threads); });
        TurbulenceSpectrum sp(*g);
        double shellErr = 0.0;
        for (const TurbulenceShell& s : sp.shells(1.0)) shellErr = std::max(shellErr, std::abs(s.measured / s.expected - 1.0));
        double mean[3], var[3];
        turbulenceMoments(*g, mean, var);
        double varErr = 0.0;
        for (double v : var) varErr = std::max(varErr, std::abs(v - 1.0));
        const double kmax = 2.0 * M_PI * g->maxMode() / g->tile();
        std::printf("| %d³ | %.1f | %.1f | %.1f | %.1f | %.1f %% | %.1e | %.1e | %.1e |\n", res, g->bytes() / 1048576.0,
                    t * 1e3, tf * 1e3, kmax, 100.0 / g->energyScale(), shellErr, sp.divergence(), varErr);
    }
    std::printf("\nresolved variance: share of the analytic sigma² the kept modes (1 <= |m| <= res/2 - 1) hold; the\n"
                "grid is rescaled to sigma² exactly, so every resolved mode carries 1/share of its analytic energy.\n"
                "max shell error: |measured/expected - 1| of the shell-averaged spectrum (expected includes that rescale).\n\n");
}

void planningTable(int maxRes, int threads) {
    std::printf("## FFTW planning: Estimate (default, reproducible) vs Measure\n\n");
    std::printf("| res | Estimate synthesis ms | Measure planning ms | Measure synthesis ms |\n|---:|---:|---:|---:|\n");
    for (int res : {64, 128}) {
        if (res > maxRes) break;
        setTurbulenceFftPlanning(FftPlanning::Estimate);
        const double est = bestSeconds(3, [&] { TurbulenceGrid::synthesize(specFor(res), threads); });
        setTurbulenceFftPlanning(FftPlanning::Measure);
        const double plan = seconds([&] { TurbulenceGrid::synthesize(specFor(res), threads); });
        const double meas = bestSeconds(3, [&] { TurbulenceGrid::synthesize(specFor(res), threads); });
        std::printf("| %d³ | %.1f | %.0f | %.1f |\n", res, est * 1e3, (plan - meas) * 1e3, meas * 1e3);
    }
    setTurbulenceFftPlanning(FftPlanning::Estimate);
    std::printf("\n");
}

// The bench's own table: the standard built-ins plus fftturb (fieldFunctions() is the field
// layer's full table; this keeps the benchmark independent of the rest of it).
std::shared_ptr<const runtime::FunctionTable> fieldFunctionsForBench() {
    static auto t = [] {
        auto table = std::make_shared<runtime::FunctionTable>(*runtime::FunctionTable::standard());
        addTurbulenceBuiltins(*table);
        return table;
    }();
    return t;
}

void samplingTable(size_t points) {
    std::printf("## Sampling (%zu random points in 3 tiles³, 1 thread)\n\n", points);
    std::printf("| res | interp | random ns/point | sheet ns/point | VM ns/point | rms error / sigma | "
                "max error / sigma | sampled variance |\n|---:|---|---:|---:|---:|---:|---:|---:|\n");
    const size_t side = static_cast<size_t>(std::sqrt(static_cast<double>(points)));
    for (int res : {32, 64}) {
        auto g = TurbulenceGrid::synthesize(specFor(res));
        const auto pts = randomPoints(points, 24.0, 3);
        // A cloth-like sheet: a tilted square of points in raster order (coherent access).
        std::vector<double> sheet;
        sheet.reserve(3 * side * side);
        for (size_t j = 0; j < side; ++j)
            for (size_t i = 0; i < side; ++i) {
                const double u = 6.0 * i / side, v = 6.0 * j / side;
                sheet.insert(sheet.end(), {1.0 + u, 2.0 + 0.3 * u + 0.8 * v, 0.5 + 0.6 * v});
            }
        std::vector<float> out(3 * points);
        // The exact band-limited field at a few hundred points (a direct Fourier sum).
        TurbulenceSpectrum sp(*g);
        const size_t nExact = res <= 32 ? 400 : 150;
        std::vector<double> exact(3 * nExact);
        for (size_t i = 0; i < nExact; ++i) sp.evaluate(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], &exact[3 * i]);
        for (auto interp : {TurbulenceInterp::Trilinear, TurbulenceInterp::Tricubic}) {
            const double coherent = bestSeconds(3, [&] { g->sampleMany(sheet.data(), side * side, interp, out.data()); });
            const double direct = bestSeconds(3, [&] { g->sampleMany(pts.data(), points, interp, out.data()); });
            double err2 = 0.0, errMax = 0.0, var = 0.0;
            for (size_t i = 0; i < nExact; ++i)
                for (int c = 0; c < 3; ++c) {
                    const double e = out[3 * i + c] - exact[3 * i + c];
                    err2 += e * e;
                    errMax = std::max(errMax, std::abs(e));
                }
            for (size_t i = 0; i < 3 * points; ++i) var += static_cast<double>(out[i]) * out[i];
            // Through the compiler and the block VM (cache lookup per block included).
            const std::string text = "fftturb($P, 1, 1, 1, 8, " + std::to_string(res) + ", " +
                                     (interp == TurbulenceInterp::Trilinear ? "0" : "1") + ")";
            lang::SourceFile src("<bench>", text);
            lang::DiagnosticSink sink;
            runtime::CompileSettings settings;
            settings.variables = runtime::standardVariables();
            settings.functions = fieldFunctionsForBench();
            auto prog = runtime::Program::compile(src, settings, sink);
            double vm = 0.0;
            if (prog) {
                runtime::EvalRequest req;
                req.count = points;
                req.uniforms = {{"t", {0.0}, {}}, {"frame", {1}, {}}, {"fps", {24}, {}}};
                req.varyings = {{"P", 3, pts.data(), 3, 1}};
                runtime::EvalOutput<float> o;
                o.data = out.data();
                o.pointStride = 3;
                o.compStride = 1;
                vm = bestSeconds(3, [&] { runtime::evaluate<float>(*prog, req, o); });
            }
            std::printf("| %d³ | %s | %.1f | %.1f | %.1f | %.2e | %.2e | %.3f |\n", res,
                        interp == TurbulenceInterp::Trilinear ? "trilinear" : "tricubic (Catmull-Rom)",
                        direct / points * 1e9, coherent / (side * side) * 1e9, vm / points * 1e9, std::sqrt(err2 / (3.0 * nExact)), errMax,
                        var / (3.0 * points));
        }
    }
    std::printf("\nrandom: points spread over 3 tiles per axis; sheet: a %zu² cloth-like sheet in raster order;\n"
                "VM: the random points through fftturb() compiled and run by the block VM (float).\n", side);
    std::printf("error: against the exact band-limited field (the Fourier series of the grid) at random points;\n"
                "sampled variance: mean square of the samples (the grid's own is 1) — interpolation smooths.\n\n");
}

} // namespace

int main(int argc, char** argv) {
    const int maxRes = argc > 1 ? std::atoi(argv[1]) : 256;
    const size_t points = argc > 2 ? static_cast<size_t>(std::atoll(argv[2])) : 400000;
    const int threads = argc > 3 ? std::atoi(argv[3]) : 0;
    std::printf("# gale_bench_turbulence %d %zu %d\n\n", maxRes, points, threads);
    synthesisTable(maxRes, threads);
    planningTable(maxRes, threads);
    samplingTable(points);
    return 0;
}
