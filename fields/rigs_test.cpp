// Tests for the wind rigs: gust envelopes in closed form, gust arrival at distance d after
// d / travel_speed (through gust(P) in an expression), keyframed strength carried with the
// front, and the windicator's $windDir / $windSpeed.
#include "fields/expression_field.h"
#include "fields/rigs.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale::fields;

namespace {

std::shared_ptr<ExpressionField> compileWith(const Scene* scene, const std::string& text,
                                             gale::runtime::Precision precision =
                                                 gale::runtime::Precision::Double) {
    gale::lang::SourceFile src("rig.se", text);
    gale::lang::DiagnosticSink sink;
    ExpressionFieldOptions o;
    o.scene = scene;
    o.precision = precision;
    auto f = ExpressionField::compile(src, o, sink);
    if (!f) FAIL(gale::lang::renderDiagnostics(src, sink));
    return f;
}

double xAt(const Field& f, const Vec3& p, double t) {
    double v[3];
    SampleTime when;
    when.time = t;
    REQUIRE(f.sample(p.data(), 1, when, v).ok);
    return v[0];
}

} // namespace

TEST_CASE("gust envelope: smooth attack, hold, smooth decay", "[rigs]") {
    Gust g;
    g.attack = 0.2;
    g.hold = 0.3;
    g.decay = 0.6;
    CHECK(gustEnvelope(g, -0.01) == 0.0);
    CHECK(gustEnvelope(g, 0.0) == 0.0);
    CHECK(gustEnvelope(g, 0.05) == Approx(0.15625));
    CHECK(gustEnvelope(g, 0.1) == Approx(0.5));
    CHECK(gustEnvelope(g, 0.2) == 1.0);
    CHECK(gustEnvelope(g, 0.45) == 1.0);
    CHECK(gustEnvelope(g, 0.8) == Approx(0.5));
    CHECK(gustEnvelope(g, 0.5 + 0.45) == Approx(1 - 0.84375));
    CHECK(gustEnvelope(g, 1.1) == 0.0);
    CHECK(gustEnvelope(g, 50) == 0.0);
    g.attack = 0;
    CHECK(gustEnvelope(g, 0.0) == 1.0);
}

TEST_CASE("a gust reaches distance d after d / travel_speed", "[rigs]") {
    Scene scene;
    scene.windicator = Windicator{};
    scene.windicator->direction = Param(std::vector<double>{0.6, 0, 0.8}); // unit
    Gust g;
    g.start = 0.5;
    g.attack = 0.2;
    g.hold = 0.3;
    g.decay = 0.6;
    g.strength = Param(6.0);
    g.travelSpeed = 8.0;
    scene.gusts.push_back(g);
    for (auto precision : {gale::runtime::Precision::Double, gale::runtime::Precision::Float}) {
        auto f = compileWith(&scene, "gust($P) * [1, 0, 0]", precision);
        const double tol = precision == gale::runtime::Precision::Double ? 1e-9 : 1e-4;
        for (double d : {0.0, 4.0, 16.0, -2.0}) {
            // d metres downwind, plus an offset across the wind that must not matter.
            const Vec3 p{0.6 * d, 3.0, 0.8 * d};
            const double arrival = g.start + d / g.travelSpeed;
            INFO("d = " << d << ", arrival " << arrival);
            CHECK(xAt(*f, p, arrival - 0.01) == 0.0);
            CHECK(xAt(*f, p, arrival + 0.1) == Approx(3.0).margin(tol));  // half-way up
            CHECK(xAt(*f, p, arrival + 0.2) == Approx(6.0).margin(tol));  // full
            CHECK(xAt(*f, p, arrival + 0.5) == Approx(6.0).margin(tol));  // end of hold
            CHECK(xAt(*f, p, arrival + 0.8) == Approx(3.0).margin(tol));  // half-way down
            CHECK(xAt(*f, p, arrival + 1.2) == 0.0);
        }
    }
}

TEST_CASE("gusts sum, and a keyframed strength travels with its front", "[rigs]") {
    Scene scene; // no windicator: gusts travel along +x
    Gust a;
    a.start = 0;
    a.attack = 0;
    a.hold = 100;
    a.strength = Param::keyed({0, 2}, {{0}, {4}}, KeyInterp::Linear);
    a.travelSpeed = 8;
    Gust b = a;
    b.strength = Param(1.0);
    b.start = 1;
    scene.gusts = {a, b};
    auto f = compileWith(&scene, "gust($P)");
    // At x = 8 (1 s downwind) and t = 1.5, gust a left the origin at 0.5 (strength 1);
    // gust b started at 1 and arrives at 2.
    CHECK(xAt(*f, {8, 0, 0}, 1.5) == Approx(1.0));
    CHECK(xAt(*f, {8, 0, 0}, 2.5) == Approx(3.0 + 1.0));
    CHECK(xAt(*f, {0, 0, 0}, 1.5) == Approx(3.0 + 1.0));
}

TEST_CASE("gust() is zero without a rig, and the windicator binds $windDir and $windSpeed", "[rigs]") {
    gale::lang::SourceFile src("g.se", "gust($P) + 1");
    gale::lang::DiagnosticSink sink;
    auto plain = ExpressionField::compile(src, {}, sink);
    REQUIRE(plain);
    CHECK(xAt(*plain, {1, 2, 3}, 4) == 1.0);

    Scene scene;
    scene.windicator = Windicator{};
    scene.windicator->direction = Param::keyed({0, 1}, {{0, 3, 4}, {0, 0, -2}}, KeyInterp::Step);
    scene.windicator->speed = Param::keyed({0, 2}, {{2}, {6}}, KeyInterp::Linear);
    auto f = compileWith(&scene, "$windDir * $windSpeed");
    double v[3];
    const double p[3] = {0, 0, 0};
    SampleTime when;
    when.time = 0.5;
    REQUIRE(f->sample(p, 1, when, v).ok);
    CHECK(v[0] == 0.0);
    CHECK(v[1] == Approx(0.6 * 3));
    CHECK(v[2] == Approx(0.8 * 3));
    when.time = 1.5;
    REQUIRE(f->sample(p, 1, when, v).ok);
    CHECK(v[2] == Approx(-5.0));

    // Without a windicator the variables are not defined (the wind preset falls back to its
    // parameters with getVar).
    Scene none;
    gale::lang::SourceFile uses("u.se", "$windDir");
    gale::lang::DiagnosticSink errors;
    ExpressionFieldOptions o;
    o.scene = &none;
    CHECK_FALSE(ExpressionField::compile(uses, o, errors));

    CHECK(windDirectionAt(Windicator{}, 0) == Vec3{1, 0, 0});
    Windicator zero;
    zero.direction = Param(std::vector<double>{0, 0, 0});
    CHECK(windDirectionAt(zero, 0) == Vec3{0, 0, 0});
}
