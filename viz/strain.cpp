// Rest-relative strain per vertex and its colour map (strain.h).
#include "viz/strain.h"

#include <algorithm>
#include <cmath>

namespace gale::viz {

std::vector<double> vertexStrain(const GeometryOverlay& rest, const GeometryOverlay& frame) {
    const size_t n = frame.points.size();
    if (rest.points.size() != n) return {};
    std::vector<double> out(n, 0.0);
    auto edge = [&](int i, int j) {
        if (i < 0 || j < 0 || static_cast<size_t>(i) >= n || static_cast<size_t>(j) >= n) return;
        double l = 0, l0 = 0;
        for (int c = 0; c < 3; ++c) {
            const double d = frame.points[i][c] - frame.points[j][c];
            const double d0 = rest.points[i][c] - rest.points[j][c];
            l += d * d;
            l0 += d0 * d0;
        }
        if (!(l0 > 0)) return;
        const double s = std::sqrt(l / l0) - 1.0;
        if (!std::isfinite(s)) return;
        for (int v : {i, j})
            if (std::fabs(s) > std::fabs(out[v])) out[v] = s;
    };
    for (const auto& t : frame.triangles) {
        edge(t[0], t[1]);
        edge(t[1], t[2]);
        edge(t[2], t[0]);
    }
    for (const auto& line : frame.polylines)
        for (size_t k = 0; k + 1 < line.size(); ++k) edge(line[k], line[k + 1]);
    return out;
}

Rgb strainColour(double strain, Rgb base, double top) {
    const double s = std::isfinite(strain) && top > 0 ? std::clamp(strain / top, -1.0, 1.0) : 0.0;
    auto mix = [](Rgb a, Rgb b, double w) {
        return Rgb{a.r + w * (b.r - a.r), a.g + w * (b.g - a.g), a.b + w * (b.b - a.b)};
    };
    const Rgb yellow{0.98, 0.82, 0.22}, red{0.86, 0.12, 0.1}, teal{0.2, 0.82, 0.72};
    if (s < 0) return mix(base, teal, -s);
    return s < 0.5 ? mix(base, yellow, 2 * s) : mix(yellow, red, 2 * s - 1);
}

} // namespace gale::viz
