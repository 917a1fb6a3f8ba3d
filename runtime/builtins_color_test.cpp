// Colour built-ins (rgbtohsl, hsltorgb, hsi, midhsi, saturate, swatch): kernels called directly
// on uniform and varying operands in float and double against values worked out by hand from
// the HSL formulas, the HSL round trip on many colours, and constant folding of colour calls.
#include "runtime/builtins.h"
#include "runtime/builtins_testing.h"
#include "runtime/program.h"

#include <catch2/catch.hpp>

#include <array>
#include <random>
#include <string>
#include <vector>

using namespace gale;
using namespace gale::runtime;
using namespace gale::runtime::testing;

namespace {

using C3 = std::array<double, 3>;

// One colour argument row: the colour, the scalar arguments, the expected colour.
struct ColorRow {
    C3 color;
    std::vector<double> scalars;
    C3 expected;
};

// Each row as a uniform call, then all rows as the lanes of one varying call.
template <class T>
void checkColorRows(std::string_view name, const std::vector<ColorRow>& rows) {
    for (const ColorRow& row : rows) {
        INFO(name << " row " << row.color[0] << " " << row.color[1] << " " << row.color[2]);
        KernelCall<T> u(1, 3);
        u.uniform({row.color[0], row.color[1], row.color[2]});
        for (double s : row.scalars) u.uniform({s});
        u.run(name);
        for (int k = 0; k < 3; ++k)
            CHECK(u.out(0, k) == near<T>(row.expected[static_cast<size_t>(k)]));
    }
    const int lanes = static_cast<int>(rows.size());
    KernelCall<T> v(lanes, 3);
    v.varying(3, [&](int i, int k) {
        return rows[static_cast<size_t>(i)].color[static_cast<size_t>(k)];
    });
    for (size_t j = 0; j < rows.front().scalars.size(); ++j)
        v.varying(1, [&](int i, int) { return rows[static_cast<size_t>(i)].scalars[j]; });
    v.run(name);
    for (int i = 0; i < lanes; ++i) {
        INFO(name << " lane " << i);
        for (int k = 0; k < 3; ++k)
            CHECK(v.out(i, k) ==
                  near<T>(rows[static_cast<size_t>(i)].expected[static_cast<size_t>(k)]));
    }
}

std::shared_ptr<const Program> compileOrFail(const std::string& text) {
    lang::SourceFile src("<test>", text);
    lang::DiagnosticSink sink;
    CompileSettings settings;
    settings.variables = standardVariables();
    auto p = Program::compile(src, settings, sink);
    INFO(lang::renderDiagnostics(src, sink));
    REQUIRE(p);
    return p;
}

} // namespace

TEMPLATE_TEST_CASE("rgbtohsl: Foley-van Dam, extended outside [0, 1]", "[builtins][color]", float,
                   double) {
    using T = TestType;
    checkColorRows<T>("rgbtohsl", {
                                      // L = 0.4, S = 0.4/0.8, blue largest: H = (-0.5 + 4)/6.
                                      {{0.2, 0.4, 0.6}, {}, {7 / 12.0, 0.5, 0.4}},
                                      // L = 0.7, S = 0.4/(2 - 1.4), red largest: H = 0.5/6.
                                      {{0.9, 0.7, 0.5}, {}, {1 / 12.0, 2 / 3.0, 0.7}},
                                      // Hue wraps: -0.5/6 + 1.
                                      {{1, 0, 0.5}, {}, {11 / 12.0, 1, 0.5}},
                                      // Green largest: H = ((B - R)/1 + 2)/6.
                                      {{0, 1, 0}, {}, {1 / 3.0, 1, 0.5}},
                                      // Grey (spread below 1e-6).
                                      {{0.3, 0.3, 0.3}, {}, {0, 0, 0.3}},
                                      // Outside [0, 1]: S = 1 - min, and S = max.
                                      {{-0.5, 0, 0.5}, {}, {7 / 12.0, 1.5, 0}},
                                      {{1.5, 1, 0.5}, {}, {1 / 12.0, 1.5, 1}},
                                  });
}

TEMPLATE_TEST_CASE("hsltorgb: the inverse, hue wrapping, grey for s <= 0", "[builtins][color]",
                   float, double) {
    using T = TestType;
    checkColorRows<T>("hsltorgb", {
                                      {{7 / 12.0, 0.5, 0.4}, {}, {0.2, 0.4, 0.6}},
                                      {{1 / 12.0, 2 / 3.0, 0.7}, {}, {0.9, 0.7, 0.5}},
                                      {{1.25, 1, 0.5}, {}, {0.5, 1, 0}},
                                      {{-0.75, 1, 0.5}, {}, {0.5, 1, 0}},
                                      {{0.3, 0, 0.7}, {}, {0.7, 0.7, 0.7}},
                                      {{0.3, -2, 0.7}, {}, {0.7, 0.7, 0.7}},
                                      {{7 / 12.0, 1.5, 0}, {}, {-0.5, 0, 0.5}},
                                      {{1 / 12.0, 1.5, 1}, {}, {1.5, 1, 0.5}},
                                  });
}

TEST_CASE("rgbtohsl and hsltorgb invert each other, in and outside [0, 1]", "[builtins][color]") {
    // SeExpr2's documented property: the conversion is reversible for any rgb.
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> d(-0.5, 1.5);
    const int lanes = 200;
    std::vector<C3> colors(lanes);
    for (C3& c : colors) {
        for (double& v : c) v = d(rng);
    }
    KernelCall<double> toHsl(lanes, 3);
    toHsl.varying(
        3, [&](int i, int k) { return colors[static_cast<size_t>(i)][static_cast<size_t>(k)]; });
    toHsl.run("rgbtohsl");
    KernelCall<double> back(lanes, 3);
    back.varying(3, [&](int i, int k) { return toHsl.out(i, k); });
    back.run("hsltorgb");
    for (int i = 0; i < lanes; ++i) {
        INFO("lane " << i);
        CHECK(toHsl.out(i, 0) >= 0);
        CHECK(toHsl.out(i, 0) < 1);
        for (int k = 0; k < 3; ++k)
            CHECK(back.out(i, k) ==
                  Approx(colors[static_cast<size_t>(i)][static_cast<size_t>(k)]).margin(1e-12));
    }
}

TEMPLATE_TEST_CASE("hsi: hue in degrees, saturation and intensity scales, map", "[builtins][color]",
                   float, double) {
    using T = TestType;
    checkColorRows<T>("hsi", {
                                 // +60 degrees: hue 3/4, max 0.6, min 0.2.
                                 {{0.2, 0.4, 0.6}, {60, 1, 1, 1}, {0.4, 0.2, 0.6}},
                                 // Saturation 0.25: max 0.5, min 0.3; intensity 2.
                                 {{0.2, 0.4, 0.6}, {0, 0.5, 2, 1}, {0.6, 0.8, 1.0}},
                                 // map 0.5: h 60, s 0.5, i 1.5.
                                 {{0.2, 0.4, 0.6}, {120, 0, 2, 0.5}, {0.6, 0.45, 0.75}},
                                 // map 0: unchanged.
                                 {{0.2, 0.4, 0.6}, {120, 0, 2, 0}, {0.2, 0.4, 0.6}},
                                 // Red by 120 degrees is green.
                                 {{1, 0, 0}, {120, 1, 1, 1}, {0, 1, 0}},
                                 // Grey stays grey; i still scales.
                                 {{0.5, 0.5, 0.5}, {90, 3, 0.5, 1}, {0.25, 0.25, 0.25}},
                             });
}

TEMPLATE_TEST_CASE("midhsi: map centred on 0.5, both directions, falloff and interp",
                   "[builtins][color]", float, double) {
    using T = TestType;
    checkColorRows<T>("midhsi",
                      {
                          // map 0.5: no change.
                          {{0.2, 0.4, 0.6}, {60, 0.5, 2, 0.5, 1, 0}, {0.2, 0.4, 0.6}},
                          // map 1: hsi(c, 60, 0.5, 2).
                          {{0.2, 0.4, 0.6}, {60, 0.5, 2, 1, 1, 0}, {0.8, 0.6, 1.0}},
                          // map 0: hue -60, saturation / 0.5, intensity / 2.
                          {{0.2, 0.4, 0.6}, {60, 0.5, 2, 0, 1, 0}, {0, 0.4, 0.2}},
                          // map 0.75: m = 0.5.
                          {{0.2, 0.4, 0.6}, {120, 0.5, 2, 0.75, 1, 0}, {0.6, 0.375, 0.825}},
                          // falloff 0.5: m = linearstep(0.75, 0.5, 1) = 0.5 at map 0.875.
                          {{0.2, 0.4, 0.6}, {120, 0.5, 2, 0.875, 0.5, 0}, {0.6, 0.375, 0.825}},
                          // smooth: m = smoothstep(0.25, 0, 1) = 0.15625 at map 0.625.
                          {{0.2, 0.4, 0.6},
                           {120, 0.5, 2, 0.625, 1, 1},
                           {0.215625 * 1.15625, 0.284765625 * 1.15625, 0.584375 * 1.15625}},
                      });
}

TEMPLATE_TEST_CASE("saturate: rec709 luminance mix, negatives clamped", "[builtins][color]", float,
                   double) {
    using T = TestType;
    const double lum = 0.2 * 0.2126 + 0.4 * 0.7152 + 0.6 * 0.0722; // 0.37192
    checkColorRows<T>("saturate", {
                                      {{0.2, 0.4, 0.6}, {0}, {lum, lum, lum}},
                                      {{0.2, 0.4, 0.6}, {1}, {0.2, 0.4, 0.6}},
                                      {{0.2, 0.4, 0.6}, {2}, {0.4 - lum, 0.8 - lum, 1.2 - lum}},
                                      {{1, 0, 0}, {0}, {0.2126, 0.2126, 0.2126}},
                                      {{0, 0, 1}, {0}, {0.0722, 0.0722, 0.0722}},
                                      // 3c - 2 lum with lum = 0.44384: the red goes negative.
                                      {{0.1, 0.5, 0.9}, {3}, {0, 1.5 - 0.88768, 2.7 - 0.88768}},
                                  });
}

TEMPLATE_TEST_CASE("swatch is choose over colours", "[builtins][color]", float, double) {
    using T = TestType;
    checkScalarRows<T>(
        "swatch",
        {{0.5, 10, 20, 30, 20}, {0.33, 10, 20, 30, 10}, {1, 10, 20, 30, 30}, {-1, 10, 20, 30, 10}});
    checkScalarRows<T>("swatch", {{0.5, 10, 20, 20}, {0.49, 10, 20, 10}});
    KernelCall<T> vec(3, 3);
    vec.varying(1, [](int i, int) { return i / 2.0; })
        .uniform({1, 0, 0})
        .uniform({0, 1, 0})
        .uniform({0, 0, 1})
        .run("swatch");
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) CHECK(vec.out(i, k) == T(i == k ? 1 : 0));
}

TEST_CASE("colour calls on constants are folded at compile time", "[builtins][color][fold]") {
    // Each gives [0.4, 0.2, 0.6] (see the kernel tests above), with no instruction left to run.
    const char* cases[] = {"hsi([0.2, 0.4, 0.6], 60, 1, 1)",
                           "midhsi([0.2, 0.4, 0.6], 60, 0.5, 2, 1) / 2 + [0, -0.1, 0.1]",
                           "hsltorgb(rgbtohsl([0.4, 0.2, 0.6]))", "saturate([0.4, 0.2, 0.6], 1)",
                           "swatch(0.5, [0, 0, 0], [0.4, 0.2, 0.6])"};
    for (const char* text : cases) {
        INFO(text);
        auto p = compileOrFail(text);
        CHECK(p->bytecode().code.empty());
        REQUIRE(p->resultWidth() == 3);
        EvalRequest req;
        req.count = 1;
        req.uniforms = {{"t", {0}, {}}, {"frame", {0}, {}}, {"fps", {24}, {}}};
        const double zero[3] = {0, 0, 0};
        req.varyings = {{"P", 3, zero, 3, 1}};
        double out[3] = {-1, -1, -1};
        EvalOutput<double> o;
        o.data = out;
        o.pointStride = 3;
        o.compStride = 1;
        EvalResult r = evaluate<double>(*p, req, o);
        REQUIRE(r.ok);
        CHECK(out[0] == Approx(0.4).margin(1e-12));
        CHECK(out[1] == Approx(0.2).margin(1e-12));
        CHECK(out[2] == Approx(0.6).margin(1e-12));
    }
}

TEST_CASE("an FP[1] colour parameter takes a vector's first component", "[builtins][color]") {
    // hsi's h, s, i, map are FP[1]; a vector gives its first component, as in SeExpr2.
    const auto& info = builtin("hsi").info;
    CHECK(info.firstComponent);
    CHECK(builtin("saturate").info.firstComponent);
    CHECK(builtin("midhsi").info.firstComponent);
    CHECK(builtin("midhsi").info.parsed.minArgs == 5);
    CHECK(builtin("hsi").info.parsed.minArgs == 4);
    CHECK(!builtin("swatch").info.firstComponent);
}
