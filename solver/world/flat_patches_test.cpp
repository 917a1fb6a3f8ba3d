// Flat patches: every pair the labels leave out stays more than ξ apart over the step (brute
// force over the pairs, sampled in time and with the vertices moved within the slack), on a sheet
// moving rigidly, and on the shapes a certificate must refuse: a sheet compressed below ξ, a
// sheet folded onto itself, and a spiral ramp whose two turns lie ξ/2 apart with every normal
// near the vertical (only the contour test tells it from a flat sheet).
#include "solver/world/flat_patches.h"

#include "solver/contact/ccd.h"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <set>

using namespace gale::solver;

namespace {

struct Sheet {
    std::vector<std::array<int, 3>> tris;
    std::vector<double> x; // 3 per vertex
};

// A grid of nu × nv vertices at point(i, j), two triangles a cell (diagonals alternating).
template <class Point>
Sheet grid(int nu, int nv, Point&& point) {
    Sheet s;
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const Vec3 p = point(i, j);
            s.x.insert(s.x.end(), {p.x(), p.y(), p.z()});
        }
    for (int j = 0; j + 1 < nv; ++j)
        for (int i = 0; i + 1 < nu; ++i) {
            const int a = j * nu + i, b = a + 1, c = a + nu, d = c + 1;
            if ((i + j) % 2) {
                s.tris.push_back({a, b, d});
                s.tris.push_back({a, d, c});
            } else {
                s.tris.push_back({a, b, c});
                s.tris.push_back({b, d, c});
            }
        }
    return s;
}

// The triangle tree as the self-collision pass builds it: over the rest positions.
contact::Bvh restTree(const Sheet& s) {
    std::vector<contact::Box> boxes(s.tris.size());
    for (size_t t = 0; t < s.tris.size(); ++t)
        for (int v : s.tris[t]) boxes[t].add(Vec3(vec3At(s.x.data(), v)));
    contact::Bvh tree;
    tree.build(boxes);
    return tree;
}

struct Verdict {
    long leftOut = 0;         // pairs the labels leave out
    double leftOutMin = 1e30; // their smallest distance over the samples (m)
    long close = 0;           // pairs within ξ somewhere in the samples
};

// Every vertex–triangle and edge–edge pair sharing no vertex, at 11 times of the step and with
// every vertex moved by up to `slack` (3 random draws a time): which are left out by the labels,
// how close those come, and how many pairs come within ξ at all.
Verdict judge(const FlatPatches& fp, const std::vector<std::array<int, 3>>& tris,
              const std::vector<double>& x0, const std::vector<double>& x1, double slack,
              double xi) {
    const size_t nv = x0.size() / 3;
    const std::vector<int>& vl = fp.vertexLabels();
    const std::vector<int>& tl = fp.triangleLabels();
    std::set<std::array<int, 2>> edgeSet;
    for (const auto& t : tris)
        for (int k = 0; k < 3; ++k)
            edgeSet.insert({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
    const std::vector<std::array<int, 2>> edges(edgeSet.begin(), edgeSet.end());
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    std::vector<std::vector<double>> samples;
    for (int s = 0; s <= 10; ++s)
        for (int draw = 0; draw < (s % 5 == 0 ? 3 : 1); ++draw) {
            std::vector<double> x(3 * nv);
            for (size_t i = 0; i < nv; ++i) {
                Vec3 jitter(U(rng), U(rng), U(rng));
                if (jitter.norm() > 1.0) jitter.normalize();
                const Vec3 p = (1.0 - 0.1 * s) * Vec3(vec3At(x0.data(), i)) +
                               0.1 * s * Vec3(vec3At(x1.data(), i)) + slack * jitter;
                vec3At(x.data(), i) = p;
            }
            samples.push_back(std::move(x));
        }
    Verdict out;
    const auto record = [&](bool leftOut, double d2min) {
        const double d = std::sqrt(d2min);
        if (d < xi) ++out.close;
        if (leftOut) {
            ++out.leftOut;
            out.leftOutMin = std::min(out.leftOutMin, d);
        }
    };
    for (size_t v = 0; v < nv; ++v)
        for (size_t t = 0; t < tris.size(); ++t) {
            const auto& tri = tris[t];
            if (tri[0] == int(v) || tri[1] == int(v) || tri[2] == int(v)) continue;
            double d2 = 1e30, w[3];
            for (const auto& x : samples)
                d2 = std::min(d2, contact::pointTriangleDistance2(
                                      vec3At(x.data(), v), vec3At(x.data(), tri[0]),
                                      vec3At(x.data(), tri[1]), vec3At(x.data(), tri[2]), w));
            record(vl[v] >= 0 && vl[v] == tl[t], d2);
        }
    for (size_t e = 0; e < edges.size(); ++e)
        for (size_t f = e + 1; f < edges.size(); ++f) {
            const auto &a = edges[e], &b = edges[f];
            if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) continue;
            double d2 = 1e30, s, u;
            for (const auto& x : samples)
                d2 = std::min(d2, contact::segmentSegmentDistance2(
                                      vec3At(x.data(), a[0]), vec3At(x.data(), a[1]),
                                      vec3At(x.data(), b[0]), vec3At(x.data(), b[1]), s, u));
            const int la = vl[a[0]];
            record(la >= 0 && la == vl[a[1]] && la == vl[b[0]] && la == vl[b[1]], d2);
        }
    return out;
}

FlatPatches patchesOf(const Sheet& rest) {
    FlatPatches fp;
    fp.setTopology(rest.tris, rest.x.size() / 3, std::vector<uint8_t>(rest.tris.size(), 1));
    return fp;
}

// The patches of the step x0 → x1 over `rest`'s mesh and tree, judged: returns the verdict and
// the patch count.
std::pair<Verdict, int> certifyAndJudge(const Sheet& rest, const std::vector<double>& x0,
                                        const std::vector<double>& x1, double slack, double xi) {
    FlatPatches fp = patchesOf(rest);
    const int patches = fp.find(restTree(rest), x0, x1, slack, xi);
    return {judge(fp, rest.tris, x0, x1, slack, xi), patches};
}

size_t labelled(const std::vector<int>& labels) {
    return static_cast<size_t>(
        std::count_if(labels.begin(), labels.end(), [](int l) { return l >= 0; }));
}

} // namespace

TEST_CASE("flat patches: a sheet turning and moving is one patch, its pairs more than ξ apart",
          "[world][flat_patches]") {
    const double xi = 0.003, slack = xi / 8;
    const Sheet s = grid(16, 16, [](int i, int j) { return Vec3(0.01 * i, 0.01 * j, 0.0); });
    // The step: a turn of 25° about a tilted axis and a shift of 4 cm.
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(25.0 * M_PI / 180.0, Vec3(1.0, 0.5, 0.3).normalized()).toRotationMatrix();
    std::vector<double> x1(s.x.size());
    for (size_t i = 0; i < s.x.size() / 3; ++i)
        vec3At(x1.data(), i) = r * Vec3(vec3At(s.x.data(), i)) + Vec3(0.04, -0.01, 0.02);
    FlatPatches fp = patchesOf(s);
    const contact::Bvh tree = restTree(s);
    REQUIRE(fp.find(tree, s.x, x1, slack, xi) == 1);
    CHECK(labelled(fp.triangleLabels()) == s.tris.size());
    CHECK(labelled(fp.vertexLabels()) == 14 * 14); // the interior vertices
    const Verdict v = judge(fp, s.tris, s.x, x1, slack, xi);
    CHECK(v.leftOut > 10000);
    CHECK(v.leftOutMin > xi);
    CHECK(v.close == 0);
    // The same patch holds for a further step of the same motion, not for one that folds it.
    // Folded: the half past the middle column turned 170° about it, back over the other half.
    const Eigen::Matrix3d fold =
        Eigen::AngleAxisd(170.0 * M_PI / 180.0, r * Vec3::UnitY()).toRotationMatrix();
    const Vec3 hinge = r * Vec3(0.075, 0.0, 0.0) + Vec3(0.04, -0.01, 0.02);
    std::vector<double> x2(s.x.size()), folded(s.x.size());
    for (size_t i = 0; i < s.x.size() / 3; ++i) {
        vec3At(x2.data(), i) = r * Vec3(vec3At(x1.data(), i)) + Vec3(0.04, -0.01, 0.02);
        const Vec3 p = vec3At(x1.data(), i);
        vec3At(folded.data(), i) = i % 16 < 8 ? p : Vec3(hinge + fold * (p - hinge));
    }
    std::vector<uint8_t> lost(s.x.size() / 3, 0);
    CHECK(fp.recertify(x1, x2, slack, xi, lost) == 0);
    CHECK(std::count(lost.begin(), lost.end(), 1) == 0);
    CHECK(fp.recertify(x1, folded, slack, xi, lost) == 1);
    CHECK(static_cast<size_t>(std::count(lost.begin(), lost.end(), 1)) == s.x.size() / 3);
    // Lost, it is not tried again: nothing passes, nothing fails.
    std::fill(lost.begin(), lost.end(), 0);
    CHECK(fp.recertify(x1, x2, slack, xi, lost) == 0);
    CHECK(std::count(lost.begin(), lost.end(), 1) == 0);
}

TEST_CASE("flat patches: a sheet squeezed below ξ leaves out no pair that comes within ξ",
          "[world][flat_patches]") {
    const double xi = 0.003, slack = xi / 8;
    // The upper half's rows 1.2 mm apart at the end of the step (1 cm at its start): a vertex
    // and the triangles two rows on are within ξ there; the lower half keeps its 1 cm rows.
    const Sheet s = grid(12, 16, [](int i, int j) { return Vec3(0.01 * i, 0.01 * j, 0.0); });
    const Sheet end = grid(12, 16, [](int i, int j) {
        return Vec3(0.01 * i, j < 8 ? 0.01 * j : 0.07 + 0.0012 * (j - 7), 0.0);
    });
    const auto [v, patches] = certifyAndJudge(s, s.x, end.x, slack, xi);
    CHECK(patches >= 1);
    CHECK(v.close > 100);
    CHECK(v.leftOut > 1000); // the lower half's pairs
    CHECK(v.leftOutMin > xi);
}

TEST_CASE("flat patches: a sheet folded onto itself keeps its facing layers' pairs",
          "[world][flat_patches]") {
    const double xi = 0.003, slack = xi / 8;
    // A strip 20 columns long folded at its middle round a 1 mm radius: the layers 2 mm apart.
    const int nu = 20, nv = 6;
    const Sheet rest = grid(nu, nv, [](int i, int j) { return Vec3(0.01 * i, 0.01 * j, 0.0); });
    const double half = 0.095, radius = 0.001;
    const Sheet folded = grid(nu, nv, [&](int i, int j) {
        const double u = 0.01 * i;
        if (u <= half) return Vec3(u, 0.01 * j, 0.0);
        const double arc = u - half, turn = std::min(arc / radius, M_PI);
        const double beyond = std::max(0.0, arc - M_PI * radius);
        return Vec3(half + radius * std::sin(turn) - beyond, 0.01 * j,
                    radius * (1.0 - std::cos(turn)));
    });
    const auto [v, patches] = certifyAndJudge(rest, folded.x, folded.x, slack, xi);
    CHECK(v.close > 100);
    CHECK(patches >= 2); // each layer's flat part is a patch of its own
    CHECK(v.leftOut > 1000);
    CHECK(v.leftOutMin > xi);
}

TEST_CASE("flat patches: the turns of a spiral ramp ξ/2 apart are told apart by the contour",
          "[world][flat_patches]") {
    // An annulus r in [6, 16] cm wound through 1.6 turns, rising 1.5 mm a turn: every normal
    // within 0.3° of the vertical (the cones pass), triangles of 1–2 cm (the altitudes pass), but
    // the second turn lies 1.5 mm over the first. Only a contour that winds once (test 2) keeps
    // a patch to one turn.
    const double xi = 0.003, slack = xi / 8;
    const int nr = 6, nt = 100;
    const Sheet ramp = grid(nr, nt, [&](int i, int j) {
        const double r = 0.06 + 0.02 * i, a = 1.6 * 2.0 * M_PI * j / (nt - 1);
        return Vec3(r * std::cos(a), r * std::sin(a), 0.0015 * a / (2.0 * M_PI));
    });
    const auto [v, patches] = certifyAndJudge(ramp, ramp.x, ramp.x, slack, xi);
    CHECK(patches >= 2);
    CHECK(v.close > 500);
    CHECK(v.leftOut > 1000);
    CHECK(v.leftOutMin > xi);
}

TEST_CASE("flat patches: triangles narrower than ξ are left to the pair walk",
          "[world][flat_patches]") {
    // A flat sheet at rest, ξ = 8 mm: columns 2 cm apart on its left, 7 mm on its right, rows
    // 2 cm. On the right a vertex and the triangle across the next column are 7 mm apart, within
    // ξ; only the altitude test (3.) keeps them out of a patch (the cones are all vertical).
    const double xi = 0.008, slack = xi / 8;
    const Sheet s = grid(16, 8, [](int i, int j) {
        return Vec3(i < 8 ? 0.02 * i : 0.14 + 0.007 * (i - 7), 0.02 * j, 0.0);
    });
    const auto [v, patches] = certifyAndJudge(s, s.x, s.x, slack, xi);
    CHECK(patches >= 1);
    CHECK(v.close > 50);
    CHECK(v.leftOut > 100); // the left half's pairs
    CHECK(v.leftOutMin > xi);
}

TEST_CASE("flat patches: the cones' angle bound lies above the true angle, within 3.2e-5 rad",
          "[flat_patches]") {
    // Against libm's atan2 (the exact angle to rounding): random directions, and pairs near
    // parallel, orthogonal and opposite (the polynomial's ends and the octants' seams).
    std::mt19937 rng(7);
    std::normal_distribution<double> g;
    double worstBelow = 0.0, worstAbove = 0.0;
    const auto check = [&](const Vec3& a, const Vec3& b) {
        const double exact = std::atan2(a.cross(b).norm(), a.dot(b));
        const double bound = angleUpperBound(a, b);
        worstBelow = std::max(worstBelow, exact - bound);
        worstAbove = std::max(worstAbove, bound - exact);
    };
    for (int k = 0; k < 100000; ++k) {
        const Vec3 a(g(rng), g(rng), g(rng)), b(g(rng), g(rng), g(rng));
        check(a, b);
        const double t = std::ldexp(1.0, -(k % 40)); // 1 … 2⁻³⁹ rad off
        const Vec3 u = a.normalized(), w = a.cross(b).normalized().cross(u);
        check(u, std::cos(t) * u + std::sin(t) * w);                             // near parallel
        check(u, -std::cos(t) * u + std::sin(t) * w);                            // near opposite
        check(u, std::sin(t) * u + std::cos(t) * w);                             // near orthogonal
        check(u, std::cos(0.25 * M_PI + t) * u + std::sin(0.25 * M_PI + t) * w); // at the seam
    }
    check(Vec3::Zero(), Vec3::UnitX());
    CAPTURE(worstBelow, worstAbove);
    CHECK(worstBelow <= 0.0);
    CHECK(worstAbove <= 3.2e-5);
}
