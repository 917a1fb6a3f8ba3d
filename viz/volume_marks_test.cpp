// Tests of the 3-D marks: arrows sample the field at cell centres, streamlines follow the flow
// (straight in a uniform wind, on circles in a rigid rotation) and stop at the box.
#include "viz/volume_marks.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale;

TEST_CASE("arrow volume samples the field at every cell centre", "[viz][volume]") {
    fields::FunctionField field(
        [](const fields::Vec3& x, double) {
            return fields::Vec3{x[0], 2 * x[1], 0.0};
        },
        "linear");
    viz::Box3 box;
    box.lo = {0, 0, 0};
    box.hi = {1, 2, 4};
    viz::ArrowVolume a;
    REQUIRE(viz::sampleArrowVolume(field, {}, box, 4, a).ok);
    REQUIRE(a.positions.size() == 3 * 64);
    // Cell (1, 2, 3): centre (1.5/4, 2.5/4 * 2, 3.5/4 * 4); x slowest.
    const size_t i = (1 * 4 + 2) * 4 + 3;
    CHECK(a.positions[3 * i] == Approx(0.375));
    CHECK(a.positions[3 * i + 1] == Approx(1.25));
    CHECK(a.positions[3 * i + 2] == Approx(3.5));
    CHECK(a.velocities[3 * i] == Approx(0.375));
    CHECK(a.velocities[3 * i + 1] == Approx(2.5));
    // The largest: the cell nearest (1, 2): (0.875, 2 * 1.75).
    CHECK(a.maxSpeed == Approx(std::hypot(0.875, 3.5)).epsilon(1e-6));
    CHECK_FALSE(viz::sampleArrowVolume(field, {}, box, 0, a).ok);
    CHECK_FALSE(viz::sampleArrowVolume(field, {}, box, 65, a).ok);
}

TEST_CASE("streamlines run straight in a uniform wind and stop at the box", "[viz][volume]") {
    const fields::FieldPtr wind = fields::uniformField({3.0, 0.0, 4.0}); // unit (0.6, 0, 0.8)
    viz::Box3 box;
    viz::Rake rake;
    rake.a = {0, -0.5, 0};
    rake.b = {0, 0.5, 0};
    rake.count = 5;
    viz::StreamlineOptions opt;
    opt.step = 0.1;
    opt.maxSteps = 100;
    std::vector<viz::Streamline> lines;
    REQUIRE(viz::traceRake(*wind, {}, rake, box, opt, lines).ok);
    REQUIRE(lines.size() == 5);
    for (const viz::Streamline& l : lines) {
        // Steps of 0.08 in z from the seed at z = 0: the 13th leaves the box (|z| > 1) and is
        // dropped, so 12 points each way plus the seed.
        REQUIRE(l.points.size() == 25);
        for (size_t k = 1; k < l.points.size(); ++k) {
            const double dx = l.points[k][0] - l.points[k - 1][0],
                         dz = l.points[k][2] - l.points[k - 1][2];
            CHECK(std::hypot(dx, dz) == Approx(0.1).epsilon(1e-5));
            CHECK(dx / dz == Approx(0.75).epsilon(1e-5)); // downstream: the same direction
            CHECK(dz > 0);
        }
        CHECK(l.speed.front() == Approx(5.0));
    }
    // The middle seed sits at the rake's middle.
    CHECK(lines[2].points[13][1] == Approx(0.0).margin(1e-7));
}

TEST_CASE("streamlines of a rigid rotation stay on their circles", "[viz][volume]") {
    fields::FunctionField spin(
        [](const fields::Vec3& x, double) {
            return fields::Vec3{-x[1], x[0], 0.0};
        },
        "spin");
    viz::Box3 box;
    box.lo = {-2, -2, -1};
    box.hi = {2, 2, 1};
    viz::Rake rake;
    rake.a = {0.5, 0, 0};
    rake.b = {1.5, 0, 0};
    rake.count = 3;
    viz::StreamlineOptions opt;
    opt.step = 0.02;
    opt.maxSteps = 100;
    std::vector<viz::Streamline> lines;
    REQUIRE(viz::traceRake(spin, {}, rake, box, opt, lines).ok);
    REQUIRE(lines.size() == 3);
    const double radius[3] = {0.5, 1.0, 1.5};
    for (int s = 0; s < 3; ++s) {
        // RK2's radial drift per step is O(h^3 / r^2); over 100 steps well under 0.1%.
        for (const auto& p : lines[s].points)
            CHECK(std::hypot(p[0], p[1]) == Approx(radius[s]).epsilon(1e-3));
        CHECK(lines[s].speed.front() == Approx(radius[s]).epsilon(1e-3));
    }
    // Counter-clockwise downstream: 100 steps of 0.02 m on the unit circle end at +2 rad, and
    // upstream at -2 rad.
    const auto& last = lines[1].points.back();
    const auto& first = lines[1].points.front();
    CHECK(std::atan2(last[1], last[0]) == Approx(2.0).epsilon(1e-3));
    CHECK(std::atan2(first[1], first[0]) == Approx(-2.0).epsilon(1e-3));
}

TEST_CASE("a still field gives no streamlines; bad rakes are refused", "[viz][volume]") {
    const fields::FieldPtr still = fields::uniformField({0.0, 0.0, 0.0});
    std::vector<viz::Streamline> lines;
    CHECK(viz::traceRake(*still, {}, viz::Rake{}, viz::Box3{}, {}, lines).ok);
    CHECK(lines.empty());
    viz::Rake bad;
    bad.count = 0;
    CHECK_FALSE(viz::traceRake(*still, {}, bad, viz::Box3{}, {}, lines).ok);
}
