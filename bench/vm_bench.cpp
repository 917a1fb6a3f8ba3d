// VM speed against hand-written C++ loops doing the same work on the same points, in the same
// run (so the ratios survive noisy machines), plus float-vs-double error and thread scaling.
// Usage: gale_bench_vm [points=1000000] [repeats=7]
#include "runtime/program.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <thread>

using namespace gale;
using namespace gale::runtime;

namespace {

struct Case {
    const char* name;
    const char* source;
    int width;
    // The same arithmetic written by hand: reads AoS double xyz, writes AoS float results.
    void (*hand)(const double* xyz, float* out, size_t n, float t);
};

void handScalar(const double* xyz, float* out, size_t n, float) {
    for (size_t i = 0; i < n; ++i) {
        const float x = static_cast<float>(xyz[3 * i]), y = static_cast<float>(xyz[3 * i + 1]);
        out[i] = x * 2.0f + std::sin(y) * 0.5f;
    }
}

// d = P - c; r = |d|; n = d/(r+1); w = cross(n, up)*2.5 + n*0.5; clamp(w*exp(-r*0.01) + off, -10, 10) + t*0.1
void handVector(const double* xyz, float* out, size_t n, float t) {
    for (size_t i = 0; i < n; ++i) {
        const float dx = static_cast<float>(xyz[3 * i]) - 1.0f, dy = static_cast<float>(xyz[3 * i + 1]) - 2.0f,
                    dz = static_cast<float>(xyz[3 * i + 2]) - 3.0f;
        const float r = std::sqrt(dx * dx + dy * dy + dz * dz);
        const float inv = r + 1.0f;
        const float nx = dx / inv, ny = dy / inv, nz = dz / inv;
        // cross(n, [0,1,0]) = [-nz, 0, nx]
        const float wx = -nz * 2.5f + nx * 0.5f, wy = 0.0f * 2.5f + ny * 0.5f, wz = nx * 2.5f + nz * 0.5f;
        const float e = std::exp(-r * 0.01f);
        const float o[3] = {wx * e + 0.1f, wy * e, wz * e};
        for (int k = 0; k < 3; ++k) out[3 * i + k] = std::min(std::max(o[k], -10.0f), 10.0f) + t * 0.1f;
    }
}

const Case kCases[] = {
    {"scalar: $P[0]*2.0 + sin($P[1]) * 0.5", "$P[0]*2.0 + sin($P[1]) * 0.5", 1, &handScalar},
    {"vector: ~20 ops (cross, length, exp, clamp)",
     "d = $P - [1, 2, 3]; r = length(d); n = d / (r + 1);\n"
     "w = cross(n, [0, 1, 0]) * 2.5 + n * 0.5;\n"
     "clamp(w * exp(-r * 0.01) + [0.1, 0, 0], -10, 10) + $t * 0.1",
     3, &handVector},
};

double bestSeconds(int repeats, const std::function<void()>& f) {
    double best = 1e30;
    for (int r = 0; r < repeats; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        f();
        auto t1 = std::chrono::steady_clock::now();
        best = std::min(best, std::chrono::duration<double>(t1 - t0).count());
    }
    return best;
}

template <class T>
EvalResult runVm(const Program& p, const std::vector<double>& xyz, size_t n, std::vector<T>& out, int threads) {
    EvalRequest req;
    req.count = n;
    req.threads = threads;
    req.uniforms = {{"t", {0.5}, {}}, {"frame", {12}, {}}, {"fps", {24}, {}}};
    req.varyings = {{"P", 3, xyz.data(), 3, 1}};
    EvalOutput<T> o;
    o.data = out.data();
    o.pointStride = p.resultWidth();
    o.compStride = 1;
    return evaluate<T>(p, req, o);
}

} // namespace

int main(int argc, char** argv) {
    const size_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
    const int repeats = argc > 2 ? std::atoi(argv[2]) : 7;
    std::mt19937_64 rng(42);
    std::vector<double> xyz(3 * n);
    for (double& v : xyz) v = -50.0 + 100.0 * static_cast<double>(rng() >> 11) * 0x1.0p-53;

    std::printf("gale VM benchmark: %zu points in [-50,50]^3, best of %d, block %d lanes, %u hardware threads\n\n", n,
                repeats, kBlockSize, std::thread::hardware_concurrency());
    std::printf("%-46s %10s %10s %10s %8s %10s %9s %12s\n", "expression", "hand ns", "vm f32 ns", "vm f64 ns",
                "f32/hand", "vm 2thr ns", "2t speed", "f32 vs f64");
    for (const Case& c : kCases) {
        lang::SourceFile src("<bench>", c.source);
        lang::DiagnosticSink sink;
        CompileSettings settings;
        settings.variables = standardVariables();
        auto prog = Program::compile(src, settings, sink);
        if (!prog) {
            std::fprintf(stderr, "%s", lang::renderDiagnostics(src, sink).c_str());
            return 1;
        }
        std::vector<float> hand(n * static_cast<size_t>(c.width)), vmF(hand.size());
        std::vector<double> vmD(hand.size());
        const double tHand = bestSeconds(repeats, [&] { c.hand(xyz.data(), hand.data(), n, 0.5f); });
        const double tF = bestSeconds(repeats, [&] { runVm(*prog, xyz, n, vmF, 1); });
        const double tD = bestSeconds(repeats, [&] { runVm(*prog, xyz, n, vmD, 1); });
        const double t2 = bestSeconds(repeats, [&] { runVm(*prog, xyz, n, vmF, 2); });
        // Accuracy: float VM against double VM; and the hand loop must agree with the VM.
        double maxErr = 0, scale = 0, handErr = 0;
        for (size_t i = 0; i < vmD.size(); ++i) {
            maxErr = std::max(maxErr, std::abs(static_cast<double>(vmF[i]) - vmD[i]));
            handErr = std::max(handErr, std::abs(static_cast<double>(hand[i]) - vmD[i]));
            scale = std::max(scale, std::abs(vmD[i]));
        }
        const double ns = 1e9 / static_cast<double>(n);
        std::printf("%-46s %10.2f %10.2f %10.2f %7.2fx %10.2f %8.2fx %12.2e\n", c.name, tHand * ns, tF * ns, tD * ns,
                    tF / tHand, t2 * ns, tF / t2, maxErr / std::max(1.0, scale));
        if (handErr > 1e-3 * std::max(1.0, scale)) {
            std::fprintf(stderr, "hand-written loop disagrees with the VM (max error %g): benchmark invalid\n", handErr);
            return 1;
        }
    }
    std::printf("\nf32/hand: VM float time over the hand-written float loop (lower is better; < 1 beats it).\n"
                "2t speed: 1-thread time over 2-thread time. f32 vs f64: max |float - double| / max(1, max |value|).\n");
    return 0;
}
