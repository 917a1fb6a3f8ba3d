// spline, curve and ccurve kernels against hand-computed Catmull-Rom / Hermite values, for
// constant, uniform and varying control points, in float and double; and their validate hooks.
#include "runtime/builtins.h"
#include "runtime/builtins_testing.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace gale;
using namespace gale::runtime;
using namespace gale::runtime::testing;

namespace {

// curve/ccurve with a uniform param and uniform points; each point is {pos, val..., interp}.
template <class T>
std::vector<double> rampAt(std::string_view name, double param, const std::vector<std::vector<double>>& points,
                           int width = 1) {
    KernelCall<T> c(1, width);
    c.uniform({param});
    for (const auto& p : points) {
        c.uniform({p.front()});
        c.uniform(std::vector<double>(p.begin() + 1, p.end() - 1));
        c.uniform({p.back()});
    }
    c.run(name);
    std::vector<double> r;
    for (int k = 0; k < width; ++k) r.push_back(double(c.out(0, k)));
    return r;
}

template <class T>
double curveAt(double param, const std::vector<std::vector<double>>& points) {
    return rampAt<T>("curve", param, points)[0];
}

} // namespace

// ---- spline ----------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("spline: uniform Catmull-Rom with phantom ends", "[builtins]", float, double) {
    using T = TestType;
    // One segment between y2 = 0 and y3 = 1, tangents (1-0)/2 and (1-0)/2: symmetric, 0.5 at the middle.
    checkScalarRows<T>("spline", {{0.5, 0, 0, 1, 1, 0.5}, {0, 0, 0, 1, 1, 0}, {1, 0, 0, 1, 1, 1}});
    // Two segments through 1, 2, 4; Hermite by hand: tangents 1, 1.5, 3.
    checkScalarRows<T>("spline", {{0.25, 0, 1, 2, 4, 8, 1.4375},
                                  {0.75, 0, 1, 2, 4, 8, 2.8125},
                                  {0, 0, 1, 2, 4, 8, 1},
                                  {0.5, 0, 1, 2, 4, 8, 2},
                                  {1, 0, 1, 2, 4, 8, 4},
                                  {-3, 0, 1, 2, 4, 8, 1},
                                  {7, 0, 1, 2, 4, 8, 4}});
    // FP[3] values with a scalar u.
    KernelCall<T> v(3, 3);
    v.varying(1, [](int i, int) { return 0.25 * (i + 1); });
    for (double y : {0.0, 1.0, 2.0, 4.0, 8.0}) v.uniform({y, 2 * y, -y});
    v.run("spline");
    const double want[3] = {1.4375, 2, 2.8125};
    for (int i = 0; i < 3; ++i) {
        CHECK(v.out(i, 0) == near<T>(want[i]));
        CHECK(v.out(i, 1) == near<T>(2 * want[i]));
        CHECK(v.out(i, 2) == near<T>(-want[i]));
    }
}

// ---- curve -----------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("curve: interpolation codes on constant points", "[builtins]", float, double) {
    using T = TestType;
    // The reference value of the language spec: smooth is 3u^2 - 2u^3.
    CHECK(curveAt<T>(0.25, {{0, 0, 2}, {1, 1, 2}}) == near<T>(0.15625));
    // linear, step, and clamping to the end values outside.
    CHECK(curveAt<T>(0.25, {{0, 0, 1}, {1, 2, 1}}) == near<T>(0.5));
    CHECK(curveAt<T>(0.5, {{0, 3, 0}, {1, 5, 0}}) == near<T>(3));
    CHECK(curveAt<T>(1, {{0, 3, 0}, {1, 5, 0}}) == near<T>(5));
    CHECK(curveAt<T>(-1, {{0, 3, 1}, {1, 5, 1}}) == near<T>(3));
    CHECK(curveAt<T>(2, {{0, 3, 1}, {1, 5, 1}}) == near<T>(5));
    CHECK(curveAt<T>(2, {{0, 3, 3}, {1, 5, 3}}) == near<T>(5));
    // Points in any order: sorted by position.
    CHECK(curveAt<T>(0.25, {{1, 2, 1}, {0, 0, 1}}) == near<T>(0.5));
    CHECK(curveAt<T>(0.75, {{1, 2, 1}, {0.5, 1, 0}, {0, 0, 1}}) == near<T>(1));
    // The LEFT point's code decides: a step after a linear segment.
    CHECK(curveAt<T>(0.25, {{0, 0, 1}, {0.5, 1, 0}, {1, 2, 1}}) == near<T>(0.5));
    CHECK(curveAt<T>(0.75, {{0, 0, 1}, {0.5, 1, 0}, {1, 2, 1}}) == near<T>(1));
    // No points at all (SeExpr2 allows it): 0.
    CHECK(curveAt<T>(0.5, {}) == near<T>(0));
}

TEMPLATE_TEST_CASE("curve: spline and monotone segments", "[builtins]", float, double) {
    using T = TestType;
    // Catmull-Rom slopes: at x=1 (3-0)/2 = 1.5 and at x=2 (3-1)/2 = 1; Hermite at 1.5:
    // 0.5*1 + 0.125*1.5 + 0.5*3 - 0.125*1 = 2.0625.
    const std::vector<std::vector<double>> pts = {{0, 0, 3}, {1, 1, 3}, {2, 3, 3}, {3, 3, 3}};
    CHECK(curveAt<T>(1.5, pts) == near<T>(2.0625));
    CHECK(curveAt<T>(1, pts) == near<T>(1));
    CHECK(curveAt<T>(2, pts) == near<T>(3));
    // The first point's slope sees the phantom end point at -FLT_MAX: (about) zero.
    CHECK(curveAt<T>(0.5, {{0, 0, 3}, {1, 1, 3}, {2, 0, 3}}) == near<T>(0.5));

    // Monotone: on [1, 2] (delta 0.1) the slopes 0.55 and 1 are clamped to 3 * 0.1.
    CHECK(curveAt<T>(1.5, {{0, 0, 4}, {1, 1, 4}, {2, 1.1, 4}, {3, 3, 4}}) == near<T>(1.05));
    // The same points as a plain spline overshoot below 1.
    CHECK(curveAt<T>(1.5, {{0, 0, 3}, {1, 1, 3}, {2, 1.1, 3}, {3, 3, 3}}) == near<T>(0.99375));
    // A flat monotone segment zeroes both slopes, which also flattens the segment before it.
    CHECK(curveAt<T>(0.5, {{0, 0, 4}, {1, 1, 4}, {2, 1, 4}, {3, 2, 4}}) == near<T>(0.5));
    CHECK(curveAt<T>(1.5, {{0, 0, 4}, {1, 1, 4}, {2, 1, 4}, {3, 2, 4}}) == near<T>(1));
    // Only [1, 2] is monotone, but its clamped slope 0.3 at x=1 also shapes the spline segment
    // [0, 1] (Hermite at 0.5: 0.5 * 1 - 0.125 * 0.3), as in SeExpr2; unclamped it would be 0.55.
    CHECK(curveAt<T>(1.5, {{0, 0, 3}, {1, 1, 4}, {2, 1.1, 3}, {3, 3, 3}}) == near<T>(1.05));
    CHECK(curveAt<T>(0.5, {{0, 0, 3}, {1, 1, 4}, {2, 1.1, 3}, {3, 3, 3}}) == near<T>(0.4625));
    CHECK(curveAt<T>(0.5, {{0, 0, 3}, {1, 1, 3}, {2, 1.1, 3}, {3, 3, 3}}) == near<T>(0.43125));
}

TEST_CASE("curve rounds linear/smooth knots to float like SeExpr2", "[builtins]") {
    const float t0 = 0.1f, t1 = 0.2f;
    const float span = t1 - t0;
    CHECK(curveAt<double>(0.15, {{0.1, 0, 1}, {0.2, 1, 1}}) == (0.15 - double(t0)) / double(span));
}

TEMPLATE_TEST_CASE("curve: varying param, uniform and varying points", "[builtins]", float, double) {
    using T = TestType;
    const int n = 9;
    // Constant points, varying param: a smooth ramp from 0 to 1 over [0, 1].
    KernelCall<T> c(n, 1);
    c.varying(1, [](int i, int) { return (i - 1) / 6.0; });
    c.uniform({1}).uniform({1}).uniform({2}).uniform({0}).uniform({0}).uniform({2}); // unsorted
    c.run("curve");
    for (int i = 0; i < n; ++i) {
        double u = (i - 1) / 6.0;
        u = u < 0 ? 0 : (u > 1 ? 1 : u);
        CHECK(c.out(i) == near<T>(u * u * (3 - 2 * u)));
    }
    // Varying second point (position 0.5 + i/4) and varying code (linear, then step).
    KernelCall<T> v(n, 1);
    v.uniform({0.5});
    v.uniform({0}).uniform({0}).varying(1, [](int i, int) { return i < 5 ? 1.0 : 0.0; });
    v.varying(1, [](int i, int) { return 0.5 + i / 4.0; }).uniform({1}).uniform({1});
    v.run("curve");
    for (int i = 0; i < n; ++i) {
        INFO("lane " << i);
        const double want = i == 0 ? 1.0 : (i < 5 ? 0.5 / (0.5 + i / 4.0) : 0.0);
        CHECK(v.out(i) == near<T>(want));
    }
}

TEMPLATE_TEST_CASE("curve: an interpolation code out of range gives 0 at run time", "[builtins]", float, double) {
    CHECK(curveAt<TestType>(0.5, {{0, 1, 7}, {1, 1, 1}}) == 0);
    CHECK(curveAt<TestType>(1.5, {{0, 1, 7}, {1, 2, 1}}) == near<TestType>(2));
}

TEMPLATE_TEST_CASE("ccurve: FP[3] values, scalar values broadcast", "[builtins]", float, double) {
    using T = TestType;
    auto lin = rampAt<T>("ccurve", 0.25, {{0, 0, 0, 0, 1}, {1, 1, 2, 4, 1}}, 3);
    CHECK(lin[0] == near<T>(0.25));
    CHECK(lin[1] == near<T>(0.5));
    CHECK(lin[2] == near<T>(1));
    auto bc = rampAt<T>("ccurve", 0.5, {{0, 0, 1}, {1, 2, 4, 6, 1}}, 3);
    CHECK(bc[0] == near<T>(1));
    CHECK(bc[1] == near<T>(2));
    CHECK(bc[2] == near<T>(3));
    // The spline example scaled per channel by 1, 2, 3.
    auto sp = rampAt<T>("ccurve", 1.5, {{0, 0, 0, 0, 3}, {1, 1, 2, 3, 3}, {2, 3, 6, 9, 3}, {3, 3, 6, 9, 3}}, 3);
    CHECK(sp[0] == near<T>(2.0625));
    CHECK(sp[1] == near<T>(4.125));
    CHECK(sp[2] == near<T>(6.1875));
    // Monotone clamps per channel: channel 1 is flat on [1, 2].
    auto mono = rampAt<T>("ccurve", 1.5, {{0, 0, 0, 0, 4}, {1, 1, 1, 1, 4}, {2, 1.1, 1, 1.1, 4}, {3, 3, 2, 3, 4}}, 3);
    CHECK(mono[0] == near<T>(1.05));
    CHECK(mono[1] == near<T>(1));
    CHECK(mono[2] == near<T>(1.05));
    // Varying param over uniform FP[3] points.
    KernelCall<T> v(5, 3);
    v.varying(1, [](int i, int) { return i / 4.0; });
    v.uniform({0}).uniform({0, 1, 2}).uniform({1});
    v.uniform({1}).uniform({4, 5, 6}).uniform({1});
    v.run("ccurve");
    for (int i = 0; i < 5; ++i)
        for (int k = 0; k < 3; ++k) CHECK(v.out(i, k) == near<T>(k + 4 * (i / 4.0)));
}

// ---- validate hooks --------------------------------------------------------------------------


TEST_CASE("curve and ccurve validate their argument shapes and codes", "[builtins]") {
    {
        Site s("curve", scalars(7), {{}, {0}, {0}, {2}, {1}, {1}, {4}});
        CHECK(s.validate());
        CHECK(!s.sink.hasErrors());
    }
    {
        Site s("curve", scalars(6), {});
        CHECK(!s.validate());
        CHECK(s.sink.errorCount() == 1);
    }
    {
        Site s("curve", scalars(7), {{}, {0}, {0}, {2}, {1}, {1}, {5}});
        CHECK(!s.validate());
        REQUIRE(s.sink.errorCount() == 1);
        CHECK(s.sink.diagnostics()[0].span.begin == s.site.argSpans[6].begin);
    }
    {
        Site s("curve", scalars(4), {{}, {0}, {0}, {-1}});
        CHECK(!s.validate());
    }
    {
        // ccurve: FP[3] or FP[1] values; a vector position or code gives its first component
        // (SeExpr2), a string is an error.
        std::vector<lang::Type> t = scalars(7);
        t[2] = lang::Type::fp(3);
        Site ok("ccurve", t, {});
        CHECK(ok.validate());
        t[4] = lang::Type::fp(3);
        t[6] = lang::Type::fp(2);
        Site vecPos("ccurve", t, {{}, {}, {}, {}, {}, {}, {1, 9}});
        CHECK(vecPos.validate());
        CHECK(!vecPos.sink.hasErrors());
        Site badCode("ccurve", t, {{}, {}, {}, {}, {}, {}, {7, 1}});
        CHECK(!badCode.validate()); // the code is the first component: 7
        t[4] = lang::Type::string(lang::Lifetime::Constant);
        Site bad("ccurve", t, {});
        CHECK(!bad.validate());
        REQUIRE(bad.sink.errorCount() == 1);
        CHECK(bad.sink.diagnostics()[0].span.begin == bad.site.argSpans[4].begin);
        t[4] = lang::Type::fp(1);
        t[5] = lang::Type::fp(2);
        Site bad2("ccurve", t, {});
        CHECK(!bad2.validate());
        REQUIRE(bad2.sink.errorCount() == 1);
        CHECK(bad2.sink.diagnostics()[0].span.begin == bad2.site.argSpans[5].begin);
    }
}

TEST_CASE("dist and wchoose validate hooks", "[builtins]") {
    {
        Site s("dist", {lang::Type::fp(3), lang::Type::fp(1)}, {});
        CHECK(s.validate());
        CHECK(s.site.resultType.isScalar());
    }
    {
        Site s("dist", {lang::Type::fp(2), lang::Type::fp(3)}, {});
        CHECK(!s.validate());
    }
    {
        Site s("dist", scalars(3), {});
        CHECK(!s.validate());
    }
    {
        std::vector<lang::Type> t = scalars(6);
        t[1] = lang::Type::fp(4);
        Site s("dist", t, {});
        CHECK(s.validate());
        CHECK(s.site.resultType.width == 4);
        t[2] = lang::Type::fp(2);
        Site bad("dist", t, {});
        CHECK(!bad.validate());
    }
    {
        Site s("wchoose", scalars(6), {});
        CHECK(s.validate());
        CHECK(!s.sink.hasErrors());
        CHECK(s.sink.diagnostics().size() == 1); // a warning: the last value has no weight
    }
}
