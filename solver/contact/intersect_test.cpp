// Triangle–triangle intersection: hand-made crossings, touches and coplanar cases; random
// triangle pairs against an independent test (edge–plane crossing points and barycentric
// coordinates); a crumpled mesh's pairs against brute force over all triangle pairs.
#include "solver/contact/intersect.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <random>

using namespace gale::solver::contact;

namespace {
// Independent: the segment's crossing point with the triangle's plane, then barycentric
// coordinates of that point. `margin` returns how far from a decision boundary it was.
bool referenceSegment(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c,
                      double& margin) {
    const Vec3 n = (b - a).cross(c - a).normalized();
    const double dp = (p - a).dot(n), dq = (q - a).dot(n);
    margin = std::min(std::abs(dp), std::abs(dq));
    if (dp * dq >= 0.0) return false;
    const Vec3 x = p + (dp / (dp - dq)) * (q - p);
    // Barycentric by areas projected on n.
    const double area = (b - a).cross(c - a).dot(n);
    const double w0 = (b - x).cross(c - x).dot(n) / area;
    const double w1 = (c - x).cross(a - x).dot(n) / area;
    const double w2 = 1.0 - w0 - w1;
    margin = std::min({margin, std::abs(w0), std::abs(w1), std::abs(w2)});
    return w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0;
}
bool referenceTriangles(const Vec3 t[3], const Vec3 u[3], double& margin) {
    bool hit = false;
    margin = 1e300;
    for (int e = 0; e < 3; ++e) {
        double m1, m2;
        hit = referenceSegment(t[e], t[(e + 1) % 3], u[0], u[1], u[2], m1) || hit;
        hit = referenceSegment(u[e], u[(e + 1) % 3], t[0], t[1], t[2], m2) || hit;
        margin = std::min({margin, m1, m2});
    }
    return hit;
}
// The triangles of an n × n grid of vertices (row-major), two per cell.
std::vector<std::array<int, 3>> gridTriangles(int n) {
    std::vector<std::array<int, 3>> tris;
    for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const int a = j * n + i;
            tris.push_back({a, a + 1, a + n});
            tris.push_back({a + 1, a + n + 1, a + n});
        }
    return tris;
}
} // namespace

TEST_CASE("intersect: orientation signs", "[contact][intersect]") {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    CHECK(orient3d(a, b, c, Vec3(0.2, 0.2, -1)) == 1); // below the counter-clockwise triangle
    CHECK(orient3d(a, b, c, Vec3(0.2, 0.2, 1)) == -1);
    CHECK(orient3d(a, b, c, Vec3(5, 7, 0)) == 0); // in the plane, exactly
    // Nearly coplanar at a scale where the naive determinant is all rounding.
    const Vec3 far(1e8, 1e8, 0);
    CHECK(orient3d(a + far, b + far, c + far, Vec3(0.25, 0.25, 0) + far) == 0);
}

TEST_CASE("intersect: hand-made triangle pairs", "[contact][intersect]") {
    const Vec3 t[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    SECTION("an edge through the middle") {
        const Vec3 u[3] = {Vec3(0.2, 0.2, -1), Vec3(0.3, 0.2, 1), Vec3(0.2, 0.3, 1)};
        CHECK(trianglesIntersect(t, u));
        CHECK(trianglesIntersect(u, t));
    }
    SECTION("above, not touching") {
        const Vec3 u[3] = {Vec3(0.2, 0.2, 0.1), Vec3(0.3, 0.2, 1), Vec3(0.2, 0.3, 1)};
        CHECK_FALSE(trianglesIntersect(t, u));
    }
    SECTION("crossing the plane outside the triangle") {
        const Vec3 u[3] = {Vec3(2, 2, -1), Vec3(3, 2, 1), Vec3(2, 3, 1)};
        CHECK_FALSE(trianglesIntersect(t, u));
    }
    SECTION("a pierced ring: neither has a vertex inside the other, edges cross") {
        const Vec3 u[3] = {Vec3(0.25, -0.5, -0.5), Vec3(0.25, 2, -0.5), Vec3(0.25, -0.5, 2)};
        CHECK(trianglesIntersect(t, u));
    }
    SECTION("coplanar overlap is not counted") {
        const Vec3 u[3] = {Vec3(0.1, 0.1, 0), Vec3(0.6, 0.1, 0), Vec3(0.1, 0.6, 0)};
        CHECK_FALSE(trianglesIntersect(t, u));
    }
    SECTION("sharing a vertex: a fan folded through itself, and one folded without crossing") {
        const Vec3 through[3] = {Vec3(0, 0, 0), Vec3(0.5, 0.3, -1), Vec3(0.3, 0.5, 1)};
        CHECK(trianglesSharingVertexIntersect(t, 0, through, 0));
        const Vec3 above[3] = {Vec3(0, 0, 0), Vec3(0.5, 0.3, 1), Vec3(0.3, 0.5, 1)};
        CHECK_FALSE(trianglesSharingVertexIntersect(t, 0, above, 0));
    }
}

TEST_CASE("intersect: random pairs agree with the independent test", "[contact][intersect]") {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    int compared = 0, hits = 0;
    for (int k = 0; k < 40000; ++k) {
        Vec3 t[3], u[3];
        for (int i = 0; i < 3; ++i) {
            t[i] = Vec3(U(rng), U(rng), U(rng));
            u[i] = Vec3(U(rng), U(rng), U(rng)) * 0.8 + Vec3(0.3, 0, 0);
        }
        double margin = 0.0;
        const bool want = referenceTriangles(t, u, margin);
        if (margin < 1e-9) continue; // too near a decision boundary for the reference
        ++compared;
        hits += want;
        REQUIRE(trianglesIntersect(t, u) == want);
    }
    CHECK(compared > 39000);
    CHECK(hits > 1000);
}

TEST_CASE("intersect: a crumpled mesh's pairs match brute force", "[contact][intersect]") {
    // A 12 × 12 grid with large random heights: many triangles cross, some sharing a vertex.
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    const int n = 12;
    std::vector<double> x;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            x.push_back(i * 0.1 + 0.08 * U(rng));
            x.push_back(j * 0.1 + 0.08 * U(rng));
            x.push_back(0.3 * U(rng));
        }
    const std::vector<std::array<int, 3>> tris = gridTriangles(n);
    const auto pairs = intersectingPairs(x, tris);
    const auto at = [&](int v) { return Vec3(x[3 * v], x[3 * v + 1], x[3 * v + 2]); };
    std::vector<std::pair<int, int>> want;
    int sharedVertexHits = 0;
    for (size_t i = 0; i < tris.size(); ++i)
        for (size_t j = i + 1; j < tris.size(); ++j) {
            int shared = 0, si = 0, sj = 0;
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    if (tris[i][a] == tris[j][b]) ++shared, si = a, sj = b;
            if (shared >= 2) continue;
            const Vec3 t[3] = {at(tris[i][0]), at(tris[i][1]), at(tris[i][2])};
            const Vec3 u[3] = {at(tris[j][0]), at(tris[j][1]), at(tris[j][2])};
            const bool hit =
                shared ? trianglesSharingVertexIntersect(t, si, u, sj) : trianglesIntersect(t, u);
            if (hit) want.emplace_back(static_cast<int>(i), static_cast<int>(j));
            sharedVertexHits += hit && shared;
        }
    auto got = pairs;
    std::sort(got.begin(), got.end());
    CHECK(got == want);
    CHECK(want.size() > 20);
    CHECK(sharedVertexHits > 0);
    CHECK(intersectingPairs(x, tris, 3).size() == 3);
}

TEST_CASE("intersect: strands through a crumpled sheet match the independent test",
          "[contact][intersect]") {
    // A 10 × 10 crumpled sheet and 40 random strands of 6 segments hanging through it: the
    // (segment, triangle) crossings against the crossing point's barycentric coordinates over
    // every pair (pairs too close to a decision boundary for either test to be sure left out).
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    const int n = 10;
    std::vector<double> y;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            y.push_back(i * 0.1 + 0.03 * U(rng));
            y.push_back(0.05 * U(rng));
            y.push_back(j * 0.1 + 0.03 * U(rng));
        }
    const std::vector<std::array<int, 3>> tris = gridTriangles(n);
    std::vector<double> x;
    std::vector<std::array<int, 2>> segs;
    for (int s = 0; s < 40; ++s) {
        Vec3 p(0.45 + 0.45 * U(rng), 0.25, 0.45 + 0.45 * U(rng));
        for (int k = 0; k <= 6; ++k) {
            if (k > 0)
                segs.push_back(
                    {static_cast<int>(x.size() / 3) - 1, static_cast<int>(x.size() / 3)});
            for (int c = 0; c < 3; ++c) x.push_back(p[c]);
            p += Vec3(0.03 * U(rng), -0.08, 0.03 * U(rng));
        }
    }
    const auto got = crossingSegments(x, segs, y, tris);
    const auto at = [](const std::vector<double>& v, int i) {
        return Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    };
    int compared = 0, crossings = 0;
    for (size_t s = 0; s < segs.size(); ++s)
        for (size_t t = 0; t < tris.size(); ++t) {
            double margin = 0.0;
            const bool want =
                referenceSegment(at(x, segs[s][0]), at(x, segs[s][1]), at(y, tris[t][0]),
                                 at(y, tris[t][1]), at(y, tris[t][2]), margin);
            if (margin < 1e-9) continue;
            ++compared;
            crossings += want;
            const bool found = std::find(got.begin(), got.end(),
                                         std::pair<int, int>(static_cast<int>(s),
                                                             static_cast<int>(t))) != got.end();
            INFO("segment " << s << " triangle " << t);
            REQUIRE(found == want);
        }
    CHECK(compared > 30000);
    CHECK(crossings >= 35); // nearly every strand goes through the sheet once
    CHECK(crossingSegments(x, segs, y, tris, 5).size() == 5);
}
