// Colliders: signed distances, no penetration when cloth drapes over a sphere or hair over a
// capsule, Coulomb friction on an incline (slides with a = g(sin θ − μ cos θ) when μ < tan θ,
// sticks otherwise), and keyframed colliders carrying cloth along.
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/bodies/hair.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale::solver;
using namespace gale::solver::testing;
using gale::fields::Param;

namespace {

Collider sphere(const Vec3& c, double r) {
    Collider k;
    k.shape = ColliderShape::Sphere;
    k.a = Param(std::vector<double>{c.x(), c.y(), c.z()});
    k.radius = r;
    return k;
}

ClothMaterial stillAirCloth(double sigma) {
    ClothMaterial m;
    m.density = sigma;
    m.lift.value = Param(0.0);
    m.drag.value = Param(0.0);
    return m;
}

} // namespace

TEST_CASE("colliders: signed distances and normals", "[collider]") {
    Collider p;
    p.shape = ColliderShape::Plane;
    p.a = Param(std::vector<double>{0, 1, 0});
    p.normal = Param(std::vector<double>{0, 2, 0});
    ContactPoint c = queryCollider(colliderPose(p, 0), Vec3(3, 0.5, 1));
    CHECK(c.distance == Approx(-0.5));
    CHECK(c.normal.isApprox(Vec3::UnitY()));
    c = queryCollider(colliderPose(sphere(Vec3(1, 0, 0), 0.5), 0), Vec3(1, 2, 0));
    CHECK(c.distance == Approx(1.5));
    Collider cap;
    cap.shape = ColliderShape::Capsule;
    cap.a = Param(std::vector<double>{0, 0, 0});
    cap.b = Param(std::vector<double>{0, 0, 2});
    cap.radius = 0.25;
    c = queryCollider(colliderPose(cap, 0), Vec3(1, 0, 1));
    CHECK(c.distance == Approx(0.75));
    CHECK(c.normal.isApprox(Vec3::UnitX()));
    c = queryCollider(colliderPose(cap, 0), Vec3(0, 0, 3));
    CHECK(c.distance == Approx(0.75));
    // A keyframed centre moves, and its velocity is reported.
    Collider mv = sphere(Vec3::Zero(), 0.5);
    mv.a = Param::keyed({0.0, 1.0}, {{0, 0, 0}, {0, 2, 0}}, gale::fields::KeyInterp::Linear);
    c = queryCollider(colliderPose(mv, 0.5), Vec3(0, 3, 0));
    CHECK(c.distance == Approx(1.5));
    CHECK(c.velocity.y() == Approx(2.0));
}

TEST_CASE("colliders: cloth draped over a sphere does not pass through", "[collider]") {
    TriMesh mesh = makeGrid(1.2, 1.2, 16, 16, Vec3(-0.6, 0.6, -0.6), Vec3::UnitX(), Vec3::UnitZ());
    World w(WorldSettings{});
    w.addBody(std::make_unique<Cloth>("sheet", mesh, stillAirCloth(0.1)));
    Collider s = sphere(Vec3::Zero(), 0.4);
    s.thickness = 0.01;
    w.addCollider(s);
    int contacts = 0;
    for (int f = 1; f <= 36; ++f) {
        const FrameStats fs = w.advanceFrame(f);
        REQUIRE_FALSE(fs.failed);
        contacts = fs.bodies[0].contacts;
        const VecX& x = w.bodies()[0]->positions();
        double minDist = 1e9;
        for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i) minDist = std::min(minDist, vec3At(x.data(), i).norm());
        CHECK(minDist >= 0.4 + 0.01 - 1e-9);
    }
    INFO("center " << vec3At(w.bodies()[0]->positions().data(), 8 * 16 + 8).transpose());
    CHECK(contacts > 10);
    // Draped: the corners fell well below the top of the sphere.
    CHECK(w.bodies()[0]->positions()[1] < 0.0);
}

TEST_CASE("colliders: Coulomb friction on an incline", "[collider]") {
    const double theta = 30.0 * 3.14159265358979323846 / 180.0, g = 9.81, T = 0.5;
    const Vec3 normal(-std::sin(theta), std::cos(theta), 0.0);
    const Vec3 down(-std::cos(theta), -std::sin(theta), 0.0); // along the slope, downhill
    for (double mu : {0.2, 0.4, 0.8}) {
        Collider plane;
        plane.shape = ColliderShape::Plane;
        plane.a = Param(std::vector<double>{0, 0, 0});
        plane.normal = Param(std::vector<double>{normal.x(), normal.y(), normal.z()});
        plane.friction = mu;
        plane.thickness = 0.0;
        // A small patch lying on the plane.
        const Vec3 u = -down, v = Vec3::UnitZ();
        TriMesh mesh = makeGrid(0.1, 0.1, 3, 3, Vec3::Zero(), u, v);
        ClothMaterial m = stillAirCloth(0.1);
        m.stretch = Param(1e4);
        WorldSettings ws;
        ws.gravity = Vec3(0, -g, 0);
        ws.substeps = 8;
        World w(ws);
        w.addBody(std::make_unique<Cloth>("patch", mesh, m));
        w.addCollider(plane);
        w.advance(0.0, T, 240);
        Vec3 c = Vec3::Zero();
        const VecX& x = w.bodies()[0]->positions();
        for (size_t i = 0; i < 9; ++i) c += vec3At(x.data(), i) / 9.0;
        Vec3 c0 = Vec3::Zero();
        for (size_t i = 0; i < 9; ++i) c0 += mesh.position(i) / 9.0;
        const double slid = (c - c0).dot(down);
        const double a = g * (std::sin(theta) - mu * std::cos(theta));
        INFO("mu " << mu << " slid " << slid);
        if (a > 0)
            CHECK(slid == Approx(0.5 * a * T * T).epsilon(0.03));
        else
            CHECK(std::abs(slid) < 1e-6);
        CHECK(std::abs((c - c0).dot(normal)) < 1e-6); // stays on the plane
    }
}

TEST_CASE("colliders: hair falls onto a capsule and rests on it", "[collider][hair]") {
    Strands s = makeStrandGrid(Vec3(0, 1.0, 0), 0.2, 0.0, 5, 1, 0.5, 10, Vec3::UnitX(), Vec3::UnitZ(), Vec3::UnitZ());
    HairMaterial m;
    m.rootPinned = false;
    m.dragNormal.value = Param(0.0);
    m.dragTangent.value = Param(0.0);
    m.radius = 1e-3;
    World w(WorldSettings{});
    w.addBody(std::make_unique<Hair>("h", s, m));
    Collider cap;
    cap.shape = ColliderShape::Capsule;
    cap.a = Param(std::vector<double>{-1, 0.5, 0.25});
    cap.b = Param(std::vector<double>{1, 0.5, 0.25});
    cap.radius = 0.2;
    cap.thickness = 0.002;
    cap.friction = 0.5;
    w.addCollider(cap);
    const ColliderPose pose = colliderPose(cap, 0);
    for (int f = 1; f <= 24; ++f) {
        REQUIRE_FALSE(w.advanceFrame(f).failed);
        const VecX& x = w.bodies()[0]->positions();
        for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i)
            CHECK(queryCollider(pose, vec3At(x.data(), i)).distance >= 0.002 - 1e-9);
    }
    // Strands lying across the capsule: their middles rest on its top.
    const VecX& x = w.bodies()[0]->positions();
    CHECK(vec3At(x.data(), 5).y() == Approx(0.5 + 0.2 + 0.002).margin(0.01));
}

TEST_CASE("colliders: a keyframed sphere lifts the cloth", "[collider]") {
    for (Preconditioner pre : {Preconditioner::Multigrid, Preconditioner::BlockJacobi}) {
        TriMesh mesh = makeGrid(0.6, 0.6, 10, 10, Vec3(-0.3, 0.0, -0.3), Vec3::UnitX(), Vec3::UnitZ());
        World w(WorldSettings{});
        w.addBody(std::make_unique<Cloth>("sheet", mesh, stillAirCloth(0.1)));
        // The expected height is the exact (LDLᵀ) answer: the sheet rides on the sphere. The scene
        // sits near a bifurcation — the sheet is struck at 1 m/s and a contact near the top is
        // close to releasing for most of the second — so where the solve error lands decides
        // whether the sheet hops off the top: at the default 1e-3, multigrid PCG leaves it 2–6 cm
        // above the sphere (1e-4 and 3e-5, or 1e-5 without warm start, likewise), block Jacobi
        // happens not to. Solve near-exactly (1e-7: both preconditioners give the LDLᵀ heights to
        // 1 mm) so the test checks the contact handling, not the preconditioner's error pattern.
        w.bodies()[0]->options().cgTolerance = 1e-7;
        w.bodies()[0]->options().preconditioner = pre;
        Collider s = sphere(Vec3::Zero(), 0.2);
        s.a = Param::keyed({0.0, 1.0}, {{0, -0.25, 0}, {0, 0.75, 0}}, gale::fields::KeyInterp::Linear);
        s.friction = 0.5;
        w.addCollider(s);
        for (int f = 1; f <= 24; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
        double top = -1e9;
        const VecX& x = w.bodies()[0]->positions();
        for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i) top = std::max(top, x[3 * i + 1]);
        // The sphere's top is at 0.75 + 0.2 at t = 1 s; the cloth rides on it.
        CHECK(top == Approx(0.95 + s.thickness).margin(0.02));
    }
}
