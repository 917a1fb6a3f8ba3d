// Tests of what a slice shows as data: the plane's axes, sampling at pixel centres, the speed
// scale, the arrow grid, streamlines of a uniform flow and the framing of geometry, against
// values worked out by hand.
#include "viz/slice_marks.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace gale;

namespace {

viz::Slice uniformSlice(int nu, int nv, float vx, float vy, float vz) {
    viz::Slice s;
    s.nu = nu;
    s.nv = nv;
    s.bounds = {0, 0, 2, 1};
    s.velocity.resize(3 * static_cast<size_t>(nu) * nv);
    for (size_t i = 0; i < s.velocity.size(); i += 3) {
        s.velocity[i] = vx;
        s.velocity[i + 1] = vy;
        s.velocity[i + 2] = vz;
    }
    return s;
}

} // namespace

TEST_CASE("the plane's drawn axes", "[viz][slice]") {
    int u = -1, v = -1;
    viz::planeAxes(2, u, v);
    CHECK((u == 0 && v == 1));
    viz::planeAxes(1, u, v);
    CHECK((u == 0 && v == 2));
    viz::planeAxes(0, u, v);
    CHECK((u == 2 && v == 1));
}

TEST_CASE("a slice samples the field at every pixel centre, top row first", "[viz][slice]") {
    fields::FunctionField where([](const fields::Vec3& x, double) { return x; }, "position");
    viz::Slice s;
    s.nu = 4;
    s.nv = 2;
    s.bounds = {-1, 0, 3, 1};
    s.normalAxis = 1;
    viz::planeAxes(1, s.uAxis, s.vAxis); // u = x, v = z
    s.planeValue = 0.25;
    REQUIRE(viz::sampleSlice(where, {}, s).ok);
    REQUIRE(s.velocity.size() == 24);
    // (row 0, col 1): x = -1 + 1.5 / 4 * 4 = 0.5, z = 1 - 0.5 / 2 * 1 = 0.75, y = the plane.
    CHECK(s.velocity[3] == Approx(0.5));
    CHECK(s.velocity[4] == Approx(0.25));
    CHECK(s.velocity[5] == Approx(0.75));
    // (row 1, col 3): x = 2.5, z = 0.25.
    CHECK(s.velocity[3 * 7] == Approx(2.5));
    CHECK(s.velocity[3 * 7 + 2] == Approx(0.25));

    fields::FunctionField bad(
        [](const fields::Vec3&, double) {
            return fields::Vec3{std::numeric_limits<double>::quiet_NaN(), 0, 0};
        },
        "nan");
    const fields::SampleStatus st = viz::sampleSlice(bad, {}, s);
    CHECK(st.nonFinite == 8);
    CHECK(s.velocity.empty()); // nothing to draw from
}

TEST_CASE("the speed scale", "[viz][slice]") {
    const viz::Slice s = uniformSlice(8, 4, 3, 0, 4);
    viz::SpeedScale a = viz::speedScale(s, 0);
    REQUIRE(a.speed.size() == 32);
    CHECK(a.speed[17] == Approx(5));
    CHECK(a.max == Approx(5));
    CHECK(a.top == Approx(5));                                                  // niceCeil(5) = 5
    CHECK(viz::speedScale(uniformSlice(8, 4, 3.3f, 0, 4), 0).top == Approx(6)); // |v| 5.19 -> 6
    CHECK(viz::speedScale(s, 12).top == 12);
    viz::Slice empty = s;
    empty.velocity.clear();
    CHECK(viz::speedScale(empty, 0).speed.empty());
}

TEST_CASE("arrows sit at grid cell centres with the in-plane velocity", "[viz][slice]") {
    const viz::Slice s = uniformSlice(44, 22, 1, 2, 7); // z = C slice: u = x, v = y
    const viz::ArrowGrid g = viz::sliceArrows(s, 220, 110, 22);
    REQUIRE(g.arrows.size() == 10 * 5);
    CHECK(g.cell == Approx(22));
    CHECK(g.arrows[0].x == Approx(11));
    CHECK(g.arrows[0].y == Approx(11));
    CHECK(g.arrows[13].x == Approx(3.5 * 22));
    CHECK(g.arrows[13].y == Approx(1.5 * 22));
    for (const viz::ArrowMark& a : g.arrows) {
        CHECK(a.vx == Approx(1));
        CHECK(a.vy == Approx(-2)); // v up is pixel y down
        CHECK(a.magnitude == Approx(std::sqrt(5.0)));
    }
    CHECK(g.reference == Approx(std::sqrt(5.0)));
    viz::RenderSettings set;
    CHECK(viz::markSpacing(set, 1100, 500, 1.0) == Approx(50)); // 1100 / 22
    CHECK(viz::markSpacing(set, 220, 110, 1.0) == Approx(26));  // at least 26 px
    set.arrowSpacing = 40;
    CHECK(viz::markSpacing(set, 1100, 500, 1.0) == 40);
}

TEST_CASE("streamlines of a uniform flow are straight and run downstream", "[viz][slice]") {
    const viz::Slice s = uniformSlice(40, 20, 2, 0, 0);
    const std::vector<viz::Polyline> lines = viz::sliceStreamlines(s, 400, 200, 2.0, 30, 1.5);
    REQUIRE(!lines.empty());
    for (const viz::Polyline& l : lines) {
        REQUIRE(l.size() >= 2);
        for (size_t k = 1; k < l.size(); ++k) {
            CHECK(l[k][1] == Approx(l[0][1]).margin(1e-9));
            CHECK(l[k][0] > l[k - 1][0]);
        }
    }
    // A still slice has no direction anywhere.
    double dx, dy;
    CHECK_FALSE(viz::sliceDirection(uniformSlice(4, 4, 0, 0, 0), 40, 40, 1.0, 20, 20, dx, dy));
    CHECK_FALSE(viz::sliceDirection(s, 400, 200, 2.0, -1, 20, dx, dy)); // outside the plot
}

TEST_CASE("geometry is framed with a padding", "[viz][slice]") {
    viz::GeometryOverlay g;
    g.points = {{0, 0, 0}, {1, 2, 5}, {std::numeric_limits<double>::infinity(), 9, 9}};
    std::array<double, 4> b{};
    REQUIRE(viz::geometryBounds({&g}, 0, 1, b));
    // Extent 1 x 2: pad 0.15 * 2 = 0.3 on every side; the infinite point is ignored.
    CHECK(b[0] == Approx(-0.3));
    CHECK(b[1] == Approx(-0.3));
    CHECK(b[2] == Approx(1.3));
    CHECK(b[3] == Approx(2.3));
    viz::GeometryOverlay none;
    CHECK_FALSE(viz::geometryBounds({&none}, 0, 1, b));
}
