// Elastic elements: forces are minus the energy gradient (finite differences), stiffness
// matrices are PSD and exact where the model says so, rest states are force-free, and the
// Bergou hinge gives E = 6 k_b |e|² sin²(θ/2)/(A0 + A1) for a fold by θ.
#include "solver/bodies/elastic.h"

#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace gale::solver;

namespace {

double membraneEnergy(const MembraneRest& r, const Vec3 x[3], double ks, double ksh) {
    TriangleElastic te;
    membraneForces(r, x, ks, ksh, te);
    return te.energy;
}

double minEigenSym(const Eigen::MatrixXd& m) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (m + m.transpose()));
    return es.eigenvalues().minCoeff();
}

} // namespace

TEST_CASE("membrane: forces are −∇E, stiffness PSD, exact Hessian for pure stretch in tension", "[elastic]") {
    const Vec3 rest[3] = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.02, 0.08, 0)};
    Vec3 uv[3];
    materialCoordinates(rest, Vec3::UnitX(), uv);
    MembraneRest mr;
    REQUIRE(makeMembraneRest(uv, mr));
    CHECK(mr.area == Approx(0.5 * 0.1 * 0.08));
    // At rest: no force, no energy.
    TriangleElastic te;
    membraneForces(mr, rest, 2000, 200, te);
    CHECK(te.energy == Approx(0.0).margin(1e-15));
    for (int i = 0; i < 3; ++i) CHECK(te.f[i].norm() < 1e-10);

    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-0.004, 0.004);
    for (int trial = 0; trial < 20; ++trial) {
        Vec3 x[3];
        for (int i = 0; i < 3; ++i) x[i] = 1.3 * rest[i] + Vec3(u(rng), u(rng), u(rng));
        for (double ksh : {200.0, 0.0}) {
            membraneForces(mr, x, 2000, ksh, te);
            Eigen::MatrixXd K(9, 9), Kfd(9, 9);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) K.block<3, 3>(3 * i, 3 * j) = te.K[i][j];
            CHECK(minEigenSym(K) >= -1e-8 * K.norm());
            const double eps = 1e-7;
            for (int i = 0; i < 3; ++i)
                for (int c = 0; c < 3; ++c) {
                    Vec3 xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
                    xp[i][c] += eps;
                    xm[i][c] -= eps;
                    const double g = (membraneEnergy(mr, xp, 2000, ksh) - membraneEnergy(mr, xm, 2000, ksh)) / (2 * eps);
                    CHECK(-te.f[i][c] == Approx(g).margin(1e-6 * (1 + std::abs(g))));
                    TriangleElastic tp, tm;
                    membraneForces(mr, xp, 2000, ksh, tp);
                    membraneForces(mr, xm, 2000, ksh, tm);
                    for (int k = 0; k < 3; ++k) Kfd.block<3, 1>(3 * k, 3 * i + c) = -(tp.f[k] - tm.f[k]) / (2 * eps);
                }
            // Both directions stretched (x ≈ 1.3 × rest): with no shear term the stretch Hessian
            // including the tension term is exact.
            if (ksh == 0.0) CHECK((K - Kfd).norm() <= 1e-4 * K.norm());
        }
    }
}

TEST_CASE("membrane: rigid motions cost nothing; degenerate rest triangles are rejected", "[elastic]") {
    const Vec3 rest[3] = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.0, 0.1, 0)};
    Vec3 uv[3];
    materialCoordinates(rest, Vec3::UnitX(), uv);
    MembraneRest mr;
    REQUIRE(makeMembraneRest(uv, mr));
    const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    Vec3 x[3];
    for (int i = 0; i < 3; ++i) x[i] = R * rest[i] + Vec3(5, -2, 1);
    TriangleElastic te;
    membraneForces(mr, x, 2000, 200, te);
    CHECK(te.energy == Approx(0.0).margin(1e-12));
    // Flipped winding: same energy for the same deformation.
    const Vec3 restF[3] = {rest[0], rest[2], rest[1]};
    Vec3 uvF[3];
    materialCoordinates(restF, Vec3::UnitX(), uvF);
    MembraneRest mf;
    REQUIRE(makeMembraneRest(uvF, mf));
    const Vec3 y[3] = {Vec3(0, 0, 0), Vec3(0.13, 0.01, 0), Vec3(-0.01, 0.09, 0.02)};
    const Vec3 yF[3] = {y[0], y[2], y[1]};
    CHECK(membraneEnergy(mr, y, 2000, 200) == Approx(membraneEnergy(mf, yF, 2000, 200)).epsilon(1e-10));
    // Collinear corners: no rest data, no force.
    const Vec3 line[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
    Vec3 uvl[3];
    materialCoordinates(line, Vec3::UnitX(), uvl);
    MembraneRest ml;
    CHECK_FALSE(makeMembraneRest(uvl, ml));
    membraneForces(ml, y, 2000, 200, te);
    CHECK(te.energy == 0.0);
}

TEST_CASE("bending: planar hinges are force-free; a fold by θ has the closed-form energy", "[elastic]") {
    // Edge from (0,0,0) to (0,L,0); wings of widths a and b on either side.
    const double L = 0.2, a = 0.07, b = 0.11, kb = 0.003;
    for (double theta : {0.0, 0.1, 0.5, 1.2, 2.0}) {
        const Vec3 rest[4] = {Vec3(0, 0, 0), Vec3(0, L, 0), Vec3(a, 0.3 * L, 0), Vec3(-b, 0.6 * L, 0)};
        HingeRest hr;
        REQUIRE(makeHingeRest(rest, hr));
        double sumK = 0.0;
        for (double c : hr.k) sumK += c;
        CHECK(sumK == Approx(0.0).margin(1e-12));
        // Fold wing 3 about the edge (y axis) by θ.
        const Mat3 R = Eigen::AngleAxisd(theta, Vec3::UnitY()).toRotationMatrix();
        const Vec3 x[4] = {rest[0], rest[1], rest[2], R * rest[3]};
        Vec3 s = Vec3::Zero();
        for (int i = 0; i < 4; ++i) s += hr.k[i] * x[i];
        const double E = 0.5 * kb * hr.scale * s.squaredNorm();
        const double A0 = 0.5 * L * a, A1 = 0.5 * L * b;
        CHECK(E == Approx(6.0 * kb * L * L * std::pow(std::sin(theta / 2), 2) / (A0 + A1)).margin(1e-15));
        // Rigidly moved: still the same energy.
        const Mat3 Q = Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized()).toRotationMatrix();
        Vec3 s2 = Vec3::Zero();
        for (int i = 0; i < 4; ++i) s2 += hr.k[i] * (Q * x[i] + Vec3(1, 2, 3));
        CHECK(0.5 * kb * hr.scale * s2.squaredNorm() == Approx(E).margin(1e-15));
    }
}

TEST_CASE("springs and strand bending", "[elastic][hair]") {
    SpringElastic s;
    springForces(Vec3(0, 0, 0), Vec3(0, -0.012, 0), 0.01, 500.0, s);
    // Hooke: k = EA/L, force on the first end pulls towards the second.
    CHECK(s.f0.y() == Approx(-(500.0 / 0.01) * 0.002));
    CHECK(s.energy == Approx(0.5 * (500.0 / 0.01) * 0.002 * 0.002));
    // Stiffness = exact Hessian in tension (finite differences of the force).
    const Vec3 x0(0.001, 0.002, -0.003), x1(0.011, -0.004, 0.002);
    springForces(x0, x1, 0.01, 500.0, s);
    Mat3 fd;
    for (int c = 0; c < 3; ++c) {
        Vec3 p = x1, m = x1;
        p[c] += 1e-8;
        m[c] -= 1e-8;
        SpringElastic sp, sm;
        springForces(x0, p, 0.01, 500.0, sp);
        springForces(x0, m, 0.01, 500.0, sm);
        fd.col(c) = (sp.f0 - sm.f0) / 2e-8; // ∂f0/∂x1 = K
    }
    CHECK((fd - s.K).norm() <= 1e-5 * s.K.norm());
    // Bending weights: straight strands have d = 0; a kink gives the tangent change.
    const auto w = strandBendWeights(0.01, 0.02);
    const Vec3 a(0, 0, 0), b(0, -0.01, 0), c(0, -0.03, 0);
    CHECK((w[0] * a + w[1] * b + w[2] * c).norm() < 1e-12);
    const Vec3 ck(0.02, -0.01, 0);
    CHECK((w[0] * a + w[1] * b + w[2] * ck - (Vec3(1, 0, 0) - Vec3(0, -1, 0))).norm() < 1e-12);
}
