// Tests for the field combinators: analytic and uniform fields, sums with scales, keyframed
// scales, masks, non-finite repair, and sampling one field from several threads at once.
#include "fields/expression_field.h"
#include "fields/field.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <thread>

using namespace gale::fields;

namespace {

FieldPtr xField() {
    return std::make_shared<FunctionField>([](const Vec3& x, double t) { return Vec3{x[0] * t, 0, 0}; },
                                           "x t");
}

Vec3 at(const Field& f, const Vec3& p, double t) {
    double v[3];
    SampleTime when;
    when.time = t;
    REQUIRE(f.sample(p.data(), 1, when, v).ok);
    return {v[0], v[1], v[2]};
}

} // namespace

TEST_CASE("analytic and uniform fields", "[field]") {
    CHECK(at(*xField(), {3, 1, 1}, 2) == Vec3{6, 0, 0});
    FieldPtr u = uniformField({1, -2, 0.5});
    CHECK(at(*u, {9, 9, 9}, 5) == Vec3{1, -2, 0.5});
    CHECK(u->describe().find("uniform") != std::string::npos);
}

TEST_CASE("sums add scaled terms", "[field]") {
    SumField sum({{uniformField({1, 2, 3}), 2.0}, {xField(), -1.0}});
    CHECK(at(sum, {4, 0, 0}, 0.5) == Vec3{0, 4, 6});
    CHECK(at(SumField({}), {1, 1, 1}, 0) == Vec3{0, 0, 0});
    CHECK(sum.describe().find("sum of 2") == 0);
}

TEST_CASE("keyframed scales and masks", "[field]") {
    ScaledField scaled(uniformField({1, 1, 0}), Param::keyed({0, 1}, {{2}, {3}}, KeyInterp::Step));
    CHECK(at(scaled, {0, 0, 0}, 0.5) == Vec3{2, 2, 0});
    CHECK(at(scaled, {0, 0, 0}, 1.0) == Vec3{3, 3, 0});
    FieldPtr mask = std::make_shared<FunctionField>(
        [](const Vec3& x, double) { double m = x[1] > 0 ? 0.5 : 0.0; return Vec3{m, m, m}; }, "up");
    MaskedField masked(uniformField({4, 2, 8}), mask);
    CHECK(at(masked, {0, 1, 0}, 0) == Vec3{2, 1, 4});
    CHECK(at(masked, {0, -1, 0}, 0) == Vec3{0, 0, 0});
}

TEST_CASE("non-finite velocities become zero and are counted", "[field]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    FunctionField f([nan](const Vec3& x, double) { return x[0] > 0 ? Vec3{1, nan, 2} : Vec3{1, 1, 1}; },
                    "half bad");
    const double pos[9] = {-1, 0, 0, 1, 0, 0, 2, 0, 0};
    double v[9];
    SampleStatus s = f.sample(pos, 3, SampleTime{}, v);
    CHECK(s.ok);
    CHECK(s.nonFinite == 2);
    CHECK(v[3] == 1);
    CHECK(v[4] == 0);
    CHECK(v[5] == 2);
    CHECK(!s.message.empty());
    // A sum passes the count on.
    SumField sum({{std::make_shared<FunctionField>(f), 1.0}});
    CHECK(sum.sample(pos, 3, SampleTime{}, v).nonFinite == 2);
    // A huge scale that overflows is repaired too.
    SumField big({{uniformField({1e300, 0, 0}), 1e300}});
    CHECK(big.sample(pos, 1, SampleTime{}, v).nonFinite == 1);
    CHECK(v[0] == 0);
}

TEST_CASE("one field sampled from several threads at once", "[field]") {
    gale::lang::SourceFile src("f.se", "$k = 2;\n[sin($P[0] * $k + $t), $P[1] * $P[2], $id]\n");
    gale::lang::DiagnosticSink sink;
    ExpressionFieldOptions o;
    o.params["k"] = Param::keyed({0, 1}, {{1}, {3}}, KeyInterp::Linear);
    auto e = ExpressionField::compile(src, o, sink);
    REQUIRE(e);
    SumField sum({{e, 1.0}, {uniformField({1, 0, 0}), 0.5}});
    const size_t n = 5000;
    std::vector<double> pos(3 * n);
    for (size_t i = 0; i < 3 * n; ++i) pos[i] = std::sin(static_cast<double>(i)) * 10;
    std::vector<double> reference(3 * n);
    SampleTime when;
    when.time = 0.25;
    REQUIRE(sum.sample(pos.data(), n, when, reference.data()).ok);
    std::vector<std::vector<double>> results(4, std::vector<double>(3 * n));
    std::vector<std::thread> threads;
    for (int k = 0; k < 4; ++k)
        threads.emplace_back([&, k] {
            SampleTime w = when;
            w.threads = k % 2 ? 2 : 1;
            sum.sample(pos.data(), n, w, results[static_cast<size_t>(k)].data());
        });
    for (std::thread& t : threads) t.join();
    for (const std::vector<double>& r : results) CHECK(r == reference);
    // k(0.25) = 1.5: component 0 of point 3.
    const double want = static_cast<float>(std::sin(static_cast<float>(pos[9]) * 1.5f + 0.25f)) + 0.5;
    CHECK(reference[9] == Approx(want).epsilon(1e-6));
}
