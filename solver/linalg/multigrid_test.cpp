// The aggregation-multigrid preconditioner on a cloth-like filtered system (a mass-spring sheet
// with pins and plane contacts): multigrid PCG agrees with the sparse LDLᵀ, the V-cycle is
// symmetric and positive, and it needs far fewer iterations than block Jacobi; the scene key.
#include "solver/linalg/linear.h"
#include "scene/sim_scene.h"
#include "solver/linalg/test_sheets.h"

#include <catch2/catch.hpp>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <unistd.h>

using namespace gale::solver;

namespace {

struct Sheet {
    BlockMatrix A;
    Constraints c;
    VecX b;
    std::vector<int> constrained;
};

// An n×n sheet of 1 m, σ = 0.1 kg/m², wavy out of plane; springs along the grid edges and one
// diagonal with stiffness k along the edge (and 1% across), the backward-Euler matrix
// M + h²K at h = 1/240 s. Pins on the top row, a plane contact on a patch.
Sheet makeSheet(int n, bool constraints) {
    Sheet s;
    const double h = 1.0 / 240.0, k = 2000.0, sigma = 0.1;
    const double dx = 1.0 / (n - 1);
    auto id = [n](int i, int j) { return j * n + i; };
    auto pos = [&](int i, int j) {
        const double x = i * dx, y = j * dx;
        return Vec3(x, y, 0.05 * std::sin(6.0 * x) * std::cos(5.0 * y));
    };
    std::vector<std::pair<int, int>> pairs;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            if (i + 1 < n) pairs.push_back({id(i, j), id(i + 1, j)});
            if (j + 1 < n) pairs.push_back({id(i, j), id(i, j + 1)});
            if (i + 1 < n && j + 1 < n) pairs.push_back({id(i, j), id(i + 1, j + 1)});
        }
    const int nv = n * n;
    s.A.build(nv, pairs);
    for (int v = 0; v < nv; ++v) s.A.addDiagonal(s.A.diagonalSlot(v), sigma * dx * dx);
    for (const auto& p : pairs) {
        const Vec3 d = (pos(p.second % n, p.second / n) - pos(p.first % n, p.first / n)).normalized();
        const Mat3 B = h * h * k * (d * d.transpose() + 0.01 * (Mat3::Identity() - d * d.transpose()));
        s.A.addBlock(s.A.slot(p.first, p.first), B);
        s.A.addBlock(s.A.slot(p.second, p.second), B);
        s.A.addBlock(s.A.slot(p.first, p.second), B, -1.0);
        s.A.addBlock(s.A.slot(p.second, p.first), B, -1.0);
    }
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    s.b.resize(3 * nv);
    for (int q = 0; q < 3 * nv; ++q) s.b[q] = 1e-3 * u(rng);
    s.c.reset(nv);
    if (constraints) {
        for (int i = 0; i < n; ++i) {
            const int v = id(i, n - 1);
            s.c.kind[v] = 1;
            vec3At(s.c.z.data(), v) = Vec3(0.01 * u(rng), 0.0, 0.02);
        }
        const Vec3 nrm = Vec3(0.1, -0.2, 1.0).normalized();
        for (int j = n / 8; j < n / 8 + 4; ++j)
            for (int i = n / 4; i < n / 4 + 4; ++i) {
                const int v = id(i, j);
                s.c.kind[v] = 2;
                vec3At(s.c.normal.data(), v) = nrm;
                vec3At(s.c.z.data(), v) = 0.01 * nrm;
            }
    }
    for (int v = 0; v < nv; ++v)
        if (s.c.kind[v]) s.constrained.push_back(v);
    return s;
}

} // namespace

TEST_CASE("multigrid: PCG agrees with LDLT on a filtered sheet with pins and contacts", "[multigrid]") {
    Sheet s = makeSheet(24, true);
    FilteredSolver mg, direct;
    mg.setPreconditioner(Preconditioner::Multigrid);
    VecX x1 = VecX::Zero(s.b.size()), x2 = VecX::Zero(s.b.size());
    const SolveStatus p = mg.solve(s.A, s.c, s.b, x1, LinearSolverKind::Pcg, 1e-11, 500);
    const SolveStatus d = direct.solve(s.A, s.c, s.b, x2, LinearSolverKind::Direct, 0, 0);
    REQUIRE(p.converged);
    REQUIRE(d.converged);
    CHECK(mg.multigrid().levelCount() >= 2); // 576 vertices: a real hierarchy, not one dense solve
    CHECK((x1 - x2).norm() <= 1e-8 * x2.norm());
    // The constraints hold: pins exactly, contacts in the normal direction.
    const int pin = 24 * 23 + 5, contact = 24 * (24 / 8 + 1) + 24 / 4;
    REQUIRE(s.c.kind[pin] == 1);
    REQUIRE(s.c.kind[contact] == 2);
    CHECK((x1.segment<3>(3 * pin) - vec3At(s.c.z.data(), pin)).norm() < 1e-14);
    const Vec3 nrm = vec3At(s.c.normal.data(), contact);
    CHECK(nrm.dot(x1.segment<3>(3 * contact)) == Approx(0.01).epsilon(1e-10));
}

TEST_CASE("multigrid: the V-cycle is symmetric and positive definite", "[multigrid]") {
    for (bool multicolour : {true, false})
        for (bool constraints : {false, true}) {
            INFO((multicolour ? "multicolour" : "lexicographic")
                 << (constraints ? ", constrained" : ""));
            Sheet s = makeSheet(32, constraints);
            BlockMultigrid mg;
            mg.settings().multicolour = multicolour;
            REQUIRE(mg.refresh(s.A, s.c, s.constrained));
            REQUIRE(mg.levelCount() >= 2);
            const int n3 = 3 * s.A.size();
            std::mt19937 rng(11);
            std::uniform_real_distribution<double> u(-1.0, 1.0);
            for (int trial = 0; trial < 4; ++trial) {
                VecX x(n3), y(n3), bx(n3), by(n3);
                for (int q = 0; q < n3; ++q) x[q] = u(rng), y[q] = u(rng);
                mg.apply(x.data(), bx.data());
                mg.apply(y.data(), by.data());
                const double xBy = x.dot(by), yBx = y.dot(bx);
                CHECK(std::abs(xBy - yBx) <= 1e-10 * (std::abs(xBy) + bx.norm() * y.norm()));
                CHECK(x.dot(bx) > 0.0);
                CHECK(y.dot(by) > 0.0);
            }
            // Positive on a smooth vector too (the coarse levels' range), not only on noise.
            VecX smooth(n3), bs(n3);
            for (int q = 0; q < n3; ++q) smooth[q] = 1.0 + 0.1 * (q % 3);
            mg.apply(smooth.data(), bs.data());
            CHECK(smooth.dot(bs) > 0.0);
        }
}

TEST_CASE("multigrid: one level is an exact solve", "[multigrid]") {
    // 5×5 = 25 vertices stay below the coarsest size: the V-cycle is the dense Cholesky, so PCG
    // stops after one iteration.
    Sheet s = makeSheet(5, true);
    FilteredSolver mg;
    mg.setPreconditioner(Preconditioner::Multigrid);
    VecX x = VecX::Zero(s.b.size());
    const SolveStatus st = mg.solve(s.A, s.c, s.b, x, LinearSolverKind::Pcg, 1e-10, 50);
    CHECK(mg.multigrid().levelCount() == 1);
    CHECK(st.converged);
    CHECK(st.iterations == 1);
}

TEST_CASE("multigrid: far fewer iterations than block Jacobi on a 64x64 sheet", "[multigrid]") {
    Sheet s = makeSheet(64, true);
    FilteredSolver jacobi, mg;
    mg.setPreconditioner(Preconditioner::Multigrid);
    VecX x1 = VecX::Zero(s.b.size()), x2 = VecX::Zero(s.b.size());
    const SolveStatus j = jacobi.solve(s.A, s.c, s.b, x1, LinearSolverKind::Pcg, 1e-6, 5000);
    const SolveStatus m = mg.solve(s.A, s.c, s.b, x2, LinearSolverKind::Pcg, 1e-6, 5000);
    REQUIRE(j.converged);
    REQUIRE(m.converged);
    INFO("block Jacobi " << j.iterations << " iterations, multigrid " << m.iterations);
    CHECK(4 * m.iterations < j.iterations);
    CHECK((x1 - x2).norm() <= 1e-3 * x1.norm());
}

TEST_CASE("multigrid: single-precision products, checked and reported in double", "[multigrid]") {
    // At tolerances from kSinglePrecisionTolerance up, CG multiplies with a float copy of Â; the
    // status must still report the double-precision residual of the filtered system, computed
    // here independently of the multigrid's copies: Â y = S A S y + (I − S) y with the
    // assembled matrix and the constraint filter, rhs = S (b − A z).
    Sheet s = makeSheet(48, true);
    const long n3 = 3L * s.A.size();
    const VecX z = Eigen::Map<const VecX>(s.c.z.data(), n3);
    VecX Az(n3);
    s.A.multiply(z.data(), Az.data());
    VecX rhs = s.b - Az;
    s.c.apply(rhs.data());
    auto filteredProduct = [&](const VecX& y) {
        VecX Sy = y, out(n3);
        s.c.apply(Sy.data());
        s.A.multiply(Sy.data(), out.data());
        s.c.apply(out.data());
        return VecX(out + (y - Sy));
    };
    for (double tol : {1e-2, 1e-3, 1e-4, 1e-5, 1e-8}) {
        FilteredSolver mg;
        mg.setPreconditioner(Preconditioner::Multigrid);
        VecX x = VecX::Zero(n3);
        const SolveStatus st = mg.solve(s.A, s.c, s.b, x, LinearSolverKind::Pcg, tol, 500);
        INFO("tolerance " << tol << ": " << st.iterations << " iterations, residual " << st.residual);
        REQUIRE(st.converged);
        VecX y = x - z;
        s.c.apply(y.data());
        const double trueResidual = (rhs - filteredProduct(y)).norm() / rhs.norm();
        CHECK(trueResidual <= tol);
        // (CG's recurrence drifts from the true residual in its last digits.)
        CHECK(st.residual == Approx(trueResidual).epsilon(1e-3));
    }
}

TEST_CASE("multigrid: PCG gives the same bits on 1, 2 and 3 threads", "[multigrid]") {
    // parallelRows 0: every level sweeps colour by colour in parallel chunks (on more than one
    // thread); the default sweeps the small coarse levels sequentially. All the same bits.
    Sheet s = makeSheet(64, true);
    VecX ref;
    for (int parallelRows : {1024, 0})
        for (int threads : {1, 2, 3}) {
            tbb::task_arena arena(threads);
            VecX x = VecX::Zero(s.b.size());
            arena.execute([&] {
                FilteredSolver mg;
                mg.setPreconditioner(Preconditioner::Multigrid);
                mg.multigrid().settings().parallelRows = parallelRows;
                REQUIRE(mg.solve(s.A, s.c, s.b, x, LinearSolverKind::Pcg, 1e-8, 500).converged);
            });
            INFO(threads << " threads, parallelRows " << parallelRows);
            if (ref.size() == 0)
                ref = x;
            else
                CHECK((x - ref).cwiseAbs().maxCoeff() == 0.0);
        }
}

TEST_CASE("multigrid: each level's colours are independent sets", "[multigrid]") {
    Sheet s = makeSheet(48, true);
    BlockMultigrid mg;
    REQUIRE(mg.refresh(s.A, s.c, s.constrained));
    REQUIRE(mg.levelCount() >= 3);
    // The level-0 order is a permutation of A's vertices.
    const int n3 = 3 * s.A.size();
    VecX natural(n3), level(n3), back(n3);
    for (int q = 0; q < n3; ++q) natural[q] = q;
    mg.toLevelOrder(natural.data(), level.data());
    mg.fromLevelOrder(level.data(), back.data());
    CHECK(back == natural);
    std::vector<int> seen(s.A.size(), 0);
    for (int p = 0; p < s.A.size(); ++p) ++seen[static_cast<int>(level[3 * p]) / 3];
    CHECK(std::count(seen.begin(), seen.end(), 1) == s.A.size());
    for (int l = 0; l < mg.levelCount(); ++l) {
        const BsrMatrix& a = mg.matrix(l);
        const ColouredBlocks& cb = mg.colouring(l);
        INFO("level " << l << ": " << a.n << " rows, " << cb.blockStart.size() - 1 << " blocks, "
                      << cb.colours() << " colours");
        REQUIRE(cb.blockStart.back() == a.n);
        REQUIRE(cb.colourStart.back() == static_cast<int>(cb.blockStart.size()) - 1);
        std::vector<int> colour(a.n), block(a.n);
        for (int c = 0; c < cb.colours(); ++c)
            for (int bl = cb.colourStart[c]; bl < cb.colourStart[c + 1]; ++bl)
                for (int p = cb.blockStart[bl]; p < cb.blockStart[bl + 1]; ++p)
                    colour[p] = c, block[p] = bl;
        int coupled = 0; // blocks of a row's colour other than its own that it is coupled to
        for (int p = 0; p < a.n; ++p)
            for (int k = a.start[p]; k < a.start[p + 1]; ++k) {
                const int q = a.cols[k];
                if (block[q] != block[p] && colour[q] == colour[p]) ++coupled;
            }
        CHECK(coupled == 0);
        // Level 0 of a 48×48 sheet (blocks of 128 rows, couplings to ±49 rows): a few colours
        // of many blocks, enough to share between threads.
        if (l == 0) {
            CHECK(cb.colours() >= 2);
            CHECK(cb.colours() <= 4);
            CHECK(cb.blockStart.size() - 1 >= 18);
        }
    }
}

TEST_CASE("multigrid: the parallel V-cycle is symmetric and matches the sequential one",
          "[multigrid]") {
    Sheet s = makeSheet(40, true);
    const int n3 = 3 * s.A.size();
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    VecX x(n3), y(n3);
    for (int q = 0; q < n3; ++q) x[q] = u(rng), y[q] = u(rng);
    VecX bxSeq(n3);
    {
        BlockMultigrid seq;
        REQUIRE(seq.refresh(s.A, s.c, s.constrained));
        seq.apply(x.data(), bxSeq.data());
    }
    tbb::task_arena arena(2);
    arena.execute([&] {
        BlockMultigrid mg;
        mg.settings().parallelRows = 0;
        REQUIRE(mg.refresh(s.A, s.c, s.constrained));
        VecX bx(n3), by(n3);
        mg.apply(x.data(), bx.data());
        mg.apply(y.data(), by.data());
        CHECK((bx - bxSeq).cwiseAbs().maxCoeff() == 0.0);
        const double xBy = x.dot(by), yBx = y.dot(bx);
        CHECK(std::abs(xBy - yBx) <= 1e-10 * (std::abs(xBy) + bx.norm() * y.norm()));
        CHECK(x.dot(bx) > 0.0);
    });
}

// ---- smoothed aggregation with the rigid-body near-null space (issue 26) --------------------

namespace {

using gale::solver::testing::ClothSystem;
using gale::solver::testing::makeClothSystem;

struct MgRun {
    int iterations = 0;
    bool converged = false;
    VecX dv;
    int modes = 0;
    bool plain = false;
};

// smoothed: smoothed aggregation whatever the size (smoothedMinRows 0), else plain aggregation;
// automatic: the default choice by size.
MgRun solveMg(const ClothSystem& s, double tol, bool smoothed, bool rotations, int threads = 1,
              bool automatic = false, bool kCycle = false) {
    MgRun out;
    tbb::task_arena arena(threads);
    arena.execute([&] {
        FilteredSolver mg;
        mg.setPreconditioner(Preconditioner::Multigrid);
        if (!automatic) {
            mg.multigrid().settings().smoothed = smoothed;
            mg.multigrid().settings().smoothedMinRows = 0;
            mg.multigrid().settings().rotations = rotations;
            mg.multigrid().settings().kCycle = kCycle;
        }
        mg.multigrid().setPositions(s.x.data(), s.A.size());
        out.dv = VecX::Zero(s.b.size());
        const SolveStatus st = mg.solve(s.A, s.c, s.b, out.dv, LinearSolverKind::Pcg, tol, 1000);
        out.iterations = st.iterations;
        out.converged = st.converged;
        out.modes = mg.multigrid().modes();
        out.plain = mg.multigrid().plain();
    });
    return out;
}

// An irregular n×n sheet with a pinned 5×5 block (aggregates with no free direction: dead coarse
// unknowns) and every other vertex of rows j0 … j1 − 1, columns 2 … i1 − 1, on a plane; ref
// receives LDLᵀ's answer.
ClothSystem blockAndPlanes(int n, int j0, int j1, int i1, VecX& ref) {
    ClothSystem s = makeClothSystem(n, 1.0 / 24.0, true, true);
    for (int j = 5; j < 10; ++j)
        for (int i = 5; i < 10; ++i) s.c.kind[j * n + i] = 1;
    const Vec3 nrm = Vec3(0.3, 0.1, 1.0).normalized();
    for (int j = j0; j < j1; ++j)
        for (int i = 2; i < i1; i += 2) {
            s.c.kind[j * n + i] = 2;
            vec3At(s.c.normal.data(), j * n + i) = nrm;
        }
    FilteredSolver direct;
    ref = VecX::Zero(s.b.size());
    REQUIRE(direct.solve(s.A, s.c, s.b, ref, LinearSolverKind::Direct, 0.0, 0).converged);
    return s;
}

} // namespace

TEST_CASE("multigrid: smoothed aggregation, translations alone or with rotations, agrees with "
          "LDLT on irregular sheets",
          "[multigrid]") {
    for (bool rotations : {false, true})
        for (bool irregular : {false, true})
            for (double h : {1.0 / 24.0, 1.0 / 240.0}) {
                const ClothSystem s = makeClothSystem(24, h, irregular, true);
                FilteredSolver direct;
                VecX ref = VecX::Zero(s.b.size());
                REQUIRE(
                    direct.solve(s.A, s.c, s.b, ref, LinearSolverKind::Direct, 0.0, 0).converged);
                const double tol = 1e-9;
                const MgRun mg = solveMg(s, tol, true, rotations);
                INFO("rotations " << rotations << ", irregular " << irregular << ", h " << h << ": "
                                  << mg.iterations << " iterations");
                REQUIRE(mg.converged);
                CHECK(mg.modes == (rotations ? 6 : 3));
                // ‖Δv − Δv*‖ ≤ cond(Â)·tol·‖Δv*‖ in theory; the pinned rows are exact (S = 0).
                CHECK((mg.dv - ref).norm() <= 1e-6 * ref.norm());
                for (int v : s.constrained)
                    if (s.c.kind[v] == 1) CHECK((mg.dv - ref).segment<3>(3 * v).norm() == 0.0);
            }
}

TEST_CASE("multigrid: smoothed-aggregation iterations stay bounded from 32x32 to 256x256",
          "[multigrid][scaling][heavy]") {
    // The count at 256² against 32² (8× the resolution, 64× the vertices) at frame-size and
    // substep-size steps, regular and irregular: smoothed aggregation, with the translations
    // alone (the default; measured 8→11 at worst) and with rotations (6→9), stays within 1.6×;
    // plain aggregation on the same systems grows over 2.5× (20→68), which shows the systems are
    // hard enough for the bound to mean something.
    for (bool irregular : {false, true})
        for (double h : {1.0 / 24.0, 1.0 / 240.0}) {
            std::vector<int> sa, rot, plain;
            for (int n : {32, 64, 128, 256}) {
                const ClothSystem s = makeClothSystem(n, h, irregular, true);
                const MgRun r = solveMg(s, 1e-3, true, false);
                const MgRun rr = solveMg(s, 1e-3, true, true);
                REQUIRE(r.converged);
                REQUIRE(rr.converged);
                CHECK(r.modes == 3);
                CHECK(rr.modes == 6);
                sa.push_back(r.iterations);
                rot.push_back(rr.iterations);
                if (n == 32 || n == 256) plain.push_back(solveMg(s, 1e-3, false, false).iterations);
            }
            INFO("irregular " << irregular << ", h " << h << ": SA " << sa[0] << " " << sa[1] << " "
                              << sa[2] << " " << sa[3] << ", with rotations " << rot[0] << " "
                              << rot[1] << " " << rot[2] << " " << rot[3] << ", plain " << plain[0]
                              << " " << plain[1]);
            CHECK(*std::max_element(sa.begin(), sa.end()) <= 1.6 * sa[0]);
            CHECK(*std::max_element(rot.begin(), rot.end()) <= 1.6 * rot[0]);
            CHECK(sa.back() < plain.back());
            CHECK(plain[1] >= 2.5 * plain[0]);
        }
}

TEST_CASE("multigrid: setKind picks the hierarchy and its near-null space", "[multigrid]") {
    const ClothSystem s = makeClothSystem(16, 1.0 / 24.0, true, true);
    for (MultigridKind kind : {MultigridKind::Automatic, MultigridKind::Plain,
                               MultigridKind::Smoothed, MultigridKind::SmoothedRotations}) {
        FilteredSolver mg;
        mg.setPreconditioner(Preconditioner::Multigrid);
        mg.multigrid().setKind(kind);
        mg.multigrid().setPositions(s.x.data(), s.A.size()); // after the kind: kept for rotations
        VecX dv = VecX::Zero(s.b.size());
        REQUIRE(mg.solve(s.A, s.c, s.b, dv, LinearSolverKind::Pcg, 1e-8, 1000).converged);
        INFO("kind " << static_cast<int>(kind));
        const bool plain = kind == MultigridKind::Automatic || kind == MultigridKind::Plain;
        CHECK(mg.multigrid().plain() == plain); // 289 vertices: below smoothedMinRows
        CHECK(mg.multigrid().modes() == (kind == MultigridKind::SmoothedRotations ? 6 : 3));
        CHECK(mg.multigrid().settings().kCycle == (kind == MultigridKind::SmoothedRotations));
    }
}

TEST_CASE("multigrid: the K-cycle with flexible CG agrees with LDLT, on 1 and 2 threads alike",
          "[multigrid]") {
    // A pinned block and plane filters (blockAndPlanes) on an irregular sheet deep enough for
    // K-cycle levels (a level with another under it): the nonlinear preconditioner and the
    // flexible β still converge to the direct answer, bit for bit on any thread count.
    VecX ref;
    const ClothSystem s = blockAndPlanes(48, 20, 30, 30, ref);
    for (bool rotations : {false, true}) {
        const MgRun one = solveMg(s, 1e-9, true, rotations, 1, false, true);
        const MgRun two = solveMg(s, 1e-9, true, rotations, 2, false, true);
        const MgRun v = solveMg(s, 1e-9, true, rotations, 1, false, false);
        INFO("rotations " << rotations << ": K-cycle " << one.iterations << ", V-cycle "
                          << v.iterations << " iterations");
        REQUIRE(one.converged);
        CHECK((one.dv - ref).norm() <= 1e-6 * ref.norm());
        CHECK(one.iterations == two.iterations);
        CHECK((one.dv - two.dv).cwiseAbs().maxCoeff() == 0.0);
        // A different preconditioner indeed: not the V-cycle's iterates.
        CHECK((one.dv - v.dv).cwiseAbs().maxCoeff() > 0.0);
        // With the rotations (the scene's "smoothed-rotations") it does not cost iterations.
        if (rotations) CHECK(one.iterations <= v.iterations);
    }
}

TEST_CASE("multigrid: by default plain aggregation below smoothedMinRows, smoothed from there up",
          "[multigrid]") {
    const int threshold = BlockMultigrid::defaults().smoothedMinRows;
    REQUIRE(threshold > 0);
    const int below = static_cast<int>(std::floor(std::sqrt(threshold))) - 2; // (n+1)² < threshold
    const int above = static_cast<int>(std::ceil(std::sqrt(threshold)));      // (n+1)² > threshold
    const ClothSystem small = makeClothSystem(below, 1.0 / 24.0, false, true);
    const ClothSystem large = makeClothSystem(above, 1.0 / 24.0, false, true);
    REQUIRE(small.A.size() < threshold);
    REQUIRE(large.A.size() >= threshold);
    const MgRun a = solveMg(small, 1e-6, true, true, 1, true);
    const MgRun b = solveMg(large, 1e-6, true, true, 1, true);
    REQUIRE(a.converged);
    REQUIRE(b.converged);
    CHECK(a.plain);
    CHECK(a.modes == 3);
    CHECK_FALSE(b.plain);
    CHECK(b.modes == 3); // the translations alone (Settings::rotations off by default)
    // The automatic choice below the threshold is the forced plain path, bit for bit.
    const MgRun forced = solveMg(small, 1e-6, false, false, 1);
    CHECK(forced.plain);
    CHECK(forced.iterations == a.iterations);
    CHECK((forced.dv - a.dv).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("multigrid: smoothed aggregation gives the same bits on 1 and 2 threads", "[multigrid]") {
    const ClothSystem s = makeClothSystem(96, 1.0 / 24.0, true, true);
    for (bool rotations : {false, true}) {
        const MgRun one = solveMg(s, 1e-8, true, rotations, 1);
        const MgRun two = solveMg(s, 1e-8, true, rotations, 2);
        REQUIRE(one.converged);
        CHECK(one.iterations == two.iterations);
        CHECK((one.dv - two.dv).cwiseAbs().maxCoeff() == 0.0);
    }
}

TEST_CASE("multigrid: a fully pinned aggregate and plane filters keep the V-cycle SPD",
          "[multigrid]") {
    // A pinned block and plane filters (blockAndPlanes): PCG must still converge to LDLᵀ's answer.
    VecX ref;
    const ClothSystem s = blockAndPlanes(20, 12, 18, 18, ref);
    for (bool rotations : {false, true}) {
        const MgRun mg = solveMg(s, 1e-9, true, rotations);
        REQUIRE(mg.converged);
        CHECK((mg.dv - ref).norm() <= 1e-6 * ref.norm());
    }
}

TEST_CASE("multigrid: double products read the assembled matrix; levels are exactly symmetric",
          "[multigrid]") {
    // The hierarchy holds no double copy of Â (multigrid.h, memory): multiply in double reads
    // A's values through the level-0 slot map and filters on the fly. Checked against
    // Â y = S A S y + (I − S) y computed here from A and the constraints in A's order; the
    // single-precision product agrees to float rounding. Every coarse level of smoothed
    // aggregation, built in float from the upper triangle of Pᵀ A P, is symmetric bit for bit.
    for (bool smoothed : {false, true}) {
        const ClothSystem s = makeClothSystem(40, 1.0 / 24.0, true, true);
        const long n3 = 3L * s.A.size();
        BlockMultigrid mg;
        mg.settings().smoothed = smoothed;
        mg.settings().smoothedMinRows = 0;
        mg.setPositions(s.x.data(), s.A.size());
        REQUIRE(mg.refresh(s.A, s.c, s.constrained));
        INFO((smoothed ? "smoothed" : "plain") << ", " << mg.levelCount() << " levels");
        REQUIRE(mg.levelCount() >= 3);
        std::mt19937 rng(9);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        VecX y(n3);
        for (long q = 0; q < n3; ++q) y[q] = u(rng);
        VecX Sy = y, want(n3);
        s.c.apply(Sy.data());
        s.A.multiply(Sy.data(), want.data());
        s.c.apply(want.data());
        want += y - Sy;
        VecX yLevel(n3), got(n3), gotNatural(n3), single(n3);
        mg.toLevelOrder(y.data(), yLevel.data());
        mg.multiply(yLevel.data(), got.data());
        mg.fromLevelOrder(got.data(), gotNatural.data());
        CHECK((gotNatural - want).norm() <= 1e-14 * want.norm());
        const double dot = mg.multiplyDot(yLevel.data(), got.data(), false);
        CHECK(dot == Approx(yLevel.dot(got)).epsilon(1e-12));
        const double dotSingle = mg.multiplyDot(yLevel.data(), single.data(), true);
        CHECK((single - got).norm() <= 1e-6 * got.norm());
        CHECK((single - got).norm() > 0.0); // a float copy, not the doubles
        CHECK(dotSingle == Approx(dot).epsilon(1e-6));
        for (int l = 1; smoothed && l < mg.levelCount(); ++l) { // (plain: sums in two orders)
            const BsrMatrix& a = mg.matrix(l);
            long asymmetric = 0;
            for (int i = 0; i < a.n; ++i)
                for (int k = a.start[i]; k < a.start[i + 1]; ++k) {
                    const int j = a.cols[k];
                    const int kt =
                        static_cast<int>(std::lower_bound(a.cols.begin() + a.start[j],
                                                          a.cols.begin() + a.start[j + 1], i) -
                                         a.cols.begin());
                    REQUIRE(kt < a.start[j + 1]);
                    for (int r = 0; r < 3; ++r)
                        for (int c = 0; c < 3; ++c)
                            asymmetric += a.val[9 * k + 3 * c + r] != a.val[9 * kt + 3 * r + c];
                }
            INFO("level " << l);
            CHECK(asymmetric == 0);
        }
    }
}
