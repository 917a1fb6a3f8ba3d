// aero.md reference case 3: one triangle over an angle sweep — drag and lift magnitudes,
// winding invariance, invariants (F·v ≥ 0, broadside independent of C_L, zero area), the
// exact Jacobian against finite differences, PSD damping matrices; and hair cross-flow drag.
#include "solver/bodies/aero.h"

#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace gale::solver;

namespace {

constexpr double kPi = 3.14159265358979323846;
const double kRho = 1.225;

double minEigen(const Mat3& m) {
    Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (m + m.transpose()));
    return es.eigenvalues().minCoeff();
}

// Nearest PSD matrix by a general eigendecomposition: an independent check of the closed form.
Mat3 projectByEigen(const Mat3& m) {
    Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (m + m.transpose()));
    Vec3 l = es.eigenvalues().cwiseMax(0.0);
    return es.eigenvectors() * l.asDiagonal() * es.eigenvectors().transpose();
}

// A triangle of area A in the plane z = 0, with normal (0, 0, ±1).
Vec3 areaNormal(double area, bool flipped) { return Vec3(0, 0, flipped ? -area : area); }

} // namespace

TEST_CASE("aero: drag and lift magnitudes over an angle sweep", "[aero]") {
    const double A = 0.02, U = 12.0, cl = 0.4, cd = 1.1;
    for (int deg = 0; deg <= 90; deg += 5) {
        const double th = deg * kPi / 180.0;
        // v at angle θ from the normal, in the x-z plane.
        const Vec3 v = U * Vec3(std::sin(th), 0.0, std::cos(th));
        const Vec3 vhat = v.normalized();
        for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift}) {
            const AeroResult r = aeroTriangle(v, areaNormal(A, false), kRho, cl, cd, model,
                                              AeroJacobian::Projected);
            const double q = 0.5 * kRho * A * U * U;
            const double drag = r.force.dot(vhat);
            const double lift = (r.force - drag * vhat).norm();
            CHECK(drag == Approx(q * cd * std::cos(th)).margin(1e-12));
            const double wantLift = model == AeroModel::Frozen ? q * cl * std::sin(th)
                                                               : q * cl * std::sin(th) * std::cos(th);
            CHECK(lift == Approx(wantLift).margin(1e-12));
            // Lift is perpendicular to v and lies in the plane of v and n (pushes away from n's
            // side the wind comes from: towards +z here, i.e. F·n ≥ 0).
            CHECK(std::abs(r.force.y()) < 1e-12);
            CHECK(r.force.z() >= -1e-12);
        }
    }
}

TEST_CASE("aero: invariants — winding, F·v ≥ 0, broadside, zero area, zero speed", "[aero]") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 200; ++k) {
        const Vec3 v = 15.0 * Vec3(u(rng), u(rng), u(rng));
        const Vec3 an = 0.05 * Vec3(u(rng), u(rng), u(rng));
        const double cl = 0.5 * (1 + u(rng)), cd = 0.5 * (1 + u(rng)) + 0.2;
        for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift})
            for (AeroJacobian jac :
                 {AeroJacobian::Bounded, AeroJacobian::Projected, AeroJacobian::Paper}) {
                const AeroResult a = aeroTriangle(v, an, kRho, cl, cd, model, jac);
                const AeroResult b = aeroTriangle(v, -an, kRho, cl, cd, model, jac);
                CHECK((a.force - b.force).norm() <= 1e-12 * (1 + a.force.norm()));
                CHECK((a.damping - b.damping).norm() <= 1e-12 * (1 + a.damping.norm()));
                // F·v = ½ρA C_D (v·n)|v|² ≥ 0.
                const double s = std::abs(v.dot(an.normalized()));
                CHECK(a.force.dot(v) == Approx(0.5 * kRho * an.norm() * cd * s * v.squaredNorm()).epsilon(1e-10));
            }
    }
    // Broadside: independent of C_L.
    const Vec3 v(0, 0, -9.0);
    const AeroResult r1 = aeroTriangle(v, areaNormal(0.1, false), kRho, 0.0, 1.0, AeroModel::Frozen, AeroJacobian::Projected);
    const AeroResult r2 = aeroTriangle(v, areaNormal(0.1, false), kRho, 0.9, 1.0, AeroModel::Frozen, AeroJacobian::Projected);
    CHECK((r1.force - r2.force).norm() < 1e-12);
    CHECK(r1.force.z() == Approx(-0.5 * kRho * 0.1 * 81.0));
    // Zero area and zero relative velocity give exactly zero, never NaN.
    for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift}) {
        const AeroResult z1 = aeroTriangle(Vec3(3, 4, 5), Vec3::Zero(), kRho, 0.3, 1.0, model, AeroJacobian::Projected);
        const AeroResult z2 = aeroTriangle(Vec3::Zero(), areaNormal(0.1, false), kRho, 0.3, 1.0, model, AeroJacobian::Projected);
        CHECK(z1.force == Vec3::Zero());
        CHECK(z1.damping == Mat3::Zero());
        CHECK(z2.force == Vec3::Zero());
        CHECK(z2.damping == Mat3::Zero());
        CHECK(aeroTriangleExactJacobian(Vec3::Zero(), areaNormal(0.1, false), kRho, 0.3, 1.0, model).allFinite());
    }
}

TEST_CASE("aero: exact Jacobian matches central finite differences", "[aero]") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int checked = 0;
    for (int k = 0; k < 300; ++k) {
        const Vec3 v = 10.0 * Vec3(u(rng), u(rng), u(rng));
        const Vec3 an = 0.03 * Vec3(u(rng), u(rng), u(rng));
        // Stay away from the edge-on discontinuity of the two-sided normal.
        if (std::abs(v.normalized().dot(an.normalized())) < 0.05) continue;
        for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift}) {
            const double cl = 0.6, cd = 1.2;
            const Mat3 J = aeroTriangleExactJacobian(v, an, kRho, cl, cd, model);
            Mat3 fd;
            const double eps = 1e-6;
            for (int c = 0; c < 3; ++c) {
                Vec3 dp = v, dm = v;
                dp[c] += eps;
                dm[c] -= eps;
                fd.col(c) = (aeroTriangle(dp, an, kRho, cl, cd, model, AeroJacobian::None).force -
                             aeroTriangle(dm, an, kRho, cl, cd, model, AeroJacobian::None).force) / (2 * eps);
            }
            CHECK((J - fd).norm() <= 1e-6 * (1.0 + J.norm()));
            ++checked;
        }
    }
    CHECK(checked > 400);
}

TEST_CASE("aero: the orientation Jacobian dF/da matches finite differences", "[aero]") {
    // Newton's full Jacobian needs how F turns with the triangle (AeroOrientation::position).
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int checked = 0;
    for (int k = 0; k < 400; ++k) {
        const Vec3 v = 12.0 * Vec3(u(rng), u(rng), u(rng));
        Vec3 an = 0.03 * Vec3(u(rng), u(rng), u(rng));
        // A quarter of the cases within 2° of edge-on (but not across it: the frozen lift flips).
        if (k % 4 == 0) {
            const Vec3 vh = v.normalized();
            an -= an.dot(vh) * vh;
            an += (0.5 + 0.4 * u(rng)) * std::sin(2.0 * kPi / 180.0) * an.norm() * vh;
        }
        if (std::abs(v.normalized().dot(an.normalized())) < 1e-3) continue;
        for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift}) {
            const double cl = 0.9, cd = 0.7;
            const Mat3 G = aeroTriangleAreaJacobian(v, an, kRho, cl, cd, model);
            Mat3 fd;
            const double eps = 1e-7 * an.norm();
            for (int c = 0; c < 3; ++c) {
                Vec3 ap = an, am = an;
                ap[c] += eps;
                am[c] -= eps;
                fd.col(c) = (aeroTriangle(v, ap, kRho, cl, cd, model, AeroJacobian::None).force -
                             aeroTriangle(v, am, kRho, cl, cd, model, AeroJacobian::None).force) /
                            (2 * eps);
            }
            CHECK((G - fd).norm() <= 1e-5 * (1.0 + G.norm()));
            ++checked;
        }
    }
    CHECK(checked > 700);
}

TEST_CASE("aero: damping matrices are symmetric positive semi-definite", "[aero]") {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 500; ++k) {
        Vec3 v = 20.0 * Vec3(u(rng), u(rng), u(rng));
        const Vec3 an = 0.02 * Vec3(u(rng), u(rng), u(rng));
        if (k % 5 == 0) v -= v.dot(an.normalized()) * an.normalized(); // exactly edge-on
        const double cl = 0.8 * (1 + u(rng)), cd = 0.8 * (1 + u(rng));
        for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift}) {
            const AeroResult p = aeroTriangle(v, an, kRho, cl, cd, model, AeroJacobian::Projected);
            CHECK((p.damping - p.damping.transpose()).norm() <= 1e-12 * (1 + p.damping.norm()));
            CHECK(minEigen(p.damping) >= -1e-10 * (1 + p.damping.norm()));
            // The closed-form projection equals the general eigen-decomposition one.
            const Mat3 J = aeroTriangleExactJacobian(v, an, kRho, cl, cd, model);
            CHECK((p.damping - projectByEigen(J)).norm() <= 1e-9 * (1 + J.norm()));
            const AeroResult q = aeroTriangle(v, an, kRho, cl, cd, model, AeroJacobian::Paper);
            CHECK(minEigen(q.damping) >= -1e-10 * (1 + q.damping.norm()));
            CHECK(q.clamped == (cd < cl && v.squaredNorm() > 0));
        }
    }
}

TEST_CASE("aero: the bounded damping is PSD, diagonal in (n, e, n × e) and above the exact one",
          "[aero]") {
    // D_bounded ⪰ sym(∂F/∂v): the exact Jacobian's symmetric part with its normal–in-plane
    // coupling a12 moved onto both diagonals (diag(|a12|, |a12|) − a12(neᵀ + enᵀ) is PSD), so
    // D − sym(J) has no negative eigenvalue; D is itself PSD and, unlike the projected damping
    // (also above sym(J), rank one in the (n, e) plane where sym(J) is indefinite there),
    // couples none of n, e = the in-plane direction of v, and b = n × e.
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 500; ++k) {
        Vec3 v = 20.0 * Vec3(u(rng), u(rng), u(rng));
        const Vec3 an = 0.02 * Vec3(u(rng), u(rng), u(rng));
        Vec3 n = an.normalized();
        if (k % 5 == 0) v -= v.dot(n) * n; // exactly edge-on
        if (k % 7 == 0) v = 9.0 * n;       // broadside: no in-plane direction
        if (n.dot(v) < 0) n = -n;
        const double cl = 0.8 * (1 + u(rng)), cd = 0.8 * (1 + u(rng));
        for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift}) {
            const AeroResult d = aeroTriangle(v, an, kRho, cl, cd, model, AeroJacobian::Bounded);
            const Mat3 J = aeroTriangleExactJacobian(v, an, kRho, cl, cd, model);
            const Mat3 sym = 0.5 * (J + J.transpose());
            const double tol = 1e-10 * (1 + J.norm());
            CHECK((d.damping - d.damping.transpose()).norm() <= tol);
            CHECK(minEigen(d.damping) >= -tol);
            CHECK(minEigen(d.damping - sym) >= -tol);
            const Vec3 inPlane = v - v.dot(n) * n;
            if (inPlane.norm() > 1e-9 * v.norm()) {
                const Vec3 e = inPlane.normalized(), b = n.cross(e);
                CHECK(std::abs(e.dot(d.damping * n)) <= tol);
                CHECK(std::abs(b.dot(d.damping * n)) <= tol);
                CHECK(std::abs(b.dot(d.damping * e)) <= tol);
            } else { // no coupling to move: the projection of the exact Jacobian
                const AeroResult p =
                    aeroTriangle(v, an, kRho, cl, cd, model, AeroJacobian::Projected);
                CHECK((d.damping - p.damping).norm() <= tol);
            }
            // The same force and skew part as the projected linearisation.
            const AeroResult p = aeroTriangle(v, an, kRho, cl, cd, model, AeroJacobian::Projected);
            CHECK(d.force == p.force);
            CHECK(d.skewAxis == p.skewAxis);
        }
    }
    // Edge-on (frozen, C_L = 0.3, C_D = 1): sym(J) = ½ρA (C_D + C_L)/2 (v nᵀ + n vᵀ); the bound
    // damps the normal and the flow direction each by ½ρA (C_D + C_L)|v|/2 — the projected
    // damping's one eigenvalue — and the third direction not at all.
    const Vec3 v(20.0, 0.0, 0.0);
    const AeroResult d = aeroTriangle(v, areaNormal(0.01, false), kRho, 0.3, 1.0, AeroModel::Frozen,
                                      AeroJacobian::Bounded);
    const double want = 0.5 * kRho * 0.01 * 1.3 * 20.0 / 2.0;
    CHECK(d.damping(2, 2) == Approx(want));
    CHECK(d.damping(0, 0) == Approx(want));
    CHECK(d.damping(1, 1) == Approx(0.0).margin(1e-15));
}

TEST_CASE("aero: a normal push on a streaming triangle moves it along its normal, not the wind",
          "[aero]") {
    // The linearised step of one triangle (mass m, step h) under a push F n along its normal,
    // (m I + h D) Δv = h F n, on a flag streaming 3° off edge-on in a 20 m/s wind (the gossamer
    // flag: σ = 0.005 kg/m², a triangle of 1 cm²). The bounded damping is diagonal in (n, e, b):
    // Δv stays along n. The projected one, rank one along (n + e)/√2 where sym(∂F/∂v) is
    // indefinite, turns the push half into motion along the wind e: as much as along n once
    // hλ ≫ m — the along-wind stretch of a fluttering flag's linearised step (docs/solver.md).
    const double a = 3.0 * kPi / 180.0, A = 1e-4, m = 0.005 * A, h = 1.0 / 24.0;
    const Vec3 v(20.0 * std::cos(a), 0.0, 20.0 * std::sin(a)); // n = +z, e = +x
    const Vec3 n = Vec3::UnitZ(), e = Vec3::UnitX();
    const auto step = [&](AeroJacobian jac) {
        const AeroResult r =
            aeroTriangle(v, areaNormal(A, false), kRho, 0.3, 1.0, AeroModel::Frozen, jac);
        const Mat3 lhs = m * Mat3::Identity() + h * r.damping;
        return Vec3(lhs.ldlt().solve(h * 1e-3 * n));
    };
    const Vec3 bounded = step(AeroJacobian::Bounded), projected = step(AeroJacobian::Projected);
    CAPTURE(bounded.transpose(), projected.transpose());
    CHECK(bounded.dot(n) > 0.0);
    CHECK(std::abs(bounded.dot(e)) <= 1e-12 * bounded.norm());
    CHECK(std::abs(projected.dot(e)) > 0.8 * projected.dot(n));
}

TEST_CASE("aero: edge-on, the paper's Jacobian vanishes but the projected one does not", "[aero]") {
    const Vec3 v(20.0, 0.0, 0.0); // in the plane z = 0
    const AeroResult paper = aeroTriangle(v, areaNormal(0.01, false), kRho, 0.3, 1.0, AeroModel::Frozen, AeroJacobian::Paper);
    const AeroResult proj = aeroTriangle(v, areaNormal(0.01, false), kRho, 0.3, 1.0, AeroModel::Frozen, AeroJacobian::Projected);
    CHECK(paper.damping.norm() == 0.0);
    CHECK(paper.force.norm() == Approx(0.5 * kRho * 0.01 * 0.3 * 400.0)); // all lift, along n
    // sym(∂F/∂v) = ½ρA (C_D + C_L)/2 (v nᵀ + n vᵀ): eigenvalues ±½ρA(C_D + C_L)|v|/2, keep +.
    Eigen::SelfAdjointEigenSolver<Mat3> es(proj.damping);
    CHECK(es.eigenvalues().maxCoeff() == Approx(0.5 * kRho * 0.01 * 1.3 * 20.0 / 2.0));
    // Smooth lift: no force along n edge-on.
    const AeroResult smooth = aeroTriangle(v, areaNormal(0.01, false), kRho, 0.3, 1.0, AeroModel::SmoothLift, AeroJacobian::Projected);
    CHECK(smooth.force.norm() == 0.0);
}

TEST_CASE("aero: hair cross-flow drag and its Jacobian", "[aero][hair]") {
    const Vec3 t = Vec3(1, 2, 2).normalized();
    const double L = 0.01, d = 8e-5, cn = 1.2, ct = 0.05;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 100; ++k) {
        const Vec3 v = 6.0 * Vec3(u(rng), u(rng), u(rng));
        const AeroResult r = aeroSegment(v, t, L, d, kRho, cn, ct);
        const Vec3 vt = v.dot(t) * t, vn = v - vt;
        CHECK((r.force - (0.5 * kRho * cn * d * L * vn.norm() * vn +
                          0.5 * kRho * ct * kPi * d * L * vt.norm() * vt)).norm() < 1e-15);
        Mat3 fd;
        const double eps = 1e-6;
        for (int c = 0; c < 3; ++c) {
            Vec3 dp = v, dm = v;
            dp[c] += eps;
            dm[c] -= eps;
            fd.col(c) = (aeroSegment(dp, t, L, d, kRho, cn, ct).force - aeroSegment(dm, t, L, d, kRho, cn, ct).force) / (2 * eps);
        }
        CHECK((r.damping - fd).norm() <= 1e-6 * (1e-9 + r.damping.norm()));
        CHECK(minEigen(r.damping) >= -1e-18);
    }
    CHECK(aeroSegment(Vec3::Zero(), t, L, d, kRho, cn, ct).force == Vec3::Zero());
}

TEST_CASE("aero: in-plane PSD projection — diagonal, equal-eigenvalue and v ∥ n cases", "[aero]") {
    std::mt19937 rng(19);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 400; ++k) {
        const Vec3 n = Vec3(u(rng), u(rng), u(rng)).normalized();
        Vec3 v = 5.0 * Vec3(u(rng), u(rng), u(rng));
        if (k % 4 == 1) v = 3.0 * n; // v along n: any perpendicular
        Vec3 e = v - v.dot(n) * n;
        e = e.norm() > 1e-9 ? Vec3(e.normalized()) : Vec3(n.unitOrthogonal());
        const Vec3 b = n.cross(e);
        // j = c I + terms in span{n, e}, with a diagonal (a12 = 0) or isotropic in-plane block
        // in some cases, of either sign.
        const bool along = k % 4 == 1; // then j = c I + (terms in span{n}) only
        const double c = u(rng), a11 = u(rng);
        const double a22 = along ? c : k % 3 == 0 ? a11 : u(rng);
        const double a12 = along || k % 5 == 0 ? 0.0 : u(rng), skew = along ? 0.0 : u(rng);
        const Mat3 j = c * b * b.transpose() + a11 * n * n.transpose() + a22 * e * e.transpose() +
                       (a12 + skew) * n * e.transpose() + (a12 - skew) * e * n.transpose();
        const Mat3 p = projectPsdInPlane(j, n, v);
        CHECK(p.allFinite());
        CHECK((p - p.transpose()).norm() <= 1e-14 * (1 + p.norm()));
        CHECK((p - projectByEigen(j)).norm() <= 1e-12 * (1 + j.norm()));
    }
}

TEST_CASE("aero: the skew axis is the antisymmetric part of the exact Jacobian", "[aero]") {
    // Against ½(J − Jᵀ) of the exact Jacobian (itself checked by finite differences above),
    // read as an axial vector: W x = ω × x ⇔ ω = (W₂₁, W₀₂, W₁₀). Kept where |c_w| > ½(C_D + C_L)
    // (c_w = C_D − 3 C_L frozen, C_D − 3 C_L s/r smooth-lift), zero elsewhere.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int kept = 0, dropped = 0;
    for (AeroModel model : {AeroModel::Frozen, AeroModel::SmoothLift})
        for (int trial = 0; trial < 200; ++trial) {
            const Vec3 v(10 * u(rng), 10 * u(rng), 10 * u(rng));
            const Vec3 an(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
            const double cl = 0.5 + 0.5 * u(rng), cd = 0.5 + 0.5 * u(rng);
            const AeroResult r = aeroTriangle(v, an, kRho, cl, cd, model, AeroJacobian::Projected);
            const Mat3 j = aeroTriangleExactJacobian(v, an, kRho, cl, cd, model);
            const Mat3 w = 0.5 * (j - j.transpose());
            const Vec3 axis(w(2, 1), w(0, 2), w(1, 0));
            Vec3 n = an.normalized();
            if (n.dot(v) < 0) n = -n;
            const double cw =
                model == AeroModel::Frozen ? cd - 3 * cl : cd - 3 * cl * n.dot(v) / v.norm();
            if (std::abs(cw) > 0.5 * (cd + cl)) {
                ++kept;
                CHECK((r.skewAxis - axis).norm() <= 1e-10 * (1.0 + axis.norm()));
            } else {
                ++dropped;
                CHECK(r.skewAxis.norm() == 0.0);
            }
        }
    CHECK(kept > 20);
    CHECK(dropped > 20);
}
