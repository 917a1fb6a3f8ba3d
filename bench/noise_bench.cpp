// Noise speed: the VM's fbm and a wind expression against hand-written scalar C++ (improved
// Perlin noise with permutation-table gradients, no branches) on the same points in the same run,
// float-vs-double error, octaves vs time, and the SIMD levels of the noise core.
// Usage: gale_bench_noise [points=1000000] [repeats=7]
#include "runtime/noise.h"
#include "runtime/program.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace gale;
using namespace gale::runtime;

#define GALE_SCALAR __attribute__((noinline))

namespace {

// ---- The hand-written baseline: Perlin's improved noise (2002) in float --------------------

struct ScalarPerlin {
    int perm[512];
    float grad[16][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                         {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1},
                         {1, 1, 0},  {0, -1, 1}, {-1, 1, 0}, {0, -1, -1}};

    ScalarPerlin() {
        std::vector<int> v(256);
        std::iota(v.begin(), v.end(), 0);
        std::mt19937 rng(2002);
        std::shuffle(v.begin(), v.end(), rng);
        for (int i = 0; i < 512; ++i) perm[i] = v[static_cast<size_t>(i & 255)];
    }
    static float fade(float t) { return t * t * t * (t * (t * 6 - 15) + 10); }
    static float lerp(float t, float a, float b) { return a + t * (b - a); }
    float dot(int h, float x, float y, float z) const {
        const float* g = grad[h & 15];
        return g[0] * x + g[1] * y + g[2] * z;
    }
    float noise(float x, float y, float z) const {
        int ix = static_cast<int>(x), iy = static_cast<int>(y), iz = static_cast<int>(z);
        ix -= x < static_cast<float>(ix);
        iy -= y < static_cast<float>(iy);
        iz -= z < static_cast<float>(iz);
        x -= static_cast<float>(ix);
        y -= static_cast<float>(iy);
        z -= static_cast<float>(iz);
        const int X = ix & 255, Y = iy & 255, Z = iz & 255;
        const float u = fade(x), v = fade(y), w = fade(z);
        const int A = perm[X] + Y, AA = perm[A] + Z, AB = perm[A + 1] + Z;
        const int B = perm[X + 1] + Y, BA = perm[B] + Z, BB = perm[B + 1] + Z;
        return lerp(w,
                    lerp(v, lerp(u, dot(perm[AA], x, y, z), dot(perm[BA], x - 1, y, z)),
                         lerp(u, dot(perm[AB], x, y - 1, z), dot(perm[BB], x - 1, y - 1, z))),
                    lerp(v, lerp(u, dot(perm[AA + 1], x, y, z - 1), dot(perm[BA + 1], x - 1, y, z - 1)),
                         lerp(u, dot(perm[AB + 1], x, y - 1, z - 1), dot(perm[BB + 1], x - 1, y - 1, z - 1))));
    }
    // Σ gain^o noise(P_o), P_{o+1} = P_o * lacunarity + offset.
    float fbm(float x, float y, float z, int octaves, float lac, float gain) const {
        float sum = 0, amp = 1;
        for (int o = 0; o < octaves; ++o) {
            sum += amp * noise(x, y, z);
            x = x * lac + 0.31831f;
            y = y * lac + 0.61803f;
            z = z * lac + 0.14159f;
            amp *= gain;
        }
        return sum;
    }
};

const ScalarPerlin kPerlin;

// fbm(P*0.5, octaves, 2, 0.5) = 0.5 * Σ + 0.5
GALE_SCALAR void handFbm(const double* xyz, float* out, size_t n, int octaves, float) {
    for (size_t i = 0; i < n; ++i) {
        const float x = static_cast<float>(xyz[3 * i]) * 0.5f, y = static_cast<float>(xyz[3 * i + 1]) * 0.5f,
                    z = static_cast<float>(xyz[3 * i + 2]) * 0.5f;
        out[i] = 0.5f * kPerlin.fbm(x, y, z, octaves, 2.0f, 0.5f) + 0.5f;
    }
}

// The curve(u, 0,0,4, 0.5,1,4, 1,0,4) of the wind expression: monotone segments whose slopes
// are all zero, i.e. smoothstep up to 1 at 0.5 and back down to 0 at 1.
float gust(float px, float t) {
    const float a = px * 0.1f + t;
    const float u = a - std::floor(a);
    const float s = u < 0.5f ? u * 2 : (u - 0.5f) * 2;
    const float h = s * s * (3 - 2 * s);
    return u < 0.5f ? h : 1 - h;
}

// dir*(3+2*g) + 0.8*vfbm(P*0.3 + [t,0,0], 3, 2, 0.5), three channels at decorrelating offsets.
GALE_SCALAR void handWind(const double* xyz, float* out, size_t n, int, float t) {
    const float offset[3][3] = {{0, 0, 0}, {31.416f, 47.124f, 12.566f}, {-53.407f, 21.991f, 69.115f}};
    const float dir[3] = {1, 0, 0.2f};
    for (size_t i = 0; i < n; ++i) {
        const float px = static_cast<float>(xyz[3 * i]), py = static_cast<float>(xyz[3 * i + 1]),
                    pz = static_cast<float>(xyz[3 * i + 2]);
        const float g = gust(px, t);
        const float qx = px * 0.3f + t, qy = py * 0.3f, qz = pz * 0.3f;
        for (int k = 0; k < 3; ++k) {
            const float v = kPerlin.fbm(qx + offset[k][0], qy + offset[k][1], qz + offset[k][2], 3, 2.0f, 0.5f);
            out[3 * i + static_cast<size_t>(k)] = dir[k] * (3 + 2 * g) + 0.8f * v;
        }
    }
}

// The same without the noise, to check that the hand loop computes what the VM computes.
GALE_SCALAR void handWindBase(const double* xyz, float* out, size_t n, int, float t) {
    const float dir[3] = {1, 0, 0.2f};
    for (size_t i = 0; i < n; ++i) {
        const float g = gust(static_cast<float>(xyz[3 * i]), t);
        for (int k = 0; k < 3; ++k) out[3 * i + static_cast<size_t>(k)] = dir[k] * (3 + 2 * g);
    }
}

const char* kWind = "dir = [1, 0, 0.2]; g = curve(($P[0] * 0.1 + $t) % 1, 0,0,4, 0.5,1,4, 1,0,4);\n"
                    "dir * (3 + 2 * g) + 0.8 * vfbm($P * 0.3 + [$t, 0, 0], 3, 2, 0.5)";
const char* kWindBase = "dir = [1, 0, 0.2]; g = curve(($P[0] * 0.1 + $t) % 1, 0,0,4, 0.5,1,4, 1,0,4);\n"
                        "dir * (3 + 2 * g)";

// ---- Harness ---------------------------------------------------------------------------------

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

std::shared_ptr<const FunctionTable> noiseTable() {
    auto t = std::make_shared<FunctionTable>(*FunctionTable::standard());
    addNoiseBuiltins(*t);
    return t;
}

std::shared_ptr<const Program> compile(const std::string& text) {
    static const std::shared_ptr<const FunctionTable> table = noiseTable();
    lang::SourceFile src("<bench>", text);
    lang::DiagnosticSink sink;
    CompileSettings settings;
    settings.variables = standardVariables();
    settings.functions = table;
    auto prog = Program::compile(src, settings, sink);
    if (!prog) {
        std::fprintf(stderr, "%s", lang::renderDiagnostics(src, sink).c_str());
        std::exit(1);
    }
    return prog;
}

template <class T>
void runVm(const Program& p, const std::vector<double>& xyz, size_t n, std::vector<T>& out, float t) {
    EvalRequest req;
    req.count = n;
    req.threads = 1;
    req.uniforms = {{"t", {t}, {}}, {"frame", {12}, {}}, {"fps", {24}, {}}};
    req.varyings = {{"P", 3, xyz.data(), 3, 1}};
    EvalOutput<T> o;
    o.data = out.data();
    o.pointStride = p.resultWidth();
    o.compStride = 1;
    const EvalResult r = evaluate<T>(p, req, o);
    if (!r.ok) {
        std::fprintf(stderr, "evaluation failed: %s\n", r.error.c_str());
        std::exit(1);
    }
}

struct Row {
    double hand, vmF, vmD, vmSse42, vmSse2, err;
};

using HandFn = void (*)(const double*, float*, size_t, int, float);

Row measure(const std::string& source, HandFn hand, int octaves, const std::vector<double>& xyz, size_t n, int repeats,
            bool sse2Column) {
    const float t = 0.37f;
    auto prog = compile(source);
    const size_t w = static_cast<size_t>(prog->resultWidth());
    std::vector<float> h(n * w), f(n * w), s(n * w);
    std::vector<double> d(n * w);
    Row r{};
    r.hand = bestSeconds(repeats, [&] { hand(xyz.data(), h.data(), n, octaves, t); });
    r.vmF = bestSeconds(repeats, [&] { runVm(*prog, xyz, n, f, t); });
    r.vmD = bestSeconds(repeats, [&] { runVm(*prog, xyz, n, d, t); });
    if (sse2Column) {
        for (noise::Simd level : {noise::Simd::Sse42, noise::Simd::Sse2}) {
            noise::limitSimd(level);
            (level == noise::Simd::Sse2 ? r.vmSse2 : r.vmSse42) =
                bestSeconds(repeats, [&] { runVm(*prog, xyz, n, s, t); });
            noise::limitSimd(noise::Simd::Avx512);
            if (s != f) {
                std::fprintf(stderr, "%s and %s results differ: determinism broken\n", noise::simdName(level),
                             noise::simdName(noise::simdLevel()));
                std::exit(1);
            }
        }
    }
    double scale = 0;
    for (size_t i = 0; i < d.size(); ++i) {
        r.err = std::max(r.err, std::abs(static_cast<double>(f[i]) - d[i]));
        scale = std::max(scale, std::abs(d[i]));
    }
    r.err /= std::max(1.0, scale);
    return r;
}

} // namespace

int main(int argc, char** argv) {
    const size_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
    const int repeats = argc > 2 ? std::atoi(argv[2]) : 7;
    std::mt19937_64 rng(42);
    std::vector<double> xyz(3 * n);
    for (double& v : xyz) v = -50.0 + 100.0 * static_cast<double>(rng() >> 11) * 0x1.0p-53;
    const double ns = 1e9 / static_cast<double>(n);

    std::printf("gale noise benchmark: %zu points in [-50,50]^3, best of %d, one thread, noise SIMD level %s "
                "(detected %s), %u hardware threads\n\n",
                n, repeats, noise::simdName(noise::simdLevel()), noise::simdName(noise::detectedSimd()),
                std::thread::hardware_concurrency());

    // The hand wind loop must compute what the VM computes (noise aside: different noises).
    {
        auto base = compile(kWindBase);
        std::vector<float> vm(3 * n), hand(3 * n);
        runVm(*base, xyz, n, vm, 0.37f);
        handWindBase(xyz.data(), hand.data(), n, 0, 0.37f);
        double worst = 0;
        for (size_t i = 0; i < vm.size(); ++i) worst = std::max(worst, std::abs(static_cast<double>(vm[i]) - hand[i]));
        if (worst > 1e-4) {
            std::fprintf(stderr, "hand-written wind loop disagrees with the VM (max error %g): benchmark invalid\n", worst);
            return 1;
        }
    }

    std::printf("%-40s %8s %9s %9s %8s %9s %8s %9s %8s %9s\n", "case", "hand ns", "f32 ns", "f64 ns", "f32/hand",
                "SSE4.2 ns", "/hand", "SSE2 ns", "/hand", "f32-f64");
    struct Case {
        const char* name;
        const char* source;
        HandFn hand;
        int octaves;
    };
    const Case cases[] = {{"fbm($P*0.5, 4, 2, 0.5)", "fbm($P * 0.5, 4, 2, 0.5)", &handFbm, 4},
                          {"wind: dir*(3+2*curve) + 0.8*vfbm(..,3)", kWind, &handWind, 3}};
    for (const Case& c : cases) {
        const Row r = measure(c.source, c.hand, c.octaves, xyz, n, repeats, true);
        std::printf("%-40s %8.2f %9.2f %9.2f %7.2fx %9.2f %7.2fx %9.2f %7.2fx %9.2e\n", c.name, r.hand * ns, r.vmF * ns,
                    r.vmD * ns, r.vmF / r.hand, r.vmSse42 * ns, r.vmSse42 / r.hand, r.vmSse2 * ns, r.vmSse2 / r.hand,
                    r.err);
    }

    std::printf("\noctaves vs time, fbm($P*0.5, k, 2, 0.5):\n%-8s %9s %10s %10s %9s %10s\n", "octaves", "hand ns",
                "vm f32 ns", "vm f64 ns", "f32/hand", "f32 vs f64");
    for (int k = 1; k <= 8; ++k) {
        const Row r = measure("fbm($P * 0.5, " + std::to_string(k) + ", 2, 0.5)", &handFbm, k, xyz, n, repeats, false);
        std::printf("%-8d %9.2f %10.2f %10.2f %8.2fx %10.2e\n", k, r.hand * ns, r.vmF * ns, r.vmD * ns, r.vmF / r.hand,
                    r.err);
    }

    // The noise core alone (no VM): one 3D gradient noise per point, at each SIMD level.
    {
        std::vector<float> x(n), y(n), z(n), out(n);
        for (size_t i = 0; i < n; ++i) {
            x[i] = static_cast<float>(xyz[3 * i]);
            y[i] = static_cast<float>(xyz[3 * i + 1]);
            z[i] = static_cast<float>(xyz[3 * i + 2]);
        }
        const uint32_t seed = noise::channelSeed(0);
        float* o[1] = {out.data()};
        const double hand = bestSeconds(repeats, [&] {
            for (size_t i = 0; i < n; ++i) out[i] = kPerlin.noise(x[i], y[i], z[i]);
        });
        std::printf("\nnoise core, one 3D octave per point (float): hand-written scalar Perlin %.2f ns", hand * ns);
        for (int level = 0; level <= static_cast<int>(noise::detectedSimd()); ++level) {
            noise::limitSimd(static_cast<noise::Simd>(level));
            const double t = bestSeconds(repeats, [&] {
                noise::gradient3<float>(static_cast<int>(n), x.data(), y.data(), z.data(), 1, &seed, o);
            });
            std::printf(", %s %.2f ns (%.2fx)", noise::simdName(static_cast<noise::Simd>(level)), t * ns, t / hand);
        }
        noise::limitSimd(noise::Simd::Avx512);
        std::printf("\n");
    }

    std::printf("\nf32/hand: VM float time (noise core at the detected SIMD level) over the hand-written scalar float\n"
                "loop; lower is better, target <= 0.5. SSE4.2, SSE2: the VM float time with the noise core held to\n"
                "that level (SSE2 is what any x86-64 runs). f32-f64: max |float - double| / max(1, max |value|).\n");
    return 0;
}
