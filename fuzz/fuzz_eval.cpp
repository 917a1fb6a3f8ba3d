// libFuzzer harness, differential: compiles the input and, when it compiles, evaluates it on 300
// deterministic points (a full 256-lane block plus a tail) in float and double, per block and
// one point at a time. Block vs per-point must be bit-identical per precision; float vs double
// must agree within a tolerance scaled to the magnitudes involved (docs/fuzzing.md).
#include "lang/diagnostics.h"
#include "runtime/kernel.h"
#include "runtime/program.h"
#include "runtime/vm.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

using namespace gale;

namespace {

constexpr size_t kPoints = 300;          // one full block and a 44-lane tail
constexpr size_t kMaxInstructions = 400; // longer programs are skipped (bounded run time)
constexpr double kTime = 0.375, kFrame = 9.0, kFps = 24.0;
constexpr double kRelTol = 1e-3;         // float vs double, relative to the largest magnitude
constexpr double kPerturb = 1e-4;        // relative perturbation of inputs and constants

// How many inputs reached each check; printed at exit when GALE_FUZZ_STATS is set.
struct Stats {
    size_t inputs = 0, compiled = 0, continuous = 0, comparedPoints = 0, skippedPoints = 0;
    ~Stats() {
        if (std::getenv("GALE_FUZZ_STATS"))
            std::fprintf(stderr,
                         "fuzz_eval stats: %zu inputs, %zu compiled (block vs point), %zu continuous "
                         "(float vs double), %zu point components compared, %zu skipped\n",
                         inputs, compiled, continuous, comparedPoints, skippedPoints);
    }
} gStats;

struct Inputs {
    std::vector<double> P;  // 3 per point, float-representable
    std::vector<double> id; // the point index
    double t = kTime;
};

// A deterministic pseudo-random value in [-1, 1] (splitmix64).
double unitHash(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    x ^= x >> 31;
    return static_cast<double>(x >> 11) / static_cast<double>(1ull << 52) - 1.0;
}

Inputs makeInputs() {
    Inputs in;
    in.P.resize(3 * kPoints);
    in.id.resize(kPoints);
    for (size_t i = 0; i < kPoints; ++i) {
        in.id[i] = static_cast<double>(i);
        for (int k = 0; k < 3; ++k)
            in.P[3 * i + k] = static_cast<float>(4.0 * unitHash(3 * i + k)); // in [-4, 4]
    }
    return in;
}

runtime::EvalRequest request(const Inputs& in, size_t first, size_t count) {
    runtime::EvalRequest r;
    r.count = count;
    r.threads = 1;
    r.uniforms = {{"t", {in.t}, {}}, {"frame", {kFrame}, {}}, {"fps", {kFps}, {}}};
    runtime::VaryingInput p;
    p.name = "P";
    p.width = 3;
    p.data = in.P.data() + 3 * first;
    p.pointStride = 3;
    p.compStride = 1;
    runtime::VaryingInput id;
    id.name = "id";
    id.data = in.id.data() + first;
    r.varyings = {p, id};
    return r;
}

template <class T>
struct Run {
    runtime::EvalResult result;
    std::vector<T> values;
    std::vector<std::string> strings;
};

template <class T>
Run<T> evaluate(const runtime::Program& program, const Inputs& in, size_t first, size_t count) {
    const int width = std::max(program.resultWidth(), 1);
    Run<T> run;
    run.values.assign(count * static_cast<size_t>(width), T(0));
    runtime::EvalOutput<T> out;
    out.data = run.values.data();
    out.pointStride = width;
    out.compStride = 1;
    if (program.resultIsString()) {
        run.strings.assign(count, std::string());
        out.strings = run.strings.data();
    }
    run.result = runtime::evaluate<T>(program, request(in, first, count), out);
    return run;
}

template <class T>
bool sameBits(T a, T b) {
    if (std::isnan(a) && std::isnan(b)) return true; // NaN payloads and signs are not compared
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

[[noreturn]] void fail(const char* what, size_t point, int comp, double a, double b) {
    std::fprintf(stderr, "fuzz_eval: %s at point %zu component %d: %.17g vs %.17g\n", what, point, comp, a, b);
    __builtin_trap();
}

// Block vs one point at a time, in precision T: bit-identical results and the same status.
template <class T>
Run<T> checkBlockVsPoint(const runtime::Program& program, const Inputs& in) {
    Run<T> block = evaluate<T>(program, in, 0, kPoints);
    const int width = std::max(program.resultWidth(), 1);
    for (size_t i = 0; i < kPoints; ++i) {
        Run<T> one = evaluate<T>(program, in, i, 1);
        if (one.result.ok != block.result.ok) fail("block vs point: status differs", i, 0, block.result.ok, one.result.ok);
        if (!block.result.ok) break;
        if (program.resultIsString()) {
            if (one.strings[0] != block.strings[i]) fail("block vs point: string differs", i, 0, 0, 0);
            continue;
        }
        for (int k = 0; k < width; ++k) {
            const T a = block.values[i * width + k], b = one.values[k];
            if (!sameBits(a, b)) fail("block vs point: bits differ", i, k, a, b);
        }
    }
    return block;
}

// True when every instruction is continuous in its operands (no comparisons, branches, floors,
// cell noise, ...): only then is a float rounding error guaranteed not to flip a result.
bool continuousProgram(const runtime::Program& program) {
    static const std::set<std::string> kContinuous = {
        "abs",      "acos",   "asin",   "atan",       "cos",        "cosh",      "exp",    "log",
        "log10",    "pow",    "sin",    "sinh",       "sqrt",       "tan",       "tanh",   "cbrt",
        "asinh",    "acosh",  "atanh",  "deg",        "rad",        "cosd",      "sind",   "tand",
        "acosd",    "asind",  "atand",  "clamp",      "max",        "min",       "hypot",  "invert",
        "compress", "fit",    "gamma",  "bias",       "contrast",   "linearstep", "smoothstep",
        "gaussstep", "mix",   "length", "dot",        "cross",      "norm",      "angle",  "ortho",
        "rotate",   "up",     "dist",   "spline",     "snoise",     "noise",     "vnoise", "cnoise",
        "snoise4",  "vnoise4", "cnoise4"};
    const lang::Bytecode& bc = program.bytecode();
    for (const lang::RegInfo& r : bc.regs)
        if (r.kind == lang::TypeKind::String) return false;
    for (const lang::Instr& in : bc.code) {
        switch (in.op) {
        case lang::Op::Copy: case lang::Op::Neg: case lang::Op::Invert: case lang::Op::Add:
        case lang::Op::Sub: case lang::Op::Mul: case lang::Op::Div: case lang::Op::Pow:
        case lang::Op::Pack:
            break;
        case lang::Op::Index:
            if (!bc.isConstant(in.b)) return false;
            break;
        case lang::Op::Call:
            if (!kContinuous.count(std::string(program.functions().at(in.imm).info.name))) return false;
            break;
        default:
            return false;
        }
    }
    return true;
}

// Runs the program once in double over the first block (or the tail) like the VM does, and
// returns per lane the largest magnitude of any value it computed or read (NaN when a value is
// not finite): the scale float rounding errors are measured against.
std::vector<double> magnitudes(const runtime::Program& program, const Inputs& in, size_t first, int n) {
    const lang::Bytecode& bc = program.bytecode();
    const auto& locs = program.locations();
    std::vector<double> constants(bc.constants.begin(), bc.constants.end());
    std::vector<double> uniform(program.uniformSize() + 1, 0.0);
    std::vector<double> varying(program.varyingSize() + 1, 0.0);
    std::vector<std::string> uniformStrings(program.uniformStrings() + 1);
    std::vector<std::string> varyingStrings(program.varyingStrings() * runtime::kBlockSize + 1);
    std::string messages;
    for (const lang::HostInput& hi : bc.inputs) {
        const runtime::RegLocation& L = locs[static_cast<size_t>(hi.reg)];
        if (hi.name == "P") {
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < n; ++i) varying[L.offset + k * L.compStride + i] = in.P[3 * (first + i) + k];
        } else if (hi.name == "id") {
            for (int i = 0; i < n; ++i) varying[L.offset + i] = in.id[first + i];
        } else {
            uniform[L.offset] = hi.name == "t" ? in.t : hi.name == "frame" ? kFrame : kFps;
        }
    }
    runtime::ExecContext<double> ctx;
    ctx.bc = &bc;
    ctx.functions = &program.functions();
    ctx.locations = locs.data();
    ctx.constants = constants.data();
    ctx.uniform = uniform.data();
    ctx.varying = varying.data();
    ctx.constStrings = bc.strings.data();
    ctx.uniformStrings = uniformStrings.data();
    ctx.varyingStrings = varyingStrings.data();
    ctx.messages = &messages;
    ctx.n = 1;
    for (int32_t i : program.uniformCode()) runtime::execute(bc.code[static_cast<size_t>(i)], ctx);
    ctx.n = n;
    for (int32_t i : program.varyingCode()) runtime::execute(bc.code[static_cast<size_t>(i)], ctx);

    double shared = 1.0;
    for (double v : constants) shared = std::max(shared, std::fabs(v));
    for (double v : uniform) shared = std::isfinite(v) ? std::max(shared, std::fabs(v)) : NAN;
    std::vector<double> lanes(static_cast<size_t>(n), shared);
    for (size_t j = 0; j + 1 < varying.size(); ++j) {
        const int lane = static_cast<int>(j % runtime::kBlockSize);
        if (lane >= n) continue;
        const double v = varying[j];
        lanes[lane] = std::isfinite(v) ? std::max(lanes[lane], std::fabs(v)) : NAN;
    }
    return lanes;
}

bool isWholeNumber(double c) { return std::nearbyint(c) == c; }

// Float vs double on a continuous program. Both runs use the same (float-rounded) constants and
// float-representable inputs, so what differs is rounding inside the computation: a point
// passes when |f - d| <= kRelTol * (largest magnitude met) + 2 * (the change in d when inputs
// and non-integer constants move by kPerturb). Non-finite results are not compared.
void checkFloatVsDouble(const runtime::Program& program, const Inputs& in) {
    auto& constants = const_cast<std::vector<double>&>(program.bytecode().constants);
    const std::vector<double> original = constants;
    for (double& c : constants) c = static_cast<float>(c);
    const std::vector<double> rounded = constants;
    const int width = std::max(program.resultWidth(), 1);

    Run<float> f = evaluate<float>(program, in, 0, kPoints);
    Run<double> d = evaluate<double>(program, in, 0, kPoints);
    std::vector<double> scale = magnitudes(program, in, 0, runtime::kBlockSize);
    const std::vector<double> tail = magnitudes(program, in, runtime::kBlockSize, kPoints - runtime::kBlockSize);
    scale.insert(scale.end(), tail.begin(), tail.end());

    std::vector<double> spread(d.values.size(), 0.0);
    for (int j = 0; j < 4; ++j) {
        Inputs moved = in;
        for (size_t i = 0; i < moved.P.size(); ++i)
            moved.P[i] += kPerturb * (1.0 + std::fabs(moved.P[i])) * unitHash(1000003 * (j + 1) + i);
        moved.t += kPerturb * (1.0 + moved.t) * unitHash(77 + j);
        for (size_t c = 0; c < constants.size(); ++c)
            if (!isWholeNumber(rounded[c])) constants[c] = rounded[c] * (1.0 + kPerturb * unitHash(5000011 * (j + 1) + c));
        Run<double> p = evaluate<double>(program, moved, 0, kPoints);
        constants = rounded;
        for (size_t v = 0; v < spread.size(); ++v) spread[v] = std::max(spread[v], std::fabs(p.values[v] - d.values[v]));
    }
    constants = original;
    if (!f.result.ok || !d.result.ok) return;

    for (size_t i = 0; i < kPoints; ++i) {
        for (int k = 0; k < width; ++k) {
            const size_t v = i * width + k;
            const double fv = f.values[v], dv = d.values[v];
            // Not compared: a non-finite value anywhere, or magnitudes beyond float's range.
            if (!std::isfinite(scale[i]) || scale[i] > 1e30 || !std::isfinite(fv) || !std::isfinite(dv) ||
                !std::isfinite(spread[v])) {
                ++gStats.skippedPoints;
                continue;
            }
            ++gStats.comparedPoints;
            const double tol = kRelTol * scale[i] + 2.0 * spread[v];
            if (std::fabs(fv - dv) > tol) fail("float vs double beyond tolerance", i, k, fv, dv);
        }
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 4096) return 0;
    const lang::SourceFile source("fuzz.se", std::string(reinterpret_cast<const char*>(data), size));
    runtime::CompileSettings settings;
    settings.variables = runtime::standardVariables();
    lang::DiagnosticSink sink;
    std::shared_ptr<const runtime::Program> program = runtime::Program::compile(source, settings, sink);
    ++gStats.inputs;
    if (!program || program->bytecode().code.size() > kMaxInstructions) return 0;
    ++gStats.compiled;

    static const Inputs inputs = makeInputs();
    checkBlockVsPoint<float>(*program, inputs);
    checkBlockVsPoint<double>(*program, inputs);
    if (continuousProgram(*program)) {
        ++gStats.continuous;
        checkFloatVsDouble(*program, inputs);
    }
    return 0;
}
