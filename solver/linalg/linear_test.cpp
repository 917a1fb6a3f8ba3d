// The filtered linear solve: PCG and LDLᵀ agree, honour pins (Δv = z) and plane constraints
// (n·Δv = n·z), and solve the unconstrained directions exactly (S(AΔv − b) = 0).
#include "solver/linalg/linear.h"

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <random>

using namespace gale::solver;

namespace {
// A random system: A SPD, a random mass on the diagonal plus, for each pair, a PSD coupling
// [B, −B; −B, B]; returns a random right-hand side.
VecX randomSystem(BlockMatrix& A, int n, const std::vector<std::pair<int, int>>& pairs,
                  std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    A.build(n, pairs);
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
    return b;
}
} // namespace

TEST_CASE("linear: PCG and LDLT solve the filtered system alike", "[linear]") {
    const int n = 60;
    std::mt19937 rng(9);
    std::vector<std::pair<int, int>> pairs;
    for (int i = 0; i + 1 < n; ++i) pairs.push_back({i, i + 1});
    for (int i = 0; i + 7 < n; i += 3) pairs.push_back({i, i + 7});
    BlockMatrix A;
    const VecX b = randomSystem(A, n, pairs, rng);
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

TEST_CASE("linear: the direct solve of strands across a contact's rounds", "[linear]") {
    // Hair: strands each coupling a vertex to its next two (a band), solved directly in its
    // natural order. Between rounds a vertex's filter and another strand's diagonal block (a
    // friction damping) change; the solver rewrites and refactors those strands from the
    // blocks. Its answer has the bits of a fresh solver's and matches a dense solve of the
    // filtered system.
    const int strands = 5, per = 7, n = strands * per;
    std::mt19937 rng(31);
    std::vector<std::pair<int, int>> pairs;
    for (int s = 0; s < strands; ++s)
        for (int k = 0; k < per; ++k) {
            const int i = s * per + k;
            if (k + 1 < per) pairs.push_back({i, i + 1});
            if (k + 2 < per) pairs.push_back({i, i + 2});
        }
    BlockMatrix A;
    const VecX b = randomSystem(A, n, pairs, rng);
    Constraints c;
    c.reset(n);
    for (int s = 0; s < strands; ++s) c.kind[s * per] = 1; // the roots
    c.kind[10] = 2;
    vec3At(c.normal.data(), 10) = Vec3(0, 1, 0);
    const auto dense = [&](const Constraints& cc) {
        const Eigen::MatrixXd D = Eigen::MatrixXd(A.scalar());
        Eigen::MatrixXd S = Eigen::MatrixXd::Identity(3 * n, 3 * n);
        for (int i = 0; i < n; ++i) S.block<3, 3>(3 * i, 3 * i) = cc.filter(i);
        const VecX z = Eigen::Map<const VecX>(cc.z.data(), 3 * n);
        const Eigen::MatrixXd Ahat = S * D * S + Eigen::MatrixXd::Identity(3 * n, 3 * n) - S;
        return VecX(S * Ahat.ldlt().solve(S * (b - D * z)) + z);
    };
    FilteredSolver rounds;
    VecX x = VecX::Zero(3 * n);
    REQUIRE(rounds.solve(A, c, b, x, LinearSolverKind::Direct, 0, 0).converged);
    CHECK((x - dense(c)).norm() < 1e-10 * x.norm());
    // Round 2: a contact made on strand 3, its plane tilted; strand 2's vertex 16 slides with
    // friction (its diagonal block gains c (I − nnᵀ)); the plane of vertex 10 (strand 1) turns.
    c.kind[3 * per + 4] = 2;
    vec3At(c.normal.data(), 3 * per + 4) = Vec3(1, 2, 2).normalized();
    vec3At(c.normal.data(), 10) = Vec3(0, 0.6, 0.8);
    A.addBlock(A.diagonalSlot(16),
               Mat3(Mat3::Identity() - Vec3::UnitY() * Vec3::UnitY().transpose()), 3.5);
    REQUIRE(rounds.solve(A, c, b, x, LinearSolverKind::Direct, 0, 0).converged);
    FilteredSolver fresh;
    VecX y = VecX::Zero(3 * n);
    REQUIRE(fresh.solve(A, c, b, y, LinearSolverKind::Direct, 0, 0).converged);
    CHECK(x == y); // bit for bit
    CHECK((x - dense(c)).norm() < 1e-10 * x.norm());
    CHECK(Vec3(1, 2, 2).normalized().dot(x.segment<3>(3 * (3 * per + 4))) ==
          Approx(0.0).margin(1e-12));
    // Round 3: the contact released again, nothing else: the first round's system but for
    // vertex 10's plane and strand 2's friction.
    c.kind[3 * per + 4] = 0;
    REQUIRE(rounds.solve(A, c, b, x, LinearSolverKind::Direct, 0, 0).converged);
    FilteredSolver fresh3;
    VecX w = VecX::Zero(3 * n);
    REQUIRE(fresh3.solve(A, c, b, w, LinearSolverKind::Direct, 0, 0).converged);
    CHECK(x == w);
    CHECK((x - dense(c)).norm() < 1e-10 * x.norm());
}
