// vertexStrain against closed forms: a sheet stretched along x by a factor k has strain k − 1
// at every vertex (x edges stretch most; diagonals less, y edges not at all); compressed, the
// signed strain is negative; a hair polyline's segments. strainColour's ends and its middle.
#include "viz/strain.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale::viz;

namespace {

// An n×n grid of unit squares, two triangles each, x scaled by sx and y by sy.
GeometryOverlay grid(int n, double sx, double sy) {
    GeometryOverlay g;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) g.points.push_back({sx * i, sy * j, 0.0});
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            g.triangles.push_back({a, b, d});
            g.triangles.push_back({a, d, c});
        }
    return g;
}

} // namespace

TEST_CASE("strain: a uniform stretch along x gives k - 1 everywhere") {
    const GeometryOverlay rest = grid(4, 1, 1);
    for (double k : {1.1, 1.5, 0.8}) {
        const GeometryOverlay f = grid(4, k, 1);
        const std::vector<double> s = vertexStrain(rest, f);
        REQUIRE(s.size() == rest.points.size());
        // Edges: x ones (k − 1), y ones (0), diagonals sqrt(k² + 1)/sqrt(2) − 1 (smaller).
        for (double v : s) CHECK(v == Approx(k - 1).margin(1e-12));
    }
}

TEST_CASE("strain: only the stretched part of a sheet is strained") {
    const GeometryOverlay rest = grid(4, 1, 1);
    GeometryOverlay f = rest;
    for (auto& p : f.points)
        if (p[1] > 3.5) p[1] += 0.5; // the top row pulled up by half a cell
    const std::vector<double> s = vertexStrain(rest, f);
    for (size_t v = 0; v < s.size(); ++v) {
        const double y = rest.points[v][1];
        if (y > 2.5) // rows 3 and 4 share the stretched y edges (1 → 1.5)
            CHECK(s[v] == Approx(0.5).margin(1e-12));
        else
            CHECK(s[v] == Approx(0.0).margin(1e-12));
    }
}

TEST_CASE("strain: hair segments, a mismatched frame, and the colour map") {
    GeometryOverlay rest, f;
    rest.points = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}};
    rest.polylines = {{0, 1, 2}};
    f = rest;
    f.points[2] = {0, 3, 0}; // second segment doubled
    const std::vector<double> s = vertexStrain(rest, f);
    CHECK(s[0] == Approx(0.0));
    CHECK(s[1] == Approx(1.0));
    CHECK(s[2] == Approx(1.0));
    f.points.pop_back();
    CHECK(vertexStrain(rest, f).empty());
    const Rgb base{0.4, 0.6, 0.9};
    const Rgb zero = strainColour(0, base), top = strainColour(kStrainTop, base),
              over = strainColour(9, base);
    CHECK(zero.r == Approx(base.r));
    CHECK(zero.b == Approx(base.b));
    CHECK(top.r == Approx(over.r));
    CHECK(top.r > 0.8);
    CHECK(top.g < 0.2);
    const Rgb squeezed = strainColour(-kStrainTop, base);
    CHECK(squeezed.g > 0.8);
    CHECK(squeezed.r < 0.25);
    CHECK(strainColour(NAN, base).r == Approx(base.r));
}
