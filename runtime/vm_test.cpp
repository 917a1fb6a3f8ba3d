// Properties of the block VM: blocks equal per-point evaluation for any tail length, float
// agrees with double, any thread count gives identical bits, uniform work runs once per call,
// constant work is folded away, and checked evaluation finds the operation that made a NaN.
#include "runtime/program.h"

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstring>
#include <random>
#include <thread>

using namespace gale;
using namespace gale::runtime;

namespace {

std::shared_ptr<const Program> compileOrFail(const std::string& text, CompileSettings settings = {}) {
    lang::SourceFile src("<test>", text);
    lang::DiagnosticSink sink;
    if (settings.variables.empty()) settings.variables = standardVariables();
    auto p = Program::compile(src, settings, sink);
    INFO(lang::renderDiagnostics(src, sink));
    REQUIRE(p);
    return p;
}

struct Points {
    std::vector<double> xyz;
    size_t n = 0;
};

Points randomPoints(size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    Points p;
    p.n = n;
    p.xyz.resize(3 * n);
    for (double& v : p.xyz) v = -50.0 + 100.0 * static_cast<double>(rng() >> 11) * 0x1.0p-53;
    return p;
}

template <class T>
std::vector<T> run(const Program& prog, const Points& pts, int threads = 1, size_t first = 0, size_t count = SIZE_MAX,
                   double t = 0.25) {
    if (count == SIZE_MAX) count = pts.n - first;
    EvalRequest req;
    req.count = count;
    req.threads = threads;
    req.uniforms = {{"t", {t}, {}}, {"frame", {6}, {}}, {"fps", {24}, {}}};
    req.varyings = {{"P", 3, pts.xyz.data() + 3 * first, 3, 1}};
    const int w = prog.resultWidth();
    std::vector<T> out(count * static_cast<size_t>(w));
    EvalOutput<T> o;
    o.data = out.data();
    o.pointStride = w;
    o.compStride = 1;
    EvalResult r = evaluate<T>(prog, req, o);
    INFO(r.error);
    REQUIRE(r.ok);
    return out;
}

// Programs that exercise every opcode family, vectors, branches, built-ins and uniforms.
const char* kPrograms[] = {
    "$P[0]*2.0 + sin($P[1]) * 0.5",
    "dir = norm([1, 0.2, 0.1]); s = 3 + 2*curve(($P[0]*0.1 + $t) % 1, 0,0,4, 0.5,1,4, 1,0,4);\n"
    "dir*s + cross($P*0.01, [0,1,0]) - $P^2*0.001",
    "x = $P[0]; if (x > 0) { y = [x, 1, 2]; } else { y = -x; } y * 2 + $t",
    "a = $P % 7; b = clamp($P / 10, -1, 1); a[1] > 3 ? a : b*[1,2,3]",
    "v = [$P[2], $P[0], $P[1]]; length(v) + dot(v, $P)*0.01 + v[$id % 3]",
    "smoothstep($P[0], -20, 20) * fit($P[1], -50, 50, 0, 1) + mix(1, 2, 0.25)",
    "def f(v, s) { w = v * s; w + 1 } f($P, 0.5) + f($t, 2)",
};

} // namespace

TEST_CASE("block evaluation equals per-point evaluation for any tail length", "[vm]") {
    const Points pts = randomPoints(700, 1);
    for (const char* text : kPrograms) {
        auto prog = compileOrFail(text);
        for (size_t count : {1u, 3u, 255u, 256u, 257u, 511u, 700u}) {
            std::vector<double> block = run<double>(*prog, pts, 1, 0, count);
            const int w = prog->resultWidth();
            for (size_t i = 0; i < count; i += (count > 50 ? 37 : 1)) {
                std::vector<double> one = run<double>(*prog, pts, 1, i, 1);
                // $id is the index within the call, so compare programs that read it at i = 0 only.
                if (std::strstr(text, "$id") && i != 0) continue;
                for (int k = 0; k < w; ++k) {
                    INFO(text << " count " << count << " point " << i << " comp " << k);
                    REQUIRE(std::memcmp(&block[i * static_cast<size_t>(w) + static_cast<size_t>(k)], &one[static_cast<size_t>(k)],
                                        sizeof(double)) == 0);
                }
            }
        }
    }
}

TEST_CASE("float agrees with double within a stated tolerance", "[vm]") {
    // Tolerance: 2e-5 relative to the largest magnitude of the result (float has 24 bits;
    // the programs chain at most ~20 roundings on values up to ~1e3).
    const Points pts = randomPoints(1000, 2);
    for (const char* text : kPrograms) {
        auto prog = compileOrFail(text);
        std::vector<float> f = run<float>(*prog, pts);
        std::vector<double> d = run<double>(*prog, pts);
        double scale = 0, maxErr = 0;
        for (double v : d) scale = std::max(scale, std::abs(v));
        for (size_t i = 0; i < d.size(); ++i) maxErr = std::max(maxErr, std::abs(static_cast<double>(f[i]) - d[i]));
        INFO(text << ": max abs error " << maxErr << ", scale " << scale);
        CHECK(maxErr <= 2e-5 * std::max(1.0, scale));
    }
}

TEST_CASE("any thread count gives bit-identical output", "[vm][threads]") {
    const Points pts = randomPoints(20000, 3);
    for (const char* text : kPrograms) {
        auto prog = compileOrFail(text);
        std::vector<float> one = run<float>(*prog, pts, 1);
        for (int threads : {2, 3, 8}) {
            std::vector<float> many = run<float>(*prog, pts, threads);
            INFO(text << " threads " << threads);
            REQUIRE(std::memcmp(one.data(), many.data(), one.size() * sizeof(float)) == 0);
        }
    }
}

namespace {
std::atomic<long> gCalls{0};
std::atomic<long> gLanes{0};
struct CountingKernel {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        gCalls.fetch_add(1);
        gLanes.fetch_add(f.n);
        for (int i = 0; i < f.n; ++i) f.out[i] = f.args[0].at(0, i) + T(1);
    }
};
} // namespace

TEST_CASE("uniform work runs once per evaluation call, varying work once per block", "[vm]") {
    auto table = std::make_shared<FunctionTable>(*FunctionTable::standard());
    std::string err;
    REQUIRE(table->add(kernelBuiltin<CountingKernel>("counted", "FP[1] counted(FP[1] x)", "x + 1, counting calls"), &err));
    CompileSettings s;
    s.functions = table;
    const Points pts = randomPoints(10 * kBlockSize + 17, 4); // 11 blocks

    auto uniformProg = compileOrFail("counted($t * 2) * $P[0]", s);
    gCalls = 0;
    gLanes = 0;
    std::vector<double> out = run<double>(*uniformProg, pts, 1, 0, SIZE_MAX, 0.25);
    CHECK(gCalls.load() == 1);
    CHECK(gLanes.load() == 1);
    CHECK(out[0] == Approx((0.25 * 2 + 1) * pts.xyz[0]));

    auto constProg = compileOrFail("counted(2) * $P[0]", s);
    gCalls = 0;
    run<double>(*constProg, pts);
    CHECK(gCalls.load() == 0); // folded at compile time

    auto varyingProg = compileOrFail("counted($P[0])", s);
    gCalls = 0;
    gLanes = 0;
    run<double>(*varyingProg, pts, 2);
    CHECK(gCalls.load() == 11);
    CHECK(gLanes.load() == static_cast<long>(pts.n));
}

TEST_CASE("constant work is folded and dead code removed", "[vm][fold]") {
    auto p = compileOrFail("a = sin(1) + 2*3; unused = $P * 100; b = [a, 2, 3]; b * PI");
    CHECK(p->bytecode().code.empty());
    CHECK(p->bytecode().inputs.empty());
    std::vector<double> out = run<double>(*p, randomPoints(3, 5));
    CHECK(out[0] == Approx((std::sin(1.0) + 6) * M_PI).epsilon(1e-15));
    CHECK(out[1] == Approx(2 * M_PI));

    auto q = compileOrFail("x = $P[0] * (2 + 3); x");
    REQUIRE(q->bytecode().code.size() == 1); // one Mul by the folded 5
    CHECK(q->bytecode().code[0].op == lang::Op::Mul);
}

TEST_CASE("checked evaluation names the operation that produced a NaN", "[vm][checked]") {
    const std::string text = "a = $P[0] + 1;\nb = log(a - 100);\nb * 2";
    auto p = compileOrFail(text);
    Points pts = randomPoints(300, 6);
    for (size_t i = 0; i < pts.n; ++i) pts.xyz[3 * i] = 200; // finite everywhere...
    pts.xyz[3 * 123] = 10;                                   // ...but point 123: log(-89)
    EvalRequest req;
    req.count = pts.n;
    req.checked = true;
    req.uniforms = {{"t", {0}, {}}, {"frame", {0}, {}}, {"fps", {24}, {}}};
    req.varyings = {{"P", 3, pts.xyz.data(), 3, 1}};
    std::vector<float> out(pts.n);
    EvalOutput<float> o;
    o.data = out.data();
    EvalResult r = evaluate<float>(*p, req, o);
    REQUIRE(r.ok);
    CHECK(r.nonFinite == 1);
    CHECK(r.firstBadPoint == 123);
    REQUIRE(r.diagnostics.size() == 1);
    lang::SourceFile src("<test>", text);
    CHECK(src.lineCol(r.diagnostics[0].span.begin).line == 2);
    CHECK(src.lineCol(r.diagnostics[0].span.begin).col == 5);
    CHECK(r.diagnostics[0].message.find("'log'") != std::string::npos);
}

TEST_CASE("printf runs only on active lanes and output keeps point order", "[vm][printf]") {
    auto p = compileOrFail("if ($id % 100 == 0) { x = printf(\"p%d\\n\", $id); } else { x = 0; } x");
    const Points pts = randomPoints(1000, 7);
    EvalRequest req;
    req.count = pts.n;
    req.threads = 4;
    req.uniforms = {{"t", {0}, {}}, {"frame", {0}, {}}, {"fps", {24}, {}}};
    req.varyings = {{"P", 3, pts.xyz.data(), 3, 1}};
    std::vector<double> out(pts.n);
    EvalOutput<double> o;
    o.data = out.data();
    EvalResult r = evaluate<double>(*p, req, o);
    REQUIRE(r.ok);
    std::string expected;
    for (int i = 0; i < 1000; i += 100) expected += "p" + std::to_string(i) + "\n";
    CHECK(r.messages == expected);
}

TEST_CASE("a program is evaluated from many threads at once", "[vm][threads]") {
    auto prog = compileOrFail(kPrograms[1]);
    const Points pts = randomPoints(5000, 8);
    std::vector<float> ref = run<float>(*prog, pts);
    std::vector<std::vector<float>> outs(4);
    std::vector<std::thread> threads;
    for (int i = 0; i < 4; ++i)
        threads.emplace_back([&, i] {
            EvalRequest req;
            req.count = pts.n;
            req.uniforms = {{"t", {0.25}, {}}, {"frame", {6}, {}}, {"fps", {24}, {}}};
            req.varyings = {{"P", 3, pts.xyz.data(), 3, 1}};
            outs[static_cast<size_t>(i)].resize(pts.n * 3);
            EvalOutput<float> o;
            o.data = outs[static_cast<size_t>(i)].data();
            o.pointStride = 3;
            evaluate<float>(*prog, req, o);
        });
    for (auto& t : threads) t.join();
    for (const auto& o : outs) REQUIRE(std::memcmp(o.data(), ref.data(), ref.size() * sizeof(float)) == 0);
}
