// The banded LDLᵀ against Eigen's dense LDLᵀ on random SPD band matrices made of independent
// blocks (strands), its components and band found from the pattern, the refactorisation of only
// the changed components (the same bits as a fresh factorisation), and a non-SPD matrix refused.
#include "solver/linalg/banded_ldlt.h"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <random>

using namespace gale::solver;

namespace {

// Strands of the given lengths, each a symmetric band of half-width w with random entries,
// made diagonally dominant (SPD).
Eigen::MatrixXd strands(const std::vector<int>& lengths, int w, std::mt19937& rng) {
    int n = 0;
    for (int l : lengths) n += l;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    int b = 0;
    for (int l : lengths) {
        for (int i = b; i < b + l; ++i)
            for (int j = std::max(b, i - w); j < i; ++j) A(i, j) = A(j, i) = U(rng);
        for (int i = b; i < b + l; ++i) A(i, i) = 2.0 * w + 1.0 + U(rng);
        b += l;
    }
    return A;
}

BandedLdlt::Matrix sparse(const Eigen::MatrixXd& A) {
    BandedLdlt::Matrix S = A.sparseView();
    S.makeCompressed();
    return S;
}

} // namespace

TEST_CASE("banded LDLT: solves like a dense LDLT, components from the pattern",
          "[linalg][banded]") {
    std::mt19937 rng(4);
    const std::vector<int> lengths = {9, 15, 3, 30, 12};
    for (int w : {1, 5, 14}) {
        const Eigen::MatrixXd A = strands(lengths, w, rng);
        BandedLdlt f;
        REQUIRE(f.analyze(sparse(A)));
        CHECK(f.halfBandwidth() == std::min(w, 29));
        CHECK(f.components() == static_cast<int>(lengths.size()));
        REQUIRE(f.factorize(sparse(A)));
        CHECK(f.lastRefactored() == static_cast<int>(lengths.size()));
        Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(
            A.rows(), [&] { return std::uniform_real_distribution<double>(-1, 1)(rng); });
        Eigen::VectorXd x;
        f.solve(b, x);
        const Eigen::VectorXd want = A.ldlt().solve(b);
        CHECK((x - want).norm() <= 1e-12 * want.norm());
        CHECK((A * x - b).norm() <= 1e-12 * b.norm());
    }
}

TEST_CASE("banded LDLT: only changed strands are refactored, with the same bits",
          "[linalg][banded]") {
    std::mt19937 rng(9);
    const std::vector<int> lengths = {12, 12, 12, 12, 12, 12};
    Eigen::MatrixXd A = strands(lengths, 8, rng);
    BandedLdlt f;
    REQUIRE(f.analyze(sparse(A)));
    REQUIRE(f.factorize(sparse(A)));
    // The same values again: nothing to do.
    REQUIRE(f.factorize(sparse(A)));
    CHECK(f.lastRefactored() == 0);
    // One entry of strand 3 (rows 36..47) changes, as a contact filter would change its rows.
    A(40, 38) = A(38, 40) = 0.25;
    A(40, 40) += 1.0;
    REQUIRE(f.factorize(sparse(A)));
    CHECK(f.lastRefactored() == 1);
    BandedLdlt fresh;
    REQUIRE(fresh.analyze(sparse(A)));
    REQUIRE(fresh.factorize(sparse(A)));
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
    Eigen::VectorXd x, y;
    f.solve(b, x);
    fresh.solve(b, y);
    CHECK(x == y); // bit for bit
    CHECK((A * x - b).norm() <= 1e-12 * b.norm());
}

TEST_CASE("banded LDLT: a solve substitutes only where the factor or b changed, with the same bits",
          "[linalg][banded]") {
    // The contact active set's rounds: the same system solved again after a few strands'
    // filters (their rows and their right-hand side) changed.
    std::mt19937 rng(13);
    const std::vector<int> lengths = {10, 10, 10, 10, 10, 10, 10, 10};
    Eigen::MatrixXd A = strands(lengths, 6, rng);
    BandedLdlt f;
    REQUIRE(f.analyze(sparse(A)));
    REQUIRE(f.factorize(sparse(A)));
    Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0), x;
    f.solve(b, x);
    CHECK(f.lastSolved() == 8);
    f.solve(b, x);
    CHECK(f.lastSolved() == 0); // nothing changed
    // Strand 2 (rows 20..29) refactored, strand 6's b (rows 60..69) changed.
    A(24, 23) = A(23, 24) = -0.5;
    b[65] += 0.75;
    REQUIRE(f.factorize(sparse(A)));
    f.solve(b, x);
    CHECK(f.lastSolved() == 2);
    BandedLdlt fresh;
    REQUIRE(fresh.analyze(sparse(A)));
    REQUIRE(fresh.factorize(sparse(A)));
    Eigen::VectorXd y;
    fresh.solve(b, y);
    CHECK(x == y); // bit for bit
    CHECK((A * x - b).norm() <= 1e-12 * b.norm());
    // In place (b and x the same vector), and a NaN in one strand's b stays in that strand.
    Eigen::VectorXd z = b;
    z[5] = std::nan("");
    f.solve(z, z);
    CHECK(f.lastSolved() == 1);
    CHECK(std::isnan(z[5]));
    CHECK(z.segment(10, 70) == y.segment(10, 70));
}

TEST_CASE("banded LDLT: a matrix that is not positive definite is refused", "[linalg][banded]") {
    std::mt19937 rng(2);
    Eigen::MatrixXd A = strands({5, 5}, 2, rng);
    BandedLdlt f;
    REQUIRE(f.analyze(sparse(A)));
    REQUIRE(f.factorize(sparse(A)));
    A(7, 7) = -1.0;
    CHECK_FALSE(f.factorize(sparse(A)));
    // After a refusal every component is factored again.
    A(7, 7) = 10.0;
    REQUIRE(f.factorize(sparse(A)));
    CHECK(f.lastRefactored() == 2);
    A(2, 2) = std::nan("");
    CHECK_FALSE(f.factorize(sparse(A)));
}

TEST_CASE("banded LDLT: refactor() of the marked strands gives factorize()'s bits",
          "[linalg][banded]") {
    // The caller that holds the matrix in another form (FilteredSolver's blocks) writes the
    // changed strands' bands itself.
    std::mt19937 rng(21);
    const std::vector<int> lengths = {9, 9, 9, 9};
    Eigen::MatrixXd A = strands(lengths, 5, rng);
    const auto fillFrom = [](BandedLdlt& f, const Eigen::MatrixXd& M) {
        return [&f, &M](int c) {
            for (int i = f.firstRow(c); i < f.endRow(c); ++i)
                for (int j = std::max(f.firstRow(c), i - f.halfBandwidth()); j <= i; ++j)
                    f.set(i, j, M(i, j));
        };
    };
    BandedLdlt f;
    REQUIRE(f.analyze(sparse(A)));
    CHECK(f.componentOf(0) == 0);
    CHECK(f.componentOf(20) == 2);
    CHECK(f.firstRow(2) == 18);
    CHECK(f.endRow(2) == 27);
    // Nothing factored yet: every strand, marked or not.
    std::vector<char> changed(4, 0);
    REQUIRE(f.refactor(changed, fillFrom(f, A)));
    CHECK(f.lastRefactored() == 4);
    // Strand 1 changes; only it is marked and refactored.
    A(12, 10) = A(10, 12) = 0.5;
    A(12, 12) += 2.0;
    changed[1] = 1;
    REQUIRE(f.refactor(changed, fillFrom(f, A)));
    CHECK(f.lastRefactored() == 1);
    BandedLdlt fresh;
    REQUIRE(fresh.analyze(sparse(A)));
    REQUIRE(fresh.factorize(sparse(A)));
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), 2.0, -1.0);
    Eigen::VectorXd x, y;
    f.solve(b, x);
    fresh.solve(b, y);
    CHECK(x == y); // bit for bit
    // factorize() afterwards sees the band refactor() wrote: nothing changed.
    REQUIRE(f.factorize(sparse(A)));
    CHECK(f.lastRefactored() == 0);
    // Refused as factorize() refuses, and everything refactored after.
    Eigen::MatrixXd bad = A;
    bad(30, 30) = -1.0;
    std::fill(changed.begin(), changed.end(), 0);
    changed[3] = 1;
    CHECK_FALSE(f.refactor(changed, fillFrom(f, bad)));
    changed[3] = 0;
    REQUIRE(f.refactor(changed, fillFrom(f, A)));
    CHECK(f.lastRefactored() == 4);
}
