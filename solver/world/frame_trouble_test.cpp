// Frame-end trouble (frame_trouble.h) on a strip whose right half is moved away by 0.3 m, so that
// its two middle edges are exactly 4× their rest length (closed form), free, held by pins at both
// ends, and touching a sphere; and vertices placed at known depths inside a sphere.
#include "solver/world/frame_trouble.h"

#include "solver/bodies/cloth.h"

#include <catch2/catch.hpp>

using namespace gale::solver;
using gale::fields::Param;

namespace {

// 11 × 2 vertices, 0.1 m apart along x (vertex j·11 + i at x = 0.1 i, y = 0.1 j); the right half
// (i ≥ 6) moved by +0.3 m: edges 5–6 and 16–17 are 0.4 m for 0.1 m, the diagonals between them
// √(0.4² + 0.1²)/√0.02 = 2.92× (below the limit 3), every other edge at rest.
std::unique_ptr<Cloth> strip(bool pinned) {
    auto c = std::make_unique<Cloth>("strip", makeGrid(1.0, 0.1, 11, 2), ClothMaterial());
    VecX x = c->positions();
    for (int j = 0; j < 2; ++j)
        for (int i = 6; i < 11; ++i) x[3 * (j * 11 + i)] += 0.3;
    c->setPositions(x);
    if (pinned) {
        PinSet all;
        for (int v = 0; v < 22; ++v) all.vertices.push_back(v);
        c->addPins(all);
    }
    return c;
}

Collider sphere(const Vec3& centre, double radius, const char* name) {
    Collider c;
    c.name = name;
    c.shape = ColliderShape::Sphere;
    c.a = Param(std::vector<double>{centre.x(), centre.y(), centre.z()});
    c.radius = radius;
    return c;
}

} // namespace

TEST_CASE("frame trouble: the most stretched edge past the limit, and what forced it",
          "[frame_trouble]") {
    SECTION("free: the solver's") {
        auto c = strip(false);
        std::vector<FrameTrouble> out;
        findFrameTrouble(*c, {}, 0.0, 3.0, out);
        REQUIRE(out.size() == 1);
        const FrameTrouble& t = out[0];
        CHECK(t.kind == FrameTrouble::Kind::OverStretch);
        CHECK(t.amount == Approx(4.0).epsilon(1e-12));
        CHECK(t.count == 2);
        CHECK(((t.vertex == 5 && t.other == 6) || (t.vertex == 16 && t.other == 17)));
        CHECK(t.position.x() == Approx(0.7)); // the midpoint of x = 0.5 and 0.9
        CHECK(t.forcedBy == "the solver");
        CHECK_FALSE(t.scene);
        CHECK(t.text().find("4× its rest length (limit 3×)") != std::string::npos);
        // A limit above 4×: nothing.
        out.clear();
        findFrameTrouble(*c, {}, 0.0, 4.01, out);
        CHECK(out.empty());
    }
    SECTION("pinned at both ends: the scene's") {
        auto c = strip(true);
        std::vector<FrameTrouble> out;
        findFrameTrouble(*c, {}, 0.0, 3.0, out);
        REQUIRE(out.size() == 1);
        CHECK(out[0].forcedBy == "pins");
        CHECK(out[0].scene);
    }
    SECTION("an end touching a collider: the collider's") {
        auto c = strip(false);
        // A sphere whose surface is 2 mm below vertex 5 (x = 0.5, y = 0): within twice its
        // thickness (5 mm), so that the stretched edge is in contact with it.
        const std::vector<Collider> colliders = {sphere(Vec3(0.5, -0.102, 0.0), 0.1, "ball")};
        std::vector<FrameTrouble> out;
        findFrameTrouble(*c, colliders, 0.0, 3.0, out);
        REQUIRE(out.size() == 1); // nothing inside it
        CHECK(out[0].forcedBy == "collider 'ball'");
        CHECK_FALSE(out[0].scene);
    }
}

TEST_CASE("frame trouble: the deepest vertex inside a collider", "[frame_trouble]") {
    // The strip at rest; a sphere of radius 0.2 centred 0.19 m below vertex 0 (x = 0, y = 0):
    // vertex 0 is 10 mm inside, vertex 1 (x = 0.1) √(0.1² + 0.19²) = 0.2147 m from the centre
    // (outside), vertex 11 (y = 0.1) 0.29 m (outside).
    auto c = std::make_unique<Cloth>("strip", makeGrid(1.0, 0.1, 11, 2), ClothMaterial());
    const std::vector<Collider> colliders = {sphere(Vec3(0.0, -0.19, 0.0), 0.2, "ball")};
    std::vector<FrameTrouble> out;
    findFrameTrouble(*c, colliders, 0.0, 3.0, out);
    REQUIRE(out.size() == 1);
    const FrameTrouble& t = out[0];
    CHECK(t.kind == FrameTrouble::Kind::InsideCollider);
    CHECK(t.vertex == 0);
    CHECK(t.amount == Approx(0.01).epsilon(1e-9));
    CHECK(t.count == 1);
    CHECK(t.forcedBy == "collider 'ball'");
    CHECK_FALSE(t.scene);
    // 0.5 mm inside is within the tolerance (kInsideTolerance, 1 mm).
    out.clear();
    findFrameTrouble(*c, {sphere(Vec3(0.0, -0.1995, 0.0), 0.2, "ball")}, 0.0, 3.0, out);
    CHECK(out.empty());
    // Held there by a pin: the scene's.
    PinSet pin;
    pin.vertices = {0};
    c->addPins(pin);
    out.clear();
    findFrameTrouble(*c, colliders, 0.0, 3.0, out);
    REQUIRE(out.size() == 1);
    CHECK(out[0].scene);
    CHECK(out[0].forcedBy.find("pin holding vertex 0") != std::string::npos);
}

// A collider whose step keys jump within the frame (a teleport) forces its trouble as the scene's,
// and says so; looked at over another frame (or with no frame start given), it is the collider's.
TEST_CASE("frame trouble: a collider that jumped into the cloth is the scene's",
          "[frame_trouble]") {
    auto c = strip(false);
    Collider ball = sphere(Vec3(0.0, -0.19, 0.0), 0.2, "ball"); // vertex 0 is 1 cm inside at t = 1
    ball.a = Param::keyed({0.0, 0.5}, {{0.0, -2.0, 0.0}, {0.0, -0.19, 0.0}},
                          gale::fields::KeyInterp::Step);
    std::vector<FrameTrouble> out;
    findFrameTrouble(*c, {ball}, 0.5, 3.0, out, 0.5 - 1.0 / 24.0);
    std::vector<FrameTrouble> inside;
    for (const FrameTrouble& t : out)
        if (t.kind == FrameTrouble::Kind::InsideCollider) inside.push_back(t);
    REQUIRE(inside.size() == 1);
    INFO(inside[0].text());
    CHECK(inside[0].scene);
    CHECK(inside[0].forcedBy.find("jumped 1.81 m at t = 0.5 s") != std::string::npos);
    CHECK(inside[0].text().find("(the scene's: no cloth follows a teleport)") != std::string::npos);
    // The next frame: the jump is behind it.
    out.clear();
    findFrameTrouble(*c, {ball}, 0.5 + 1.0 / 24.0, 3.0, out, 0.5);
    REQUIRE_FALSE(out.empty());
    CHECK_FALSE(out.back().scene);
    CHECK(out.back().forcedBy == "collider 'ball'");
}
