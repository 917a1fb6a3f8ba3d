// Built-in table and kernels: the table's integrity, then math, remap, vector and selection
// kernels called directly through KernelFrame (uniform and varying operands, float and double)
// against values computed by hand or in closed form.
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"
#include "runtime/builtins_testing.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <type_traits>

using namespace gale;
using namespace gale::runtime;
using namespace gale::runtime::testing;

namespace {
constexpr double kPi = 3.14159265358979323846;
const double kNaN = std::numeric_limits<double>::quiet_NaN();
} // namespace

// ---- the table -------------------------------------------------------------------------------

TEST_CASE("standard table: every signature parses, names are unique, kernels exist", "[builtins]") {
    const auto& table = FunctionTable::standard();
    REQUIRE(table->size() > 65);
    std::set<std::string_view> names;
    for (const Builtin& b : table->all()) {
        INFO(b.info.name);
        CHECK(names.insert(b.info.name).second);
        lang::ParsedSignature sig;
        std::string error;
        CHECK(lang::parseSignature(b.info.signature, sig, &error));
        CHECK(error.empty());
        CHECK(b.info.parsed.params.size() == sig.params.size());
        for (const auto& p : sig.params) CHECK(!p.name.empty());
        CHECK(!b.info.doc.empty());
        CHECK(b.info.doc.find('\n') == std::string_view::npos);
        if (b.info.name == "getVar") {
            CHECK(b.kernelF == nullptr);
            CHECK(b.kernelD == nullptr);
            CHECK(!b.info.foldable);
        } else {
            CHECK(b.kernelF != nullptr);
            CHECK(b.kernelD != nullptr);
        }
    }
    CHECK(table.get() == FunctionTable::standard().get());
}

TEST_CASE("standard table: the language's noise built-ins are all there", "[builtins]") {
    // language.md's noise family, plus the curl and flow extensions.
    const char* expected[] = {"snoise", "noise", "vnoise", "cnoise", "snoise4", "vnoise4", "cnoise4", "fbm", "vfbm",
                              "cfbm", "fbm4", "vfbm4", "cfbm4", "turbulence", "vturbulence", "cturbulence",
                              "cellnoise", "ccellnoise", "pnoise", "hash", "voronoi", "cvoronoi", "pvoronoi",
                              "curlnoise", "curlnoise4", "flownoise"};
    const auto& table = FunctionTable::standard();
    for (const char* name : expected) {
        INFO(name);
        CHECK(table->findFunction(name, nullptr) != nullptr);
    }
}

TEST_CASE("standard table: the language's non-noise built-ins are all there", "[builtins]") {
    const char* expected[] = {
        "abs", "acos", "asin", "atan", "atan2", "ceil", "cos", "cosh", "exp", "floor", "fmod", "log", "log10", "pow",
        "sin", "sinh", "sqrt", "tan", "tanh", "cbrt", "asinh", "acosh", "atanh", "trunc", "deg", "rad", "cosd", "sind",
        "tand", "acosd", "asind", "atand", "atan2d", "clamp", "round", "min", "max", "hypot", "sign", "invert",
        "compress", "expand", "fit", "gamma", "bias", "contrast", "boxstep", "linearstep", "smoothstep", "gaussstep",
        "remap", "mix", "length", "dot", "cross", "norm", "angle", "ortho", "rotate", "up", "dist", "cycle", "pick",
        "choose", "wchoose", "spline", "curve", "ccurve", "sprintf", "printf", "getVar", "rgbtohsl", "hsltorgb", "hsi",
        "midhsi", "saturate", "swatch"};
    const auto& table = FunctionTable::standard();
    for (const char* name : expected) {
        INFO(name);
        int32_t index = -1;
        const lang::FunctionInfo* info = table->findFunction(name, &index);
        REQUIRE(info != nullptr);
        CHECK(table->at(index).info.name == name);
    }
    CHECK(table->findFunction("noSuchFunction", nullptr) == nullptr);
    CHECK(table->functionNames().size() == table->size());

    const lang::FunctionInfo* printfInfo = table->findFunction("printf", nullptr);
    CHECK(printfInfo->sideEffects);
    CHECK(!printfInfo->foldable);
    CHECK(table->findFunction("sin", nullptr)->foldable);
    const lang::FunctionInfo* clamp = table->findFunction("clamp", nullptr);
    REQUIRE(clamp->parsed.params.size() == 3);
    CHECK(clamp->parsed.result.width == 0);
    CHECK(clamp->parsed.params[1].name == "lo");
    const lang::FunctionInfo* rotate = table->findFunction("rotate", nullptr);
    CHECK(rotate->parsed.result.width == 3);
    CHECK(rotate->parsed.params[2].width == 1);
}

TEST_CASE("FunctionTable::add replaces by name and rejects bad signatures", "[builtins]") {
    FunctionTable t;
    CHECK(t.add(builtin("sin")));
    CHECK(t.size() == 1);
    Builtin b = builtin("cos");
    b.info.doc = "replaced";
    b.info.name = "sin";
    CHECK(t.add(b));
    CHECK(t.size() == 1);
    CHECK(t.at(0).info.doc == "replaced");
    Builtin bad = builtin("cos");
    bad.info.name = "bad";
    bad.info.signature = "FP[n] bad(FP[n] x";
    std::string error;
    CHECK(!t.add(bad, &error));
    CHECK(!error.empty());
    CHECK(t.size() == 1);
}

// ---- math ------------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("math kernels: C functions and angles", "[builtins]", float, double) {
    using T = TestType;
    checkScalarRows<T>("abs", {{-2.5, 2.5}, {3, 3}, {0, 0}});
    checkScalarRows<T>("sqrt", {{16, 4}, {2, std::sqrt(2.0)}});
    checkScalarRows<T>("cbrt", {{-27, -3}, {8, 2}});
    checkScalarRows<T>("exp", {{0, 1}, {1, 2.718281828459045}});
    checkScalarRows<T>("log", {{1, 0}, {2.718281828459045, 1}});
    checkScalarRows<T>("log10", {{1000, 3}, {0.01, -2}});
    checkScalarRows<T>("pow", {{2, 10, 1024}, {9, 0.5, 3}, {2, -1, 0.5}});
    checkScalarRows<T>("fmod", {{-7, 3, -1}, {7, -3, 1}, {5.5, 2, 1.5}});
    checkScalarRows<T>("floor", {{-1.5, -2}, {1.5, 1}});
    checkScalarRows<T>("ceil", {{-1.5, -1}, {1.2, 2}});
    checkScalarRows<T>("trunc", {{-1.7, -1}, {1.7, 1}});
    checkScalarRows<T>("sin", {{kPi / 6, 0.5}, {0, 0}});
    checkScalarRows<T>("cos", {{kPi / 3, 0.5}, {0, 1}});
    checkScalarRows<T>("tan", {{kPi / 4, 1}});
    checkScalarRows<T>("asin", {{0.5, kPi / 6}});
    checkScalarRows<T>("acos", {{0.5, kPi / 3}});
    checkScalarRows<T>("atan", {{1, kPi / 4}});
    checkScalarRows<T>("atan2", {{1, -1, 3 * kPi / 4}, {-1, 0, -kPi / 2}});
    checkScalarRows<T>("sinh", {{1, (std::exp(1.0) - std::exp(-1.0)) / 2}});
    checkScalarRows<T>("cosh", {{1, (std::exp(1.0) + std::exp(-1.0)) / 2}});
    checkScalarRows<T>("tanh", {{0.5, (std::exp(1.0) - 1) / (std::exp(1.0) + 1)}});
    checkScalarRows<T>("asinh", {{(std::exp(1.0) - std::exp(-1.0)) / 2, 1}});
    checkScalarRows<T>("acosh", {{(std::exp(2.0) + std::exp(-2.0)) / 2, 2}});
    checkScalarRows<T>("atanh", {{0.5, 0.5 * std::log(3.0)}});
    checkScalarRows<T>("deg", {{kPi, 180}, {-kPi / 2, -90}});
    checkScalarRows<T>("rad", {{180, kPi}, {45, kPi / 4}});
    checkScalarRows<T>("cosd", {{60, 0.5}, {180, -1}});
    checkScalarRows<T>("sind", {{30, 0.5}, {-90, -1}});
    checkScalarRows<T>("tand", {{45, 1}});
    checkScalarRows<T>("acosd", {{0.5, 60}});
    checkScalarRows<T>("asind", {{-0.5, -30}});
    checkScalarRows<T>("atand", {{1, 45}});
    checkScalarRows<T>("atan2d", {{1, 1, 45}, {0, -1, 180}, {-1, 0, -90}});
}

TEMPLATE_TEST_CASE("math kernels: clamping, rounding, min/max, hypot, sign", "[builtins]", float, double) {
    using T = TestType;
    checkScalarRows<T>("clamp", {{1.5, 0, 1, 1}, {-2, 0, 1, 0}, {0.25, 0, 1, 0.25}});
    // Half away from zero.
    checkScalarRows<T>("round", {{2.5, 3}, {-2.5, -3}, {1.4, 1}, {-1.6, -2}, {0.5, 1}});
    checkScalarRows<T>("min", {{1, 2, 1}, {-3, 2, -3}});
    checkScalarRows<T>("max", {{1, 2, 2}, {-3, -4, -3}});
    checkScalarRows<T>("hypot", {{3, 4, 5}, {-5, 12, 13}});
    checkScalarRows<T>("sign", {{-2, -1}, {0, 0}, {0.1, 1}});
    // SeExpr2's comparison order for NaN: max(NaN, 1) = 1, max(1, NaN) = NaN.
    KernelCall<T> m(1, 1);
    m.uniform({kNaN}).uniform({1}).run("max");
    CHECK(m.out(0) == T(1));
    KernelCall<T> m2(1, 1);
    m2.uniform({1}).uniform({kNaN}).run("max");
    CHECK(std::isnan(m2.out(0)));
}

TEST_CASE("round is exact half-away-from-zero in double", "[builtins]") {
    checkScalarRows<double>("round", {{0.49999999999999994, 0}, {4503599627370497.0, 4503599627370497.0}});
}

TEMPLATE_TEST_CASE("remap kernels: SeExpr2's formulas", "[builtins]", float, double) {
    using T = TestType;
    checkScalarRows<T>("invert", {{0.25, 0.75}, {2, -1}});
    checkScalarRows<T>("compress", {{0.5, 2, 4, 3}, {0, -1, 1, -1}});
    checkScalarRows<T>("expand", {{3, 2, 4, 0.5}, {1, 2, 2, 0}, {2, 2, 2, 1}});
    checkScalarRows<T>("fit", {{0.5, 0, 1, 10, 20, 15}, {3, 2, 4, 0, -1, -0.5}, {5, 0, 1, 0, 2, 10}});
    checkScalarRows<T>("gamma", {{0.25, 0.5, 0.0625}, {0.25, 2, 0.5}});
    // x^(log b / log 0.5): b = 0.5 is the identity, b = 0.25 squares.
    checkScalarRows<T>("bias", {{0.25, 0.5, 0.25}, {0.25, 0.25, 0.0625}, {0.25, 0.125, 0.015625}});
    // 0.5 bias(1-c, 2x) below 0.5, 1 - 0.5 bias(1-c, 2-2x) above.
    checkScalarRows<T>("contrast", {{0.25, 0.5, 0.25}, {0.25, 0.75, 0.125}, {0.75, 0.75, 0.875}, {0.25, 0, 0.5}});
    checkScalarRows<T>("boxstep", {{0.5, 0.5, 1}, {0.49, 0.5, 0}});
    checkScalarRows<T>("linearstep",
                       {{0.25, 0, 2, 0.125}, {-1, 0, 2, 0}, {3, 0, 2, 1}, {0.25, 2, 0, 0.875}, {1, 1, 1, 1}});
    checkScalarRows<T>("smoothstep", {{0.25, 0, 1, 0.15625}, {0.25, 1, 0, 0.84375}, {-1, 0, 1, 0}, {1, 0, 1, 1},
                                      {0.5, 0.5, 0.5, 1}});
    // 2^(-8 (1-t)^2): t = 0.5 gives 1/4; at t = 0 (x = a) SeExpr2 gives 2^-8, not 0.
    checkScalarRows<T>("gaussstep", {{0.5, 0, 1, 0.25}, {0, 0, 1, 0.00390625}, {1, 0, 1, 1}, {-0.1, 0, 1, 0},
                                     {0.5, 1, 0, 0.25}, {1, 1, 0, 0.00390625}, {1.1, 1, 0, 0}});
    checkScalarRows<T>("mix", {{2, 4, 0.25, 2.5}, {2, 4, 1, 4}});
    // remap(x, source 0, range 1, falloff 1, interp): 1 within +/-1, falling to 0 at +/-2.
    checkScalarRows<T>("remap", {{0.5, 0, 1, 1, 0, 1},
                                 {1.5, 0, 1, 1, 0, 0.5},
                                 {-1.5, 0, 1, 1, 0, 0.5},
                                 {2.5, 0, 1, 1, 0, 0},
                                 {1.25, 0, 1, 1, 1, 0.84375},
                                 {1.5, 0, 1, 1, 2, 0.25},
                                 {1.5, 0, 1, 1, 3, 0.25}, // box (3) is gaussian in SeExpr2
                                 {0.5, 0, -1, 0, 0, 1},   // falloff 0: a box of |range|
                                 {1.5, 0, 1, 0, 0, 0}});
}

TEMPLATE_TEST_CASE("map kernels broadcast a scalar over FP[n] with either stride", "[builtins]", float, double) {
    using T = TestType;
    // clamp(FP[3] varying, FP[1] uniform, FP[3] uniform)
    KernelCall<T> c(4, 3);
    c.varying(3, [](int i, int k) { return (i - 1.5) * (k + 1); }).uniform({0}).uniform({1, 2, 3});
    c.run("clamp");
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) {
            const double x = (i - 1.5) * (k + 1);
            CHECK(c.out(i, k) == near<T>(x < 0 ? 0 : (x > k + 1 ? k + 1 : x)));
        }
    // fit with a mix of varying FP[2] and uniform scalars (the 5-argument strided form).
    KernelCall<T> f(3, 2);
    f.varying(2, [](int i, int k) { return i + 0.5 * k; }).uniform({0}).uniform({2}).varying(1, [](int i, int) {
        return -double(i);
    });
    f.uniform({1, 3});
    f.run("fit");
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 2; ++k) {
            const double x = i + 0.5 * k, a2 = -double(i), b2 = k == 0 ? 1 : 3;
            CHECK(f.out(i, k) == near<T>(a2 + x / 2 * (b2 - a2)));
        }
    // pow: uniform base, varying exponent (the mixed branch of the two-argument map).
    KernelCall<T> p(5, 1);
    p.uniform({2}).varying(1, [](int i, int) { return double(i); }).run("pow");
    for (int i = 0; i < 5; ++i) CHECK(p.out(i) == near<T>(std::pow(2.0, i)));
}

// ---- vectors ---------------------------------------------------------------------------------

namespace {
// Runs a vector built-in on uniform FP[3] arguments (plus extra scalars) and returns the result.
template <class T>
std::vector<double> vecCall(std::string_view name, int outWidth, std::vector<std::vector<double>> args) {
    KernelCall<T> c(1, outWidth);
    for (auto& a : args) c.uniform(a);
    c.run(name);
    std::vector<double> r;
    for (int k = 0; k < outWidth; ++k) r.push_back(double(c.out(0, k)));
    return r;
}
template <class T>
void checkVec(const std::vector<double>& got, std::vector<double> want, double tol = -1) {
    REQUIRE(got.size() == want.size());
    for (size_t k = 0; k < got.size(); ++k) {
        INFO("component " << k);
        if (tol < 0) CHECK(got[k] == near<T>(want[k]));
        else CHECK(got[k] == Approx(want[k]).margin(tol));
    }
}
} // namespace

TEMPLATE_TEST_CASE("vector kernels: closed forms on uniform operands", "[builtins]", float, double) {
    using T = TestType;
    checkVec<T>(vecCall<T>("length", 1, {{3, 4, 12}}), {13});
    checkVec<T>(vecCall<T>("dot", 1, {{1, 2, 3}, {4, -5, 6}}), {12});
    checkVec<T>(vecCall<T>("cross", 3, {{1, 0, 0}, {0, 1, 0}}), {0, 0, 1});
    checkVec<T>(vecCall<T>("cross", 3, {{1, 2, 3}, {4, 5, 6}}), {-3, 6, -3});
    checkVec<T>(vecCall<T>("norm", 3, {{0, 3, 4}}), {0, 0.6, 0.8});
    checkVec<T>(vecCall<T>("norm", 3, {{0, 0, 0}}), {0, 0, 0});
    checkVec<T>(vecCall<T>("angle", 1, {{1, 0, 0}, {0, 2, 0}}), {kPi / 2});
    checkVec<T>(vecCall<T>("angle", 1, {{1, 0, 0}, {-3, 0, 0}}), {kPi});
    checkVec<T>(vecCall<T>("angle", 1, {{0, 0, 0}, {1, 0, 0}}), {0});
    // |v|^2 rounds below v.v here; SeExpr2 would return NaN, we clamp the cosine.
    checkVec<T>(vecCall<T>("angle", 1, {{1, 1, 1}, {1, 1, 1}}), {0}, 1e-3);
    checkVec<T>(vecCall<T>("ortho", 3, {{2, 0, 0}, {0, 3, 0}}), {0, 0, 1});
    checkVec<T>(vecCall<T>("ortho", 3, {{1, 0, 0}, {2, 0, 0}}), {0, 0, 0});
    // rotate: right-handed; the angle goes through float as in SeExpr2 (hence the 1e-7 margin).
    checkVec<T>(vecCall<T>("rotate", 3, {{1, 0, 0}, {0, 0, 1}, {kPi / 2}}), {0, 1, 0}, 1e-7);
    checkVec<T>(vecCall<T>("rotate", 3, {{1, 0, 0}, {0, 0, 2}, {kPi}}), {-1, 0, 0}, 1e-7);
    checkVec<T>(vecCall<T>("rotate", 3, {{0, 0, 1}, {1, 0, 0}, {kPi / 2}}), {0, -1, 0}, 1e-7);
    checkVec<T>(vecCall<T>("rotate", 3, {{1, 2, 3}, {0, 0, 0}, {1}}), {1, 2, 3});
    checkVec<T>(vecCall<T>("rotate", 3, {{1, 1, 0}, {1, 1, 0}, {0.7}}), {1, 1, 0}, 1e-6);
    // up(v, upvec) rotates about norm(upvec x y) by angle(upvec, y); upvec = y leaves v alone.
    checkVec<T>(vecCall<T>("up", 3, {{1, 2, 3}, {0, 5, 0}}), {1, 2, 3});
    // SeExpr2's sense of rotation: y goes to -x for upvec = +x (we keep SeExpr2's numbers).
    checkVec<T>(vecCall<T>("up", 3, {{0, 1, 0}, {1, 0, 0}}), {-1, 0, 0}, 1e-6);
    checkVec<T>(vecCall<T>("up", 3, {{0, 1, 0}, {0, -1, 0}}), {0, -1, 0}, 1e-6);
    checkVec<T>(vecCall<T>("dist", 1, {{1, 2, 3}, {4, 6, 3}}), {5});
    checkVec<T>(vecCall<T>("dist", 1, {{1}, {2}}), {std::sqrt(3.0)}); // scalars promote to FP[3]
    checkVec<T>(vecCall<T>("dist", 1, {{1}, {2}, {3}, {4}, {6}, {3}}), {5});
    // Six coordinates given as FP[2]: per component, as SeExpr2 applies scalar functions.
    checkVec<T>(vecCall<T>("dist", 2, {{0, 1}, {0}, {0}, {3, 1}, {4}, {0, 1}}), {5, std::sqrt(17.0)});
}

TEST_CASE("rotate rounds its angle to float like SeExpr2", "[builtins]") {
    const auto r = vecCall<double>("rotate", 3, {{1, 0, 0}, {0, 0, 1}, {kPi / 2}});
    const double a = double(float(kPi / 2));
    CHECK(r[0] == std::cos(a));
    CHECK(r[1] == std::sin(a));
}

TEMPLATE_TEST_CASE("vector kernels: varying operands, lane by lane", "[builtins]", float, double) {
    using T = TestType;
    const int n = 9;
    auto v = [](int i, int k) { return k == 0 ? i : 2.0 * i; };     // |v| = 3i
    auto w = [](int i, int k) { return k == 2 ? 1.0 : 0.25 * i; }; // varying second vector
    KernelCall<T> len(n, 1);
    len.varying(3, v).run("length");
    KernelCall<T> dot(n, 1);
    dot.varying(3, v).varying(3, w).run("dot");
    KernelCall<T> crs(n, 3);
    crs.varying(3, v).uniform({0, 0, 1}).run("cross");
    KernelCall<T> nrm(n, 3);
    nrm.varying(3, v).run("norm");
    KernelCall<T> rot(n, 3);
    rot.varying(3, v).uniform({0, 0, 1}).varying(1, [](int i, int) { return i * kPi / 8; }).run("rotate");
    KernelCall<T> dst(n, 1);
    dst.varying(3, v).uniform({0, 0, 0}).run("dist");
    for (int i = 0; i < n; ++i) {
        INFO("lane " << i);
        CHECK(len.out(i) == near<T>(3.0 * i));
        CHECK(dot.out(i) == near<T>(0.25 * i * i + 0.5 * i * i + 2.0 * i));
        // (i, 2i, 2i) x (0, 0, 1) = (2i, -i, 0)
        CHECK(crs.out(i, 0) == near<T>(2.0 * i));
        CHECK(crs.out(i, 1) == near<T>(-1.0 * i));
        CHECK(crs.out(i, 2) == near<T>(0));
        if (i == 0) {
            CHECK(nrm.out(i, 0) == T(0));
        } else {
            CHECK(nrm.out(i, 0) == near<T>(1.0 / 3));
            CHECK(nrm.out(i, 2) == near<T>(2.0 / 3));
        }
        const double a = i * kPi / 8, c = std::cos(a), s = std::sin(a);
        CHECK(double(rot.out(i, 0)) == Approx(c * i - s * 2.0 * i).margin(1e-5));
        CHECK(double(rot.out(i, 1)) == Approx(s * i + c * 2.0 * i).margin(1e-5));
        CHECK(rot.out(i, 2) == near<T>(2.0 * i));
        CHECK(dst.out(i) == near<T>(3.0 * i));
    }
}

// ---- selection -------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("cycle wraps integers into [lo, hi]", "[builtins]", float, double) {
    checkScalarRows<TestType>("cycle", {{5, 0, 3, 1}, {-1, 0, 3, 3}, {7, 2, 4, 3}, {1, 3, 2, 3}, {2.7, 0, 1, 0},
                                        {-0.5, 0, 3, 0}, {-5, 1, 3, 2}});
}

TEST_CASE("seHash matches SeExpr2's hash", "[builtins]") {
    // Reference values from an independent (Python) transcription of SeExpr2's algorithm.
    const double cases[][2] = {{0, 0.4832849587507744},     {1, 0.40419923151009696},  {0.3, 0.6423754681931751},
                               {-2.5, 0.6140554488203618},  {17, 0.30419969635647715}, {123.456, 0.08333778755817045},
                               {-0.001, 0.7169001234501834}};
    for (const auto& c : cases) {
        INFO(c[0]);
        CHECK(detail::seHash(&c[0], 1) == c[1]);
    }
}

TEMPLATE_TEST_CASE("pick: hashed index, weights, degenerate ranges", "[builtins]", float, double) {
    using T = TestType;
    // {index, lo, hi, weights..., expected}, from the same independent transcription.
    const std::vector<std::vector<double>> rows = {
        {0.3, 1, 10, 7}, {1, 1, 10, 5}, {-2.5, 1, 10, 7}, {17, 0, 3, 1}, {123.456, -5, 5, -5},
        {0.3, 0, 3, 1, 2, 3, 4, 3}, {7, 0, 3, 0, 5, 3}, {17, 0, 3, 0.5, 0.25, 2},
        {4, 5, 5, 5}, {4, 3, 2, 3}, {0.25, 0, 2, 0, 0, 1, 2}, {99, 0, 2, 0, 0, 1, 2}, {1, 2, 4, 0, 0, 0, 2}};
    for (const auto& row : rows) {
        // The float kernel hashes the float index: only indices exact in float agree.
        if (std::is_same_v<T, float> && double(float(row[0])) != row[0]) continue;
        INFO("pick row index " << row[0] << " size " << row.size());
        KernelCall<T> u(1, 1);
        for (size_t j = 0; j + 1 < row.size(); ++j) u.uniform({row[j]});
        u.run("pick");
        CHECK(double(u.out(0)) == row.back());
        KernelCall<T> v(4, 1);
        for (size_t j = 0; j + 1 < row.size(); ++j) v.varying(1, [&](int, int) { return row[j]; });
        v.run("pick");
        for (int i = 0; i < 4; ++i) CHECK(double(v.out(i)) == row.back());
    }
}

TEMPLATE_TEST_CASE("choose and wchoose", "[builtins]", float, double) {
    using T = TestType;
    checkScalarRows<T>("choose", {{0.5, 10, 20, 30, 20}, {1, 10, 20, 30, 30}, {0, 10, 20, 30, 10},
                                  {-1, 10, 20, 30, 10}, {0.34, 10, 20, 30, 20}, {0.99, 10, 20, 30, 30}});
    KernelCall<T> nan(1, 1);
    nan.uniform({kNaN}).uniform({10}).uniform({20}).run("choose");
    CHECK(nan.out(0) == T(0));
    // A scalar index choosing among FP[3] values (a scalar choice broadcasts).
    KernelCall<T> vec(4, 3);
    vec.varying(1, [](int i, int) { return i / 4.0; }).uniform({1, 2, 3}).uniform({7}).run("choose");
    for (int k = 0; k < 3; ++k) {
        CHECK(vec.out(0, k) == T(k + 1));
        CHECK(vec.out(1, k) == T(k + 1));
        CHECK(vec.out(2, k) == T(7));
        CHECK(vec.out(3, k) == T(7));
    }
    // wchoose: cutoffs 1 and 4 for weights 1, 3.
    checkScalarRows<T>("wchoose", {{0.5, 10, 1, 20, 3, 20}, {0.2, 10, 1, 20, 3, 10}, {0.25, 10, 1, 20, 3, 10},
                                   {0.1, 10, 0, 20, 1, 20}, {0, 10, 0, 20, 1, 20}, {0.9, 10, 1, 20, 0, 10},
                                   {0.5, 10, 0, 20, 0, 10}});
    // A trailing value without weight is ignored; fewer than two pairs give 0 (SeExpr2).
    checkScalarRows<T>("wchoose", {{0.6, 10, 1, 20, 1, 30, 20}, {0.5, 10, 1, 20, 1, 30, 10}});
    checkScalarRows<T>("wchoose", {{0.5, 10, 1, 20, 0}});
}
