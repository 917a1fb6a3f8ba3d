// Regressions found by the libFuzzer harnesses (fuzz/, docs/fuzzing.md): each case is an input
// that once crashed, tripped a sanitizer or broke a property, reduced to what reproduces it.
#include "runtime/program.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace gale;
using namespace gale::runtime;

namespace {

// Compiles `text` (standard variables) with or without constant folding; null on errors.
std::shared_ptr<const Program> compileText(const std::string& text, bool fold, std::string& diagnostics) {
    lang::SourceFile src("<fuzz>", text);
    lang::DiagnosticSink sink;
    CompileSettings settings;
    settings.variables = standardVariables();
    settings.fold = fold;
    auto p = Program::compile(src, settings, sink);
    diagnostics = lang::renderDiagnostics(src, sink);
    return p;
}

// The value at one point ($P = (1, 2, 3), $t = 0.5) in double.
std::vector<double> valueAt(const Program& p) {
    const double P[3] = {1, 2, 3};
    EvalRequest req;
    req.uniforms = {{"t", {0.5}, {}}, {"frame", {12}, {}}, {"fps", {24}, {}}};
    req.varyings = {{"P", 3, P, 3, 1}};
    std::vector<double> out(static_cast<size_t>(std::max(p.resultWidth(), 1)));
    EvalOutput<double> o;
    o.data = out.data();
    o.pointStride = p.resultWidth();
    EvalResult r = evaluate<double>(p, req, o);
    INFO(r.error);
    REQUIRE(r.ok);
    return out;
}

} // namespace

// fuzz_compile, examples/05_ice_cape/ice_wind.se compiled without folding: a built-in call's
// constant argument that was emitted as code (not folded) had no stored value, and the compiler
// read Bytecode::constants at index -1 (UBSan: pointer overflow; a garbage read without it).
TEST_CASE("unfolded constant work is uniform, and calls on it compile and agree with folding", "[fuzz][fold]") {
    const std::string text = "dir = norm([1, 2, 2]);\n"
                             "s = abs(sin(3) * 2);\n"
                             "clamp(dir * s, 0, 1) + [$P[0], 0, 0] + curve(sin(1), 0, 0, 1, 1, 1, 1)";
    std::string folded, unfolded;
    auto a = compileText(text, true, folded);
    auto b = compileText(text, false, unfolded);
    INFO(folded << unfolded);
    REQUIRE(a);
    REQUIRE(b);
    // Unfolded, the constant work runs once per call (uniform), never as a Constant register
    // without a value.
    REQUIRE(!b->bytecode().code.empty());
    for (const lang::Instr& in : b->bytecode().code)
        CHECK(b->bytecode().reg(in.dst).lifetime != lang::Lifetime::Constant);
    const std::vector<double> va = valueAt(*a), vb = valueAt(*b);
    REQUIRE(va.size() == 3);
    REQUIRE(vb.size() == 3);
    const double s = std::fabs(std::sin(3.0) * 2.0), c = std::sin(1.0);
    const double want[3] = {std::min(1.0 / 3.0 * s, 1.0) + 1.0 + c, std::min(2.0 / 3.0 * s, 1.0) + c,
                            std::min(2.0 / 3.0 * s, 1.0) + c};
    for (int k = 0; k < 3; ++k) {
        CHECK(va[k] == Approx(want[k]).epsilon(1e-12));
        CHECK(vb[k] == Approx(want[k]).epsilon(1e-12));
    }
}
