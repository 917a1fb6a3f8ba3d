// The filtered linear solve: PCG and LDLᵀ agree, honour pins (Δv = z) and plane constraints
// (n·Δv = n·z), and solve the unconstrained directions exactly (S(AΔv − b) = 0).
#include "solver/linalg/linear.h"

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <random>

using namespace gale::solver;

TEST_CASE("linear: PCG and LDLT solve the filtered system alike", "[linear]") {
    const int n = 60;
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<std::pair<int, int>> pairs;
    for (int i = 0; i + 1 < n; ++i) pairs.push_back({i, i + 1});
    for (int i = 0; i + 7 < n; i += 3) pairs.push_back({i, i + 7});
    BlockMatrix A;
    A.build(n, pairs);
    // SPD: M + Σ over pairs of a PSD coupling [B, −B; −B, B].
    for (int i = 0; i < n; ++i) A.addDiagonal(A.diagonalSlot(i), 0.5 + 0.5 * (u(rng) + 1));
    for (const auto& p : pairs) {
        Eigen::Matrix3d R = Eigen::Matrix3d::NullaryExpr([&] { return u(rng); });
        const Mat3 B = R * R.transpose() * 20.0;
        A.addBlock(A.slot(p.first, p.first), B);
        A.addBlock(A.slot(p.second, p.second), B);
        A.addBlock(A.slot(p.first, p.second), B, -1.0);
        A.addBlock(A.slot(p.second, p.first), B, -1.0);
    }
    VecX b(3 * n);
    for (int k = 0; k < 3 * n; ++k) b[k] = u(rng);
    Constraints c;
    c.reset(n);
    c.kind[0] = 1;
    c.z[0] = 0.3, c.z[1] = -0.2, c.z[2] = 0.1;
    c.kind[17] = 2;
    const Vec3 nrm = Vec3(1, 2, 2).normalized();
    vec3At(c.normal.data(), 17) = nrm;
    vec3At(c.z.data(), 17) = 0.05 * nrm;
    FilteredSolver s1, s2;
    VecX x1 = VecX::Zero(3 * n), x2 = VecX::Zero(3 * n);
    const SolveStatus p = s1.solve(A, c, b, x1, LinearSolverKind::Pcg, 1e-12, 1000);
    const SolveStatus d = s2.solve(A, c, b, x2, LinearSolverKind::Direct, 0, 0);
    CHECK(p.converged);
    CHECK(d.converged);
    CHECK((x1 - x2).norm() < 1e-9 * x2.norm());
    CHECK((x1.segment<3>(0) - Vec3(0.3, -0.2, 0.1)).norm() < 1e-14);
    CHECK(nrm.dot(x1.segment<3>(3 * 17)) == Approx(0.05));
    // The residual vanishes in the free directions.
    VecX r(3 * n);
    A.multiply(x1.data(), r.data());
    r -= b;
    c.apply(r.data());
    CHECK(r.norm() < 1e-9 * b.norm());
    // Against a dense solve of the same filtered system (S A S + I − S) y = S (b − A z).
    const Eigen::MatrixXd D = Eigen::MatrixXd(A.scalar());
    Eigen::MatrixXd S = Eigen::MatrixXd::Identity(3 * n, 3 * n);
    for (int i = 0; i < n; ++i) S.block<3, 3>(3 * i, 3 * i) = c.filter(i);
    const VecX z = Eigen::Map<const VecX>(c.z.data(), 3 * n);
    const Eigen::MatrixXd Ahat = S * D * S + Eigen::MatrixXd::Identity(3 * n, 3 * n) - S;
    const VecX y = Ahat.ldlt().solve(S * (b - D * z));
    CHECK((S * y + z - x1).norm() < 1e-9 * x1.norm());
}
