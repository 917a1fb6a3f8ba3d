// aero.md reference cases on cloth: (1) a free plate in uniform wind — backward Euler converges
// at first order to x(t) = U t − ln(1 + kUt)/k; (2) a plate falling broadside reaches
// v_t = √(2σg/(ρC_D)) along v_t tanh(g t / v_t); (4) a ribbon pinned at the top settles at
// sin φ = K[(C_D − C_L)cos²φ + C_L]. Plus mass lumping and winding invariance.
#include "solver/bodies/cloth.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <tuple>

using namespace gale::solver;
using namespace gale::solver::testing;

namespace {

const double kRho = 1.225;

Vec3 centroid(const Body& b) {
    Vec3 c = Vec3::Zero();
    for (size_t i = 0; i < b.vertexCount(); ++i) c += vec3At(b.positions().data(), i);
    return c / static_cast<double>(b.vertexCount());
}

ClothMaterial plateMaterial(double sigma, double cl, double cd) {
    ClothMaterial m;
    m.density = sigma;
    m.lift.value = gale::fields::Param(cl);
    m.drag.value = gale::fields::Param(cd);
    m.damping = gale::fields::Param(0.0);
    return m;
}

// Displacement along the wind after time T for a free plate, N substeps in one interval.
double plateDisplacement(int substeps, double T, double U, double sigma, double cd,
                         double* spread = nullptr) {
    WorldSettings ws;
    ws.gravity = Vec3::Zero();
    ws.maxHalvings = 0;
    World w(ws);
    w.setWind(constantWind(Vec3(0, 0, U)));
    auto cloth = std::make_unique<Cloth>("plate", makeGrid(1.0, 1.0, 5, 5), plateMaterial(sigma, 0.3, cd));
    cloth->options().cgTolerance = 1e-12;
    w.addBody(std::move(cloth));
    const FrameStats fs = w.advance(0.0, T, substeps);
    REQUIRE_FALSE(fs.failed);
    if (spread) {
        double lo = 1e300, hi = -1e300;
        const Body& b = *w.bodies()[0];
        for (size_t i = 0; i < b.vertexCount(); ++i) {
            lo = std::min(lo, b.positions()[3 * i + 2]);
            hi = std::max(hi, b.positions()[3 * i + 2]);
        }
        *spread = hi - lo;
    }
    return centroid(*w.bodies()[0]).z();
}

} // namespace

TEST_CASE("cloth: masses are lumped by area", "[cloth]") {
    Cloth c("c", makeGrid(2.0, 1.0, 5, 3), plateMaterial(0.2, 0.0, 1.0));
    CHECK(c.masses().sum() == Approx(0.2 * 2.0 * 1.0));
    // Alternating diagonals: interior vertex (2, 1) is a corner of 4 triangles, (1, 1) of 8.
    const double cell = 0.5 * 0.5;
    CHECK(c.masses()[1 * 5 + 2] == Approx(0.2 * 4 * (cell / 2) / 3));
    CHECK(c.masses()[1 * 5 + 1] == Approx(0.2 * 8 * (cell / 2) / 3));
}

TEST_CASE("cloth reference 1: free plate in uniform wind converges at first order", "[cloth][reference]") {
    const double U = 2.0, sigma = 0.1, cd = 1.2, T = 0.5;
    const double k = kRho * cd / (2 * sigma);
    const double exact = U * T - std::log(1 + k * U * T) / k;
    double prevErr = 0.0;
    for (int n : {32, 64, 128, 256, 512}) {
        double spread = 0.0;
        const double x = plateDisplacement(n, T, U, sigma, cd, &spread);
        CHECK(spread < 1e-9); // the mesh translates rigidly
        const double err = std::abs(x - exact);
        INFO("substeps " << n << " x " << x << " exact " << exact << " error " << err);
        if (prevErr > 0.0) {
            const double ratio = prevErr / err;
            CHECK(ratio > 1.8);
            CHECK(ratio < 2.3);
        }
        prevErr = err;
    }
    CHECK(prevErr < 3e-3 * exact);
}

TEST_CASE("cloth reference 2: a plate falling broadside reaches terminal velocity", "[cloth][reference]") {
    const double sigma = 0.1, cd = 1.0, g = 9.81;
    const double vt = std::sqrt(2 * sigma * g / (kRho * cd));
    auto run = [&](double T, int substeps, double& y, double& v) {
        WorldSettings ws;
        ws.gravity = Vec3(0, -g, 0);
        ws.maxHalvings = 0;
        World w(ws);
        auto cloth = std::make_unique<Cloth>("plate", makeGrid(0.5, 0.5, 4, 4, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ()),
                                             plateMaterial(sigma, 0.0, cd));
        cloth->options().cgTolerance = 1e-12;
        w.addBody(std::move(cloth));
        REQUIRE_FALSE(w.advance(0.0, T, substeps).failed);
        y = centroid(*w.bodies()[0]).y();
        v = w.bodies()[0]->velocities()[1];
    };
    double y, v;
    run(3.0, 600, y, v);
    CHECK(-v == Approx(vt).epsilon(1e-6)); // terminal velocity is the fixed point of the step
    const double T = 0.4;
    const double yExact = -(vt * vt / g) * std::log(std::cosh(g * T / vt));
    const double vExact = -vt * std::tanh(g * T / vt);
    double e1, e2;
    run(T, 200, y, v);
    e1 = std::abs(y - yExact);
    CHECK(v == Approx(vExact).epsilon(2e-3));
    run(T, 400, y, v);
    e2 = std::abs(y - yExact);
    CHECK(e1 / e2 == Approx(2.0).epsilon(0.1));
    CHECK(e2 < 1e-3 * std::abs(yExact));
}

namespace {

// Ribbon of width w and length L hanging in the plane x = 0 (width along z), top edge pinned,
// horizontal wind U along +x; returns the angle from the vertical of the line from the middle
// of the top edge to the middle of the bottom edge after T seconds.
double ribbonAngle(double U, double cl, double cd, double sigma, AeroModel model) {
    const double w = 0.1, L = 0.5;
    const int nx = 3, ny = 11;
    TriMesh mesh = makeGrid(w, L, nx, ny, Vec3(0, -L, -w / 2), Vec3::UnitZ(), Vec3::UnitY());
    ClothMaterial m = plateMaterial(sigma, cl, cd);
    m.stretch = gale::fields::Param(2e4);
    m.shear = gale::fields::Param(2e3);
    m.bend = gale::fields::Param(1e-6);
    m.damping = gale::fields::Param(0.002);
    m.aeroModel = model;
    auto cloth = std::make_unique<Cloth>("ribbon", mesh, m);
    PinSet pins;
    pins.vertices = gridRow(nx, ny - 1);
    cloth->addPins(pins);
    WorldSettings ws;
    ws.gravity = Vec3(0, -9.81, 0);
    World world(ws);
    world.setWind(constantWind(Vec3(U, 0, 0)));
    world.addBody(std::move(cloth));
    for (int f = 1; f <= 96; ++f) REQUIRE_FALSE(world.advanceFrame(f).failed);
    const VecX& x = world.bodies()[0]->positions();
    const Vec3 top = vec3At(x.data(), (ny - 1) * nx + 1), bottom = vec3At(x.data(), 1);
    const Vec3 d = bottom - top;
    CHECK(world.bodies()[0]->velocities().norm() < 1e-3); // settled
    return std::atan2(d.x(), -d.y());
}

} // namespace

TEST_CASE("cloth reference 4: ribbon equilibrium angle in a horizontal wind", "[cloth][reference]") {
    const double sigma = 0.1, g = 9.81, U = 2.0;
    const double K = kRho * U * U / (2 * sigma * g); // ρ w U² / (2 λ g) with λ = σ w
    SECTION("drag only: closed form") {
        const double cd = 1.0;
        const double want = std::asin((std::sqrt(1 + 4 * K * K * cd * cd) - 1) / (2 * K * cd));
        CHECK(ribbonAngle(U, 0.0, cd, sigma, AeroModel::Frozen) == Approx(want).margin(0.01));
    }
    SECTION("with lift: root of sin φ = K[(C_D − C_L)cos²φ + C_L]") {
        const double cd = 1.0, cl = 0.3;
        double lo = 0.0, hi = 1.5707963;
        for (int i = 0; i < 100; ++i) {
            const double mid = 0.5 * (lo + hi);
            const double r = std::sin(mid) - K * ((cd - cl) * std::cos(mid) * std::cos(mid) + cl);
            (r < 0 ? lo : hi) = mid;
        }
        CHECK(ribbonAngle(U, cl, cd, sigma, AeroModel::Frozen) == Approx(lo).margin(0.01));
    }
}

TEST_CASE("cloth: a 48x48 flag gives the same bits on 1, 2 and 3 threads", "[cloth][threads]") {
    // 4418 triangles: the colour-by-colour parallel assembly and the multicolour Gauss–Seidel
    // run in parallel chunks on 2 and 3 threads; positions, velocities, the elastic energy
    // and the iteration count must not depend on that.
    const int n = 48;
    auto run = [n](int threads, Preconditioner pre) {
        WorldSettings ws;
        ws.threads = threads;
        ws.fps = 96.0;
        World w(ws);
        w.setWind(std::make_shared<LambdaField>([](const Vec3& x, double t) {
            return Vec3(12.0 + 4.0 * std::sin(3.0 * t + 2.0 * x.y()),
                        2.0 * std::cos(5.0 * t + 3.0 * x.x()),
                        3.0 * std::sin(7.0 * t + x.x() + x.y()));
        }));
        ClothMaterial m;
        m.density = 0.1;
        auto c = std::make_unique<Cloth>("flag", makeGrid(1.0, 1.0, n, n, Vec3(0, 1, 0)), m);
        PinSet pins;
        pins.vertices = gridColumn(n, n, 0);
        c->addPins(pins);
        c->options().preconditioner = pre;
        w.addBody(std::move(c));
        FrameStats last;
        long iterations = 0;
        for (int f = 1; f <= 4; ++f) {
            last = w.advanceFrame(f);
            REQUIRE_FALSE(last.failed);
            iterations += last.bodies[0].iterations;
        }
        const Body& b = *w.bodies()[0];
        VecX state(2 * b.positions().size());
        state << b.positions(), b.velocities();
        return std::make_tuple(state, last.bodies[0].elastic, iterations);
    };
    for (Preconditioner pre : {Preconditioner::Multigrid, Preconditioner::BlockJacobi}) {
        const auto ref = run(1, pre);
        REQUIRE(std::get<0>(ref).allFinite());
        CHECK(std::get<1>(ref) > 0.0);
        for (int threads : {2, 3}) {
            const auto got = run(threads, pre);
            INFO(threads << " threads, "
                         << (pre == Preconditioner::Multigrid ? "multigrid" : "block Jacobi"));
            CHECK((std::get<0>(got) - std::get<0>(ref)).cwiseAbs().maxCoeff() == 0.0);
            CHECK(std::get<1>(got) == std::get<1>(ref));
            CHECK(std::get<2>(got) == std::get<2>(ref));
        }
    }
}
