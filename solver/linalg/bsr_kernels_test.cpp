// The block kernels against dense Eigen references, for the portable kernels and (where the
// CPU has them) the AVX2 + FMA ones: block-row products in double and single precision, the
// forward and backward Gauss–Seidel sweeps, and the fused residual of the forward sweep; a flag
// simulated with either set of kernels.
#include "solver/linalg/bsr_kernels.h"
#include "solver/world/test_support.h"
#include "solver/linalg/types.h"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <random>
#include <vector>

using namespace gale::solver;

namespace {

// A random symmetric block matrix with a random symmetric pattern, diagonally dominant.
struct RandomBsr {
    int n = 0;
    std::vector<int> start, cols, diag, mirror;
    std::vector<double> val;   // column-major blocks + pad
    std::vector<float> single; // the same in float + pad
    std::vector<double> dinv;  // inverses of the single-precision diagonal blocks + pad
    Eigen::MatrixXd dense;       // from val
    Eigen::MatrixXd denseSingle; // from single

    BsrPattern pattern() const { return {start.data(), cols.data(), diag.data(), n}; }
    int slot(int i, int j) const {
        for (int k = start[i]; k < start[i + 1]; ++k)
            if (cols[k] == j) return k;
        return -1;
    }
};

RandomBsr makeRandom(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<std::vector<int>> rows(n);
    for (int i = 0; i < n; ++i) rows[i].push_back(i);
    for (int e = 0; e < 4 * n; ++e) {
        const int i = static_cast<int>(rng() % n), j = static_cast<int>(rng() % n);
        if (i == j) continue;
        rows[i].push_back(j);
        rows[j].push_back(i);
    }
    RandomBsr m;
    m.n = n;
    m.start.assign(n + 1, 0);
    for (int i = 0; i < n; ++i) {
        std::sort(rows[i].begin(), rows[i].end());
        rows[i].erase(std::unique(rows[i].begin(), rows[i].end()), rows[i].end());
        m.cols.insert(m.cols.end(), rows[i].begin(), rows[i].end());
        m.start[i + 1] = static_cast<int>(m.cols.size());
    }
    const size_t blocks = m.cols.size();
    m.diag.resize(n);
    m.mirror.resize(blocks);
    for (int i = 0; i < n; ++i) {
        m.diag[i] = m.slot(i, i);
        for (int k = m.start[i]; k < m.start[i + 1]; ++k) m.mirror[k] = m.slot(m.cols[k], i);
    }
    m.dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (int i = 0; i < n; ++i)
        for (int k = m.start[i]; k < m.start[i + 1]; ++k) {
            const int j = m.cols[k];
            if (j < i) continue;
            Mat3 b;
            for (int q = 0; q < 9; ++q) b(q % 3, q / 3) = u(rng);
            if (i == j) b = b * b.transpose() + 12.0 * Mat3::Identity() * (m.start[i + 1] - m.start[i]);
            m.dense.block<3, 3>(3 * i, 3 * j) = b;
            m.dense.block<3, 3>(3 * j, 3 * i) = b.transpose();
        }
    m.val.assign(9 * blocks + kBsrPad, 0.0);
    m.single.assign(9 * blocks + kBsrPad, 0.0f);
    for (int i = 0; i < n; ++i)
        for (int k = m.start[i]; k < m.start[i + 1]; ++k)
            for (int q = 0; q < 9; ++q) {
                m.val[9 * k + q] = m.dense(3 * i + q % 3, 3 * m.cols[k] + q / 3);
                m.single[9 * k + q] = static_cast<float>(m.val[9 * k + q]);
            }
    m.denseSingle = m.dense;
    for (int i = 0; i < n; ++i)
        for (int k = m.start[i]; k < m.start[i + 1]; ++k)
            for (int q = 0; q < 9; ++q) m.denseSingle(3 * i + q % 3, 3 * m.cols[k] + q / 3) = m.single[9 * k + q];
    m.dinv.assign(9 * static_cast<size_t>(n) + kBsrPad, 0.0);
    for (int i = 0; i < n; ++i) {
        const Mat3 inv = m.denseSingle.block<3, 3>(3 * i, 3 * i).inverse();
        for (int q = 0; q < 9; ++q) m.dinv[9 * i + q] = inv(q % 3, q / 3);
    }
    return m;
}

Eigen::VectorXd randomVector(int n3, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::VectorXd v(n3);
    for (int k = 0; k < n3; ++k) v[k] = u(rng);
    return v;
}

// The dense block Gauss–Seidel sweep on the single-precision matrix.
void referenceSweep(const RandomBsr& m, const Eigen::VectorXd& r, Eigen::VectorXd& x, bool forward) {
    for (int s = 0; s < m.n; ++s) {
        const int i = forward ? s : m.n - 1 - s;
        const Vec3 y = r.segment<3>(3 * i) - m.denseSingle.middleRows<3>(3 * i) * x;
        Mat3 d;
        for (int q = 0; q < 9; ++q) d(q % 3, q / 3) = m.dinv[9 * i + q];
        x.segment<3>(3 * i) += d * y;
    }
}

// A sweep of m's single-precision matrix on A x = r.
GaussSeidelSweep sweepOf(const RandomBsr& m, const Eigen::VectorXd& r, Eigen::VectorXd& x) {
    GaussSeidelSweep g;
    g.pattern = m.pattern();
    g.val = m.single.data();
    g.mirror = m.mirror.data();
    g.dinv = m.dinv.data();
    g.r = r.data();
    g.x = x.data();
    return g;
}

double relErr(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).norm() / b.norm(); }

// Runs `body` with the portable kernels and, where available, with the wide ones.
template <class F>
void forEachKernel(F body) {
    const bool initial = wideKernels();
    setWideKernels(false);
    {
        INFO("portable kernels");
        body();
    }
    setWideKernels(true);
    if (wideKernels()) {
        INFO("AVX2 + FMA kernels");
        body();
    }
    setWideKernels(initial);
}

} // namespace

TEST_CASE("bsr kernels: block-row products equal the dense product", "[bsr]") {
    const RandomBsr m = makeRandom(157, 11);
    const Eigen::VectorXd x = randomVector(3 * m.n, 12);
    const Eigen::VectorXd want = m.dense * x, wantSingle = m.denseSingle * x;
    forEachKernel([&] {
        Eigen::VectorXd y = Eigen::VectorXd::Zero(3 * m.n);
        bsrMultiplyRows(m.pattern(), m.val.data(), x.data(), y.data(), 0, m.n);
        CHECK(relErr(y, want) < 1e-14);
        // A row range writes only its rows.
        Eigen::VectorXd part = Eigen::VectorXd::Constant(3 * m.n, 7.0);
        bsrMultiplyRows(m.pattern(), m.single.data(), x.data(), part.data(), 40, 90);
        CHECK(relErr(part.segment(120, 150), wantSingle.segment(120, 150)) < 1e-14);
        CHECK(part.head(120).cwiseEqual(7.0).all());
        CHECK(part.tail(3 * m.n - 270).cwiseEqual(7.0).all());
    });
}

TEST_CASE("bsr kernels: forward and backward Gauss-Seidel sweeps equal the dense sweep", "[bsr]") {
    const RandomBsr m = makeRandom(131, 21);
    const Eigen::VectorXd r = randomVector(3 * m.n, 22), x0 = randomVector(3 * m.n, 23);
    for (bool forward : {true, false}) {
        Eigen::VectorXd want = x0;
        referenceSweep(m, r, want, forward);
        forEachKernel([&] {
            Eigen::VectorXd x = x0;
            GaussSeidelSweep g = sweepOf(m, r, x);
            g.forward = forward;
            gaussSeidelSweep(g);
            INFO((forward ? "forward" : "backward"));
            CHECK(relErr(x, want) < 1e-13);
        });
    }
}

TEST_CASE("bsr kernels: the forward sweep from zero leaves t = r - A x", "[bsr]") {
    const RandomBsr m = makeRandom(143, 31);
    const Eigen::VectorXd r = randomVector(3 * m.n, 32);
    Eigen::VectorXd want = Eigen::VectorXd::Zero(3 * m.n);
    referenceSweep(m, r, want, true);
    forEachKernel([&] {
        Eigen::VectorXd x = Eigen::VectorXd::Zero(3 * m.n), t = Eigen::VectorXd::Constant(3 * m.n, 5.0);
        GaussSeidelSweep g = sweepOf(m, r, x);
        g.t = t.data();
        g.fromZero = true;
        gaussSeidelSweep(g);
        CHECK(relErr(x, want) < 1e-13);
        const Eigen::VectorXd residual = r - m.denseSingle * x;
        // Row i's own equation is met only up to rounding, so compare against ‖r‖.
        CHECK((t - residual).norm() < 1e-12 * r.norm());
        CHECK(residual.norm() > 1e-3 * r.norm()); // one sweep does not solve the system
    });
}

TEST_CASE("bsr kernels: sweeps over row ranges and the pulled residual give the pushed bits",
          "[bsr]") {
    // A multicolour sweep runs one sweep per chunk of rows; the rows of a chunk see the x the
    // earlier chunks left, so chunks in order give the whole sweep's bits, forward and
    // backward. After a forward sweep from zero, pulling t_i = −Σ_{j>i} A_ij x_j row by row
    // subtracts the same terms in the same order as the sweep's push: the same bits.
    const RandomBsr m = makeRandom(157, 41);
    const Eigen::VectorXd r = randomVector(3 * m.n, 42), x0 = randomVector(3 * m.n, 43);
    const int cuts[] = {0, 1, 40, 41, 100, m.n};
    forEachKernel([&] {
        for (bool forward : {true, false}) {
            Eigen::VectorXd whole = x0, pieces = x0;
            GaussSeidelSweep g = sweepOf(m, r, whole);
            g.forward = forward;
            gaussSeidelSweep(g);
            g.x = pieces.data();
            for (int c = 0; c + 1 < 6; ++c) {
                const int piece = forward ? c : 4 - c;
                g.begin = cuts[piece];
                g.end = cuts[piece + 1];
                gaussSeidelSweep(g);
            }
            INFO((forward ? "forward" : "backward"));
            CHECK((pieces - whole).cwiseAbs().maxCoeff() == 0.0);
        }
        Eigen::VectorXd x = Eigen::VectorXd::Zero(3 * m.n),
                        t = Eigen::VectorXd::Constant(3 * m.n, 5.0);
        GaussSeidelSweep g = sweepOf(m, r, x);
        g.t = t.data();
        g.fromZero = true;
        gaussSeidelSweep(g);
        Eigen::VectorXd pulled = Eigen::VectorXd::Constant(3 * m.n, 7.0);
        bsrUpperResidualRows(m.pattern(), m.single.data(), x.data(), pulled.data(), 0, 50);
        bsrUpperResidualRows(m.pattern(), m.single.data(), x.data(), pulled.data(), 50, m.n);
        CHECK((pulled - t).cwiseAbs().maxCoeff() == 0.0);
        CHECK((pulled - (r - m.denseSingle * x)).norm() < 1e-12 * r.norm());
    });
}

TEST_CASE("bsr kernels: a flag in gusty wind moves the same with either set of kernels", "[bsr]") {
    // The kernels differ only in rounding (FMA, summation in lanes), so two runs of a 0.25 s flag
    // must agree far inside the effect of the CG tolerance (1e-3) on the motion, measured here
    // against a run at 1e-7.
    const TriMesh mesh = makeGrid(1.0, 1.0, 24, 24, Vec3(0, 1, 0));
    auto run = [&mesh](bool wide, double tolerance) {
        const bool initial = wideKernels();
        setWideKernels(wide);
        WorldSettings ws;
        ws.fps = 96.0;
        ws.substeps = 1;
        World w(ws);
        w.setWind(std::make_shared<testing::LambdaField>([](const Vec3& x, double t) {
            return Vec3(10.0 * (1.0 + 0.3 * std::sin(3.0 * t + 2.0 * x.y())), 2.0 * std::cos(5.0 * t + 3.0 * x.x()), 1.0);
        }));
        ClothMaterial m;
        m.density = 0.1;
        m.stretch = gale::fields::Param(2000.0);
        m.shear = gale::fields::Param(200.0);
        m.bend = gale::fields::Param(1e-4);
        auto c = std::make_unique<Cloth>("flag", mesh, m);
        PinSet pins;
        pins.vertices = testing::gridColumn(24, 24, 0);
        c->addPins(pins);
        c->options().cgTolerance = tolerance;
        w.addBody(std::move(c));
        for (int f = 1; f <= 24; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
        setWideKernels(initial);
        return VecX(w.bodies()[0]->positions());
    };
    const VecX rest = Eigen::Map<const VecX>(mesh.positions.data(), mesh.positions.size());
    const VecX portable = run(false, 1e-3), tight = run(false, 1e-7);
    REQUIRE(portable.allFinite());
    CHECK((portable - rest).norm() > 0.1); // it did move
    const double toleranceEffect = (portable - tight).norm();
    CHECK(toleranceEffect > 0.0);
    const bool initial = wideKernels();
    setWideKernels(true);
    const bool available = wideKernels();
    setWideKernels(initial);
    if (!available) return; // no AVX2 + FMA on this CPU: nothing to compare
    const VecX wide = run(true, 1e-3);
    INFO("kernels differ by " << (wide - portable).norm() << " m, the tolerance's effect " << toleranceEffect << " m");
    CHECK((wide - portable).norm() < 0.01 * toleranceEffect);
}
