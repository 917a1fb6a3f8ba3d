// Hair: aero.md reference case 5 (a hanging chain of N equal masses: spring j from the bottom
// stretches by j m g / k), the lumped-mass variant, the steady angle of a strand in cross-flow
// (sin φ = K cos²φ), and the dynamics of a short chain in wind against a GSL rk8pd reference
// (first-order convergence of backward Euler).
#include "solver/bodies/hair.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <cmath>

using namespace gale::solver;
using namespace gale::solver::testing;

namespace {

const double kPi = 3.14159265358979323846;

HairMaterial stringMaterial(double ea, double cn, double ct) {
    HairMaterial m;
    m.stretch = gale::fields::Param(ea);
    m.bend = gale::fields::Param(0.0);
    m.damping = gale::fields::Param(0.0);
    m.dragNormal.value = gale::fields::Param(cn);
    m.dragTangent.value = gale::fields::Param(ct);
    return m;
}

} // namespace

TEST_CASE("hair reference 5: a hanging chain of equal masses", "[hair][reference]") {
    const int N = 10;
    const double L = 0.02, k = 50.0, m = 1e-3, g = 9.81;
    Strands s = makeStrandGrid(Vec3::Zero(), 0, 0, 1, 1, N * L, N);
    HairMaterial mat = stringMaterial(k * L, 0.0, 0.0);
    mat.damping = gale::fields::Param(0.02);
    auto hair = std::make_unique<Hair>("chain", s, mat);
    hair->setMasses(VecX::Constant(N + 1, m));
    WorldSettings ws;
    World w(ws);
    w.addBody(std::move(hair));
    for (int f = 1; f <= 120; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
    const VecX& x = w.bodies()[0]->positions();
    CHECK(w.bodies()[0]->velocities().norm() < 1e-8);
    for (int j = 1; j <= N; ++j) {
        // Spring j from the bottom joins vertices N − j and N − j + 1.
        const double len = (vec3At(x.data(), N - j + 1) - vec3At(x.data(), N - j)).norm();
        CHECK(len - L == Approx(j * m * g / k).epsilon(1e-6));
    }
    const double tipDrop = -x[3 * N + 1] - N * L;
    CHECK(tipDrop == Approx(m * g * N * (N + 1) / (2 * k)).epsilon(1e-6));
    CHECK(x[0] == 0.0); // the root is pinned
}

TEST_CASE("hair: lumped masses from the linear density", "[hair]") {
    const int N = 8;
    const double L = 0.01, r = 5e-4, rho = 1300.0, ea = 5.0, g = 9.81;
    Strands s = makeStrandGrid(Vec3::Zero(), 0, 0, 1, 1, N * L, N);
    HairMaterial mat = stringMaterial(ea, 0.0, 0.0);
    mat.radius = r;
    mat.density = rho;
    mat.damping = gale::fields::Param(0.02);
    auto hair = std::make_unique<Hair>("h", s, mat);
    const double lambda = rho * kPi * r * r;
    CHECK(hair->masses()[1] == Approx(lambda * L));
    CHECK(hair->masses()[N] == Approx(lambda * L / 2));
    World w(WorldSettings{});
    w.addBody(std::move(hair));
    for (int f = 1; f <= 48; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
    const VecX& x = w.bodies()[0]->positions();
    const double k = ea / L;
    for (int j = 1; j <= N; ++j) {
        // Below spring j hang j − 1 full vertices and the half-mass tip.
        const double below = (j - 0.5) * lambda * L;
        const double len = (vec3At(x.data(), N - j + 1) - vec3At(x.data(), N - j)).norm();
        CHECK(len - L == Approx(below * g / k).epsilon(1e-6));
    }
}

TEST_CASE("hair: steady angle of a strand in cross-flow", "[hair][reference]") {
    // Normal drag per length ½ρ C_n d (U cos φ)² balances the weight's normal part λ g sin φ.
    const double U = 3.0, r = 2e-4, rho = 1300.0, cn = 1.2, g = 9.81, air = 1.225;
    const double lambda = rho * kPi * r * r;
    const double K = air * cn * 2 * r * U * U / (2 * lambda * g);
    const double want = std::asin((std::sqrt(1 + 4 * K * K) - 1) / (2 * K));
    Strands s = makeStrandGrid(Vec3::Zero(), 0.02, 0, 3, 1, 0.2, 20);
    HairMaterial mat = stringMaterial(50.0, cn, 0.05);
    mat.radius = r;
    mat.density = rho;
    mat.damping = gale::fields::Param(0.002);
    World w(WorldSettings{});
    w.setWind(constantWind(Vec3(U, 0, 0)));
    w.addBody(std::make_unique<Hair>("h", s, mat));
    for (int f = 1; f <= 96; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
    const VecX& x = w.bodies()[0]->positions();
    for (int strand = 0; strand < 3; ++strand) {
        const Vec3 root = vec3At(x.data(), 21 * strand), tip = vec3At(x.data(), 21 * strand + 20);
        const Vec3 d = tip - root;
        CHECK(std::atan2(d.x(), -d.y()) == Approx(want).margin(2e-3));
    }
}

namespace {

// The same chain as ODEs for GSL: root fixed at the origin, N free vertices, springs, gravity
// and cross-flow drag per segment (wind and velocity averaged over the segment's ends).
struct ChainOde {
    int n;
    double L, k, air, d, cn, ct;
    std::vector<double> mass;
    Vec3 wind, g;
};

int chainRhs(double, const double y[], double dydt[], void* p) {
    const ChainOde& c = *static_cast<const ChainOde*>(p);
    const int n = c.n; // free vertices 1..n; y = [x1..xn, v1..vn]
    auto X = [&](int i) { return i == 0 ? Vec3::Zero() : Vec3(y[3 * (i - 1)], y[3 * (i - 1) + 1], y[3 * (i - 1) + 2]); };
    auto V = [&](int i) {
        return i == 0 ? Vec3::Zero() : Vec3(y[3 * n + 3 * (i - 1)], y[3 * n + 3 * (i - 1) + 1], y[3 * n + 3 * (i - 1) + 2]);
    };
    std::vector<Vec3> F(n + 1, Vec3::Zero());
    for (int i = 1; i <= n; ++i) F[i] = c.mass[i] * c.g;
    for (int i = 0; i < n; ++i) {
        const Vec3 e = X(i + 1) - X(i);
        const double len = e.norm();
        const Vec3 t = e / len;
        const Vec3 fs = c.k * (len - c.L) * t;
        F[i] += fs;
        F[i + 1] -= fs;
        const Vec3 v = c.wind - 0.5 * (V(i) + V(i + 1));
        const Vec3 vt = v.dot(t) * t, vn = v - vt;
        const Vec3 fa = 0.5 * c.air * c.cn * c.d * len * vn.norm() * vn + 0.5 * c.air * c.ct * kPi * c.d * len * vt.norm() * vt;
        F[i] += 0.5 * fa;
        F[i + 1] += 0.5 * fa;
    }
    for (int i = 1; i <= n; ++i)
        for (int q = 0; q < 3; ++q) {
            dydt[3 * (i - 1) + q] = y[3 * n + 3 * (i - 1) + q];
            dydt[3 * n + 3 * (i - 1) + q] = F[i][q] / c.mass[i];
        }
    return GSL_SUCCESS;
}

} // namespace

TEST_CASE("hair: a short chain in wind converges at first order to a GSL reference", "[hair][reference]") {
    const int N = 4;
    const double L = 0.05, ea = 0.02, r = 3e-4, rho = 1300.0, cn = 1.2, ct = 0.1, T = 0.25;
    const Vec3 wind(4.0, 0.0, 1.0);
    Strands s = makeStrandGrid(Vec3::Zero(), 0, 0, 1, 1, N * L, N);
    HairMaterial mat = stringMaterial(ea, cn, ct);
    mat.radius = r;
    mat.density = rho;

    ChainOde ode{N, L, ea / L, 1.225, 2 * r, cn, ct, {}, wind, Vec3(0, -9.81, 0)};
    {
        Hair probe("p", s, mat);
        for (int i = 0; i <= N; ++i) ode.mass.push_back(probe.masses()[i]);
    }
    std::vector<double> y(6 * N, 0.0);
    for (int i = 1; i <= N; ++i) y[3 * (i - 1) + 1] = -i * L;
    gsl_odeiv2_system sys{chainRhs, nullptr, static_cast<size_t>(6 * N), &ode};
    gsl_odeiv2_driver* drv = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-6, 1e-12, 1e-12);
    double t = 0.0;
    REQUIRE(gsl_odeiv2_driver_apply(drv, &t, T, y.data()) == GSL_SUCCESS);
    gsl_odeiv2_driver_free(drv);

    double prev = 0.0;
    for (int steps : {200, 400, 800, 1600}) {
        WorldSettings ws;
        ws.maxHalvings = 0;
        World w(ws);
        w.setWind(constantWind(wind));
        w.addBody(std::make_unique<Hair>("h", s, mat));
        REQUIRE_FALSE(w.advance(0.0, T, steps).failed);
        const VecX& x = w.bodies()[0]->positions();
        double err = 0.0;
        for (int i = 1; i <= N; ++i)
            err = std::max(err, (vec3At(x.data(), i) - Vec3(y[3 * (i - 1)], y[3 * (i - 1) + 1], y[3 * (i - 1) + 2])).norm());
        INFO("steps " << steps << " error " << err);
        if (prev > 0.0) {
            CHECK(prev / err > 1.7);
            CHECK(prev / err < 2.4);
        }
        prev = err;
    }
    CHECK(prev < 2e-3);
}

TEST_CASE("hair: no hair, no hair work; generated strands keep their roots", "[hair]") {
    Strands s = makeStrandGrid(Vec3(0, 2, 0), 0.1, 0.1, 4, 3, 0.3, 6);
    CHECK(s.strandCount() == 12);
    CHECK(s.vertexCount() == 12 * 7);
    World w(WorldSettings{});
    w.setWind(constantWind(Vec3(5, 0, 0)));
    w.addBody(std::make_unique<Hair>("h", s, HairMaterial{}));
    for (int f = 1; f <= 12; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
    const VecX& x = w.bodies()[0]->positions();
    for (size_t k = 0; k < s.strandCount(); ++k)
        CHECK((vec3At(x.data(), s.offsets[k]) - vec3At(s.positions.data(), s.offsets[k])).norm() == 0.0);
    CHECK(x.allFinite());
}
