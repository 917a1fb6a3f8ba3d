// Tests for keyframed parameters: constants, linear / smooth (3s^2 - 2s^3) / step curves over
// several segments, clamping outside the keys, and vector values.
#include "fields/keyframes.h"

#include <catch2/catch.hpp>

using namespace gale::fields;

TEST_CASE("constant parameters", "[keyframes]") {
    Param p(2.5);
    CHECK_FALSE(p.isKeyed());
    CHECK(p.width() == 1);
    CHECK(p.scalarAt(-100) == 2.5);
    Param v(std::vector<double>{1, 2, 3});
    CHECK(v.width() == 3);
    CHECK(v.at(7) == std::vector<double>{1, 2, 3});
    CHECK(Param().scalarAt(0) == 0.0);
}

TEST_CASE("linear keys interpolate per segment and clamp outside", "[keyframes]") {
    Param p = Param::keyed({0, 2, 3}, {{0}, {4}, {1}}, KeyInterp::Linear);
    CHECK(p.isKeyed());
    CHECK(p.width() == 1);
    CHECK(p.scalarAt(-1) == 0);
    CHECK(p.scalarAt(0) == 0);
    CHECK(p.scalarAt(0.5) == 1);
    CHECK(p.scalarAt(2) == 4);
    CHECK(p.scalarAt(2.5) == 2.5);
    CHECK(p.scalarAt(3) == 1);
    CHECK(p.scalarAt(10) == 1);
}

TEST_CASE("smooth keys ease in and out with zero tangents", "[keyframes]") {
    Param p = Param::keyed({1, 3}, {{0}, {4}}, KeyInterp::Smooth);
    // s = (t - 1) / 2; value = 4 (3 s^2 - 2 s^3).
    CHECK(p.scalarAt(1.5) == Approx(4 * 0.15625));
    CHECK(p.scalarAt(2) == Approx(2));
    CHECK(p.scalarAt(2.5) == Approx(4 * 0.84375));
    // Zero slope at the keys: a tiny step away changes the value quadratically.
    const double s = 0.5e-4;
    CHECK(p.scalarAt(1 + 1e-4) == Approx(4 * (3 * s * s - 2 * s * s * s)).epsilon(1e-9));
}

TEST_CASE("step keys hold the left key's value", "[keyframes]") {
    Param p = Param::keyed({0, 1, 2}, {{5}, {7}, {9}}, KeyInterp::Step);
    CHECK(p.scalarAt(0.999) == 5);
    CHECK(p.scalarAt(1) == 7);
    CHECK(p.scalarAt(1.5) == 7);
    CHECK(p.scalarAt(2) == 9);
}

TEST_CASE("vector keys interpolate every component", "[keyframes]") {
    Param p = Param::keyed({0, 4}, {{1, 0, 0}, {0, 0, 2}}, KeyInterp::Linear);
    CHECK(p.width() == 3);
    CHECK(p.at(1) == std::vector<double>{0.75, 0, 0.5});
    double out[3];
    p.evaluate(3, out);
    CHECK(out[0] == 0.25);
    CHECK(out[2] == 1.5);
    CHECK(p.scalarAt(2) == 0.5);
}

TEST_CASE("step keys' jumps within a window", "[keyframes]") {
    // Jumps of 5 (3-4-5) at t = 1 and 13 (5-12-13) at t = 2: the largest in (t0, t1], its time.
    Param p = Param::keyed({0, 1, 2}, {{0, 0}, {3, 4}, {-2, -8}}, KeyInterp::Step);
    double at = -1.0;
    CHECK(p.stepJump(0.0, 3.0, &at) == 13.0);
    CHECK(at == 2.0);
    CHECK(p.stepJump(0.5, 1.5, &at) == 5.0);
    CHECK(at == 1.0);
    // A key at the window's start belongs to the window before: (t0, t1].
    CHECK(p.stepJump(1.0, 1.9) == 0.0);
    CHECK(p.stepJump(1.9, 2.0) == 13.0);
    // The same keys eased, and a constant, never jump.
    CHECK(Param::keyed({0, 1, 2}, {{0, 0}, {3, 4}, {-2, -8}}, KeyInterp::Linear).stepJump(0, 3) ==
          0.0);
    CHECK(Param(std::vector<double>{1, 2, 3}).stepJump(0, 3) == 0.0);
}
