// Hard cases that must stay finite and bounded at h = 1/24 s … 1/384 s (aero.md's edge-on
// pitfall): a 24×24 gossamer flag (0.005 kg/m²) in 20 and 40 m/s edge-on wind; a flag
// stretched ×10; degenerate triangles; flipped winding; a field returning NaN at some points.
#include "solver/bodies/cloth.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace gale::solver;
using namespace gale::solver::testing;

namespace {

struct FlagRun {
    bool failed = false;
    bool finite = true;
    double maxSpeed = 0.0;   // over all frames
    double maxStretch = 0.0; // over all frames
    double maxDistance = 0.0; // from the pole (m), over all frames
    long iterations = 0;
    int rejected = 0;
    int newtonIterations = 0, newtonStalled = 0;
    double maxNewtonResidual = 0.0;
    std::vector<std::string> events;
};

struct FlagSetup {
    int n = 24;
    double size = 1.0;
    double sigma = 0.005;
    double stretch = 2000.0;
    double wind = 20.0;
    double h = 1.0 / 24.0;
    double duration = 1.0;
    int maxHalvings = 0; // the raw integrator unless robustness is asked for
    AeroJacobian jacobian = AeroJacobian::Bounded; // the default
    AeroModel model = AeroModel::Frozen;
    double prestretch = 1.0;
    bool degenerate = false;
    std::function<Vec3(const Vec3&, double)> field; // default: uniform edge-on wind
    bool sanitizeField = true;
    int newtonIterations = 0;
    double stretchLimit = 0.0; // [solver] stretch_limit (StepOptions::stretchLimit)
    double overStretch = 1.5;  // [solver] over_stretch (TroubleLimits::overStretch)
};

FlagRun runFlag(const FlagSetup& s) {
    TriMesh mesh = makeGrid(s.size, s.size, s.n, s.n, Vec3(0, 1.0, 0), Vec3::UnitX(), Vec3::UnitY());
    if (s.degenerate) {
        // Zero-area triangles: repeated corners' neighbours collinear, and a collapsed sliver.
        const int nv = static_cast<int>(mesh.vertexCount());
        mesh.triangles.push_back({0, 1, 2});            // collinear along the bottom row
        mesh.triangles.push_back({nv - 1, nv - 2, nv - 3});
        // Two extra vertices at the same point, in one triangle with a real vertex.
        const Vec3 p = mesh.position(nv / 2);
        for (int k = 0; k < 2; ++k)
            for (int c = 0; c < 3; ++c) mesh.positions.push_back(p[c]);
        mesh.uv.push_back(0.0), mesh.uv.push_back(0.0), mesh.uv.push_back(0.0), mesh.uv.push_back(0.0);
        mesh.triangles.push_back({nv / 2, nv, nv + 1});
    }
    ClothMaterial m;
    m.density = s.sigma;
    m.stretch = gale::fields::Param(s.stretch);
    m.shear = gale::fields::Param(s.stretch / 10);
    m.bend = gale::fields::Param(1e-5);
    m.damping = gale::fields::Param(0.002);
    m.lift.value = gale::fields::Param(0.3);
    m.drag.value = gale::fields::Param(1.0);
    m.aeroModel = s.model;
    VecX start = Eigen::Map<const VecX>(mesh.positions.data(), mesh.positions.size());
    if (s.prestretch != 1.0)
        for (size_t i = 0; i < mesh.vertexCount(); ++i) start[3 * i] *= s.prestretch; // from the pole x = 0
    auto cloth = std::make_unique<Cloth>("flag", mesh, m, &start);
    cloth->options().aeroJacobian = s.jacobian;
    cloth->options().newtonIterations = s.newtonIterations;
    cloth->options().stretchLimit = s.stretchLimit;
    cloth->limits().overStretch = s.overStretch;
    PinSet pins;
    pins.vertices = gridColumn(s.n, s.n, 0);
    cloth->addPins(pins);
    WorldSettings ws;
    ws.fps = 1.0 / s.h;
    ws.substeps = 1;
    ws.maxHalvings = s.maxHalvings;
    World world(ws);
    const double U = s.wind;
    if (s.field)
        world.setWind(std::make_shared<LambdaField>(s.field, s.sanitizeField));
    else
        world.setWind(constantWind(Vec3(U, 0, 0)));
    world.addBody(std::move(cloth));
    FlagRun r;
    const int frames = static_cast<int>(std::lround(s.duration / s.h));
    for (int f = 1; f <= frames; ++f) {
        const FrameStats fs = world.advanceFrame(f);
        const BodyFrameStats& b = fs.bodies[0];
        r.iterations += b.iterations;
        r.rejected += b.rejected;
        r.newtonIterations += b.newtonIterations;
        r.newtonStalled += b.newtonStalled;
        r.maxNewtonResidual = std::max(r.maxNewtonResidual, b.maxNewtonResidual);
        r.events.insert(r.events.end(), b.events.begin(), b.events.end());
        const VecX& x = world.bodies()[0]->positions();
        if (!x.allFinite() || !world.bodies()[0]->velocities().allFinite()) r.finite = false;
        r.maxSpeed = std::max(r.maxSpeed, b.maxSpeed);
        r.maxStretch = std::max(r.maxStretch, b.maxStretch);
        for (size_t i = 0; i < world.bodies()[0]->vertexCount(); ++i)
            r.maxDistance = std::max(r.maxDistance, (vec3At(x.data(), i) - Vec3(0, 1.5, 0)).norm());
        if (fs.failed) {
            r.failed = true;
            break;
        }
    }
    return r;
}

// The flag 3° off edge-on (aero.md): U m/s, 2 s at 24 fps, one substep a frame, the
// robust substepping on.
FlagSetup offEdgeOn(double U) {
    FlagSetup s;
    s.wind = U;
    s.h = 1.0 / 24;
    s.duration = 2.0;
    s.maxHalvings = 6;
    const double a = 3.0 * 3.14159265358979323846 / 180.0;
    s.field = [U, a](const Vec3&, double) { return Vec3(U * std::cos(a), 0.0, U * std::sin(a)); };
    return s;
}

} // namespace

TEST_CASE("hard: gossamer flag in edge-on wind, raw integrator, every step size", "[hard]") {
    // No substep halving: the projected aerodynamic Jacobian alone keeps the linearised
    // backward Euler bounded (aero.md: without it, or with the paper's substitution at
    // h ≥ 1/48 s, the same scene blows up).
    for (double U : {20.0, 40.0})
        for (double h : {1.0 / 24, 1.0 / 48, 1.0 / 96, 1.0 / 192, 1.0 / 384}) {
            FlagSetup s;
            s.wind = U;
            s.h = h;
            s.duration = 0.5;
            const FlagRun r = runFlag(s);
            INFO("U " << U << " h 1/" << std::lround(1 / h) << " speed " << r.maxSpeed << " stretch "
                      << r.maxStretch << " dist " << r.maxDistance << " its " << r.iterations);
            CHECK_FALSE(r.failed);
            CHECK(r.finite);
            CHECK(r.maxSpeed < 3.0 * U);
            CHECK(r.maxDistance < 5.0);
        }
}

TEST_CASE("hard: gossamer flag with the default robust substepping stays physical", "[hard]") {
    for (double U : {20.0, 40.0})
        for (double h : {1.0 / 24, 1.0 / 384}) {
            FlagSetup s;
            s.wind = U;
            s.h = h;
            s.duration = 0.5;
            s.maxHalvings = 6;
            const FlagRun r = runFlag(s);
            INFO("U " << U << " h 1/" << std::lround(1 / h) << " speed " << r.maxSpeed << " stretch "
                      << r.maxStretch << " dist " << r.maxDistance << " rejected " << r.rejected);
            CHECK_FALSE(r.failed);
            CHECK(r.finite);
            CHECK(r.maxSpeed < 2.0 * U);
            CHECK(r.maxStretch < 3.2); // the over-stretch detector's limit (3×) plus its 5 % slack
            CHECK(r.maxDistance < 1.2 * std::sqrt(1.25));
            // Every rejected substep says why.
            for (const std::string& e : r.events) CHECK(e.find("substep") != std::string::npos);
        }
}

TEST_CASE("hard: gossamer flag 3 degrees off edge-on takes one substep per frame at 1/24 s", "[hard]") {
    // The flag (aero.md): 24×24, 0.005 kg/m², 20 and 40 m/s, 3° off edge-on, 2 s at
    // 24 fps, substeps = 1. The linearised step over-stretches an edge now and then (up to 17×);
    // that substep is retried with Newton's line search, which cuts the step, so it is never
    // halved.
    for (double U : {20.0, 40.0}) {
        const FlagRun r = runFlag(offEdgeOn(U));
        INFO("U " << U << " speed " << r.maxSpeed << " stretch " << r.maxStretch << " rejected " << r.rejected);
        CHECK_FALSE(r.failed);
        CHECK(r.finite);
        CHECK(r.rejected == 0);
        CHECK(r.maxSpeed < 2.0 * U);
        CHECK(r.maxStretch < 3.0);
    }
}

TEST_CASE("hard: the gossamer flag at one substep a frame stays within a stretch limit", "[hard]") {
    // The same flag with a [solver] stretch_limit it passes without one (with the defaults —
    // the rotation projection, the bounded aero Jacobian — 1.35 at 20 m/s and 1.85 at 40, 1.07
    // and 1.35 were the projection's later iterations to go on for every edge beyond 2 %; 1.46
    // and 1.90 with the projected Jacobian; 2.9 at 20 m/s without the projection either,
    // bench/README.md): no frame ends with an edge beyond it.
    // The run without it with over_stretch at 3 (the default before 1.5: that 1.5 halves the
    // 40 m/s flag's substeps until it ends below it, 1.42).
    for (const auto& [U, cap] : {std::pair{20.0, 1.15}, std::pair{40.0, 1.5}}) {
        FlagSetup s = offEdgeOn(U);
        s.overStretch = 3.0;
        const FlagRun free = runFlag(s);
        s.stretchLimit = cap;
        const FlagRun limited = runFlag(s);
        INFO("U " << U << " stretch without the limit " << free.maxStretch << ", with it "
                  << limited.maxStretch << " (speed " << limited.maxSpeed << ", rejected "
                  << limited.rejected << ")");
        CHECK(free.maxStretch > cap);
        CHECK_FALSE(limited.failed);
        CHECK(limited.finite);
        CHECK(limited.rejected == 0);
        CHECK(limited.maxSpeed < 2.0 * U);
        CHECK(limited.maxStretch <= cap);
    }
}

TEST_CASE("hard: Newton converges every step on the smooth-lift gossamer flag at 1/24 s", "[hard][newton]") {
    // The flag at one substep per frame, 3° off edge-on: with the full Jacobian (the
    // aerodynamic force's turn with each triangle, ∂F/∂x, and the exact ∂F/∂v) every substep's
    // velocity residual ends below newton_tolerance = 0.01 m/s, with no halving. The frozen
    // model's lift flips sides edge-on (a jump in F): its equations have no solution for the
    // triangles crossing it, so there Newton stops at its iteration count (docs/solver.md).
    for (double U : {20.0, 40.0}) {
        FlagSetup s;
        s.wind = U;
        s.model = AeroModel::SmoothLift;
        s.newtonIterations = 8;
        s.maxHalvings = 6;
        s.duration = 1.0;
        const double a = 3.0 * 3.14159265358979323846 / 180.0;
        s.field = [U, a](const Vec3&, double) { return Vec3(U * std::cos(a), 0.0, U * std::sin(a)); };
        const FlagRun r = runFlag(s);
        INFO("U " << U << " newton " << r.newtonIterations << " stalled " << r.newtonStalled << " residual "
                  << r.maxNewtonResidual << " rejected " << r.rejected);
        CHECK_FALSE(r.failed);
        CHECK(r.rejected == 0);
        CHECK(r.newtonStalled == 0);
        CHECK(r.maxNewtonResidual <= 0.01);
        CHECK(r.newtonIterations >= 24); // the linearised step alone is not converged
    }
}

TEST_CASE("hard: smooth lift with the paper's Jacobian is stable edge-on", "[hard]") {
    for (double h : {1.0 / 24, 1.0 / 96}) {
        FlagSetup s;
        s.wind = 20.0;
        s.h = h;
        s.duration = 0.5;
        s.model = AeroModel::SmoothLift;
        s.jacobian = AeroJacobian::Paper;
        const FlagRun r = runFlag(s);
        CHECK_FALSE(r.failed);
        CHECK(r.maxSpeed < 20.0);
        CHECK(r.maxStretch < 2.0);
    }
}

TEST_CASE("hard: a flag stretched ×10 springs back without blowing up", "[hard]") {
    for (double h : {1.0 / 24, 1.0 / 384}) {
        FlagSetup s;
        s.wind = 20.0;
        s.h = h;
        s.duration = 1.0;
        s.prestretch = 10.0;
        s.maxHalvings = 6;
        s.sigma = 0.1;
        const FlagRun r = runFlag(s);
        INFO("h 1/" << std::lround(1 / h) << " stretch " << r.maxStretch << " dist " << r.maxDistance);
        CHECK_FALSE(r.failed);
        CHECK(r.finite);
        CHECK(r.maxDistance < 11.0); // never further out than where it started
    }
    // The raw integrator too.
    FlagSetup s;
    s.prestretch = 10.0;
    s.duration = 1.0;
    s.sigma = 0.1;
    const FlagRun r = runFlag(s);
    CHECK_FALSE(r.failed);
    CHECK(r.maxDistance < 11.0);
}

TEST_CASE("hard: degenerate triangles do not take the run down", "[hard]") {
    for (double h : {1.0 / 24, 1.0 / 384}) {
        FlagSetup s;
        s.degenerate = true;
        s.h = h;
        s.duration = 0.25;
        const FlagRun r = runFlag(s);
        CHECK_FALSE(r.failed);
        CHECK(r.finite);
        CHECK(r.maxDistance < 5.0);
    }
    TriMesh mesh = makeGrid(1, 1, 3, 3);
    mesh.triangles.push_back({0, 1, 2});
    Cloth c("c", mesh, ClothMaterial{});
    CHECK(c.degenerateTriangles() == 1);
}

TEST_CASE("hard: flipped winding gives the same motion", "[hard]") {
    for (double h : {1.0 / 24, 1.0 / 384}) {
        // Every other triangle flipped: compare the positions at the end.
        TriMesh ma = makeGrid(1, 1, 24, 24, Vec3(0, 1, 0)), mb = ma;
        for (size_t t = 0; t < mb.triangles.size(); t += 2) std::swap(mb.triangles[t][1], mb.triangles[t][2]);
        auto run = [&](const TriMesh& mesh) {
            ClothMaterial m;
            m.density = 0.005;
            m.bend = gale::fields::Param(1e-5);
            auto cloth = std::make_unique<Cloth>("flag", mesh, m);
            cloth->options().cgTolerance = 1e-10;
            PinSet pins;
            pins.vertices = gridColumn(24, 24, 0);
            cloth->addPins(pins);
            WorldSettings ws;
            ws.fps = 1.0 / h;
            ws.substeps = 1;
            World w(ws);
            w.setWind(constantWind(Vec3(20, 0, 0)));
            w.addBody(std::move(cloth));
            for (int f = 1; f <= std::lround(0.125 / h); ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
            return VecX(w.bodies()[0]->positions());
        };
        const VecX xa = run(ma), xb = run(mb);
        CHECK((xa - xb).cwiseAbs().maxCoeff() < 1e-6);
        CHECK((xa - Eigen::Map<const VecX>(ma.positions.data(), ma.positions.size())).cwiseAbs().maxCoeff() > 1e-3);
    }
}

TEST_CASE("hard: pinned on two edges in a 40 m/s broadside gale", "[hard]") {
    for (double h : {1.0 / 24, 1.0 / 384}) {
        TriMesh mesh = makeGrid(1, 1, 24, 24, Vec3(0, 1, 0));
        ClothMaterial m;
        m.density = 0.005;
        auto cloth = std::make_unique<Cloth>("sail", mesh, m);
        PinSet pins;
        pins.vertices = gridColumn(24, 24, 0);
        const std::vector<int> right = gridColumn(24, 24, 23);
        pins.vertices.insert(pins.vertices.end(), right.begin(), right.end());
        cloth->addPins(pins);
        WorldSettings ws;
        ws.fps = 1.0 / h;
        ws.substeps = 1;
        World w(ws);
        w.setWind(constantWind(Vec3(0, 0, 40)));
        w.addBody(std::move(cloth));
        double stretch = 0.0;
        for (int f = 1; f <= std::lround(0.5 / h); ++f) {
            const FrameStats fs = w.advanceFrame(f);
            REQUIRE_FALSE(fs.failed);
            stretch = std::max(stretch, fs.bodies[0].maxStretch);
        }
        const VecX& x = w.bodies()[0]->positions();
        CHECK(x.allFinite());
        CHECK(stretch < 3.0);
        // Blown downwind, held by the pinned edges.
        CHECK(vec3At(x.data(), 12 * 24 + 12).z() > 0.1);
        CHECK(vec3At(x.data(), 12 * 24 + 12).z() < 2.0);
    }
}

TEST_CASE("hard: a field returning NaN at some points is reported and recovered", "[hard]") {
    for (bool sanitize : {true, false}) {
        FlagSetup s;
        s.h = 1.0 / 48;
        s.duration = 0.25;
        s.sanitizeField = sanitize;
        s.field = [](const Vec3& x, double t) {
            if (x.x() > 0.5 && t > 0.05) return Vec3(std::nan(""), 0, 0);
            return Vec3(20, 0, 0);
        };
        const FlagRun r = runFlag(s);
        CHECK_FALSE(r.failed);
        CHECK(r.finite);
        bool reported = false;
        for (const std::string& e : r.events) reported = reported || e.find("wind") != std::string::npos;
        CHECK(reported);
    }
}
