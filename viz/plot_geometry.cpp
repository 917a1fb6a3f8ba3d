// The drawing-library-free parts of viz pictures: viridis, ticks, streamline tracing.
#include "viz/plot_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gale::viz {

// matplotlib's viridis (CC0), every 8th of its 256 entries and the last.
namespace {

constexpr int kViridisSize = 33;
constexpr double kViridis[kViridisSize][3] = {
    {0.267004, 0.004874, 0.329415}, {0.277018, 0.050344, 0.375715}, {0.282327, 0.094955, 0.417331},
    {0.282884, 0.135920, 0.453427}, {0.278826, 0.175490, 0.483397}, {0.270595, 0.214069, 0.507052},
    {0.258965, 0.251537, 0.524736}, {0.244972, 0.287675, 0.537260}, {0.229739, 0.322361, 0.545706},
    {0.214298, 0.355619, 0.551184}, {0.199430, 0.387607, 0.554642}, {0.185556, 0.418570, 0.556753},
    {0.172719, 0.448791, 0.557885}, {0.160665, 0.478540, 0.558115}, {0.149039, 0.508051, 0.557250},
    {0.137770, 0.537492, 0.554906}, {0.127568, 0.566949, 0.550556}, {0.120565, 0.596422, 0.543611},
    {0.120638, 0.625828, 0.533488}, {0.132268, 0.655014, 0.519661}, {0.157851, 0.683765, 0.501686},
    {0.196571, 0.711827, 0.479221}, {0.246070, 0.738910, 0.452024}, {0.304148, 0.764704, 0.419943},
    {0.369214, 0.788888, 0.382914}, {0.440137, 0.811138, 0.340967}, {0.515992, 0.831158, 0.294279},
    {0.595839, 0.848717, 0.243329}, {0.678489, 0.863742, 0.189503}, {0.762373, 0.876424, 0.137064},
    {0.845561, 0.887322, 0.099702}, {0.926106, 0.897330, 0.104071}, {0.993248, 0.906157, 0.143936},
};

} // namespace

Rgb viridis(double s) {
    if (!(s > 0)) s = 0;
    if (s > 1) s = 1;
    // Entry e sits at 8e/255 (the last at 1).
    const double pos = s * 255.0 / 8.0;
    int e = std::min(static_cast<int>(pos), kViridisSize - 2);
    const double span = e == kViridisSize - 2 ? 7.0 / 8.0 : 1.0;
    const double f = std::min((pos - e) / span, 1.0);
    return {kViridis[e][0] + f * (kViridis[e + 1][0] - kViridis[e][0]),
            kViridis[e][1] + f * (kViridis[e + 1][1] - kViridis[e][1]),
            kViridis[e][2] + f * (kViridis[e + 1][2] - kViridis[e][2])};
}

double niceStep(double range, int count) {
    if (!(range > 0) || count < 1) return 1.0;
    const double raw = range / count;
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    const double f = raw / p;
    return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p;
}

double niceCeil(double v) {
    if (!(v > 0)) return 1.0;
    const double p = std::pow(10.0, std::floor(std::log10(v)));
    for (double f : {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0})
        if (f * p >= v * (1 - 1e-12)) return f * p;
    return 10.0 * p;
}

std::vector<double> ticks(double lo, double hi, int count, double& step) {
    step = niceStep(hi - lo, count);
    std::vector<double> out;
    for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + 1e-9 * step; t += step)
        out.push_back(std::fabs(t) < 1e-12 * step ? 0.0 : t);
    return out;
}

std::string tickLabel(double v, double step) {
    char buf[64];
    const double a = std::fabs(v);
    if (step > 0 && (step < 1e-4 || a >= 1e6)) {
        // Very small or large: just enough significant digits to tell neighbours apart.
        const int digits = static_cast<int>(std::floor(std::log10(std::max(a, step))) -
                                            std::floor(std::log10(step))) +
                           1;
        std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits, 1, 15), v);
    } else {
        int decimals = 0;
        for (double s = step; decimals < 6 && std::fabs(s - std::round(s)) > 1e-6 * step; s *= 10.0)
            ++decimals;
        std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    }
    std::string out = buf;
    if (out.find_first_not_of("-0.") == std::string::npos && out[0] == '-') out.erase(0, 1);
    return out;
}

std::vector<Polyline> traceStreamlines(const DirectionFn& direction, double width, double height,
                                       double separation, double step) {
    const double sep = separation, test = 0.5 * separation, h = step;
    const int gw = static_cast<int>(width / test) + 1, gh = static_cast<int>(height / test) + 1;
    std::vector<Polyline> grid(static_cast<size_t>(gw) * gh);
    auto cellOf = [&](double x, double y) {
        return static_cast<size_t>(std::clamp(static_cast<int>(y / test), 0, gh - 1)) * gw +
               static_cast<size_t>(std::clamp(static_cast<int>(x / test), 0, gw - 1));
    };
    auto near = [&](double x, double y, double dist) {
        const int cx = static_cast<int>(x / test), cy = static_cast<int>(y / test);
        for (int j = cy - 2; j <= cy + 2; ++j)
            for (int i = cx - 2; i <= cx + 2; ++i) {
                if (i < 0 || j < 0 || i >= gw || j >= gh) continue;
                for (const auto& p : grid[static_cast<size_t>(j) * gw + i])
                    if (std::hypot(p[0] - x, p[1] - y) < dist) return true;
            }
        return false;
    };
    const int maxSteps = static_cast<int>(4 * (width + height) / h);
    std::vector<Polyline> lines;
    auto trace = [&](double x, double y, double sign) {
        Polyline pts;
        for (int n = 0; n < maxSteps; ++n) {
            double dx, dy, mx, my;
            if (!direction(x, y, dx, dy)) break;
            if (!direction(x + 0.5 * h * sign * dx, y + 0.5 * h * sign * dy, mx, my)) break;
            x += h * sign * mx;
            y += h * sign * my;
            if (x < 0 || y < 0 || x > width || y > height) break;
            if (near(x, y, test)) break;
            // Closed orbits: stop when coming back to this line's own earlier points.
            const size_t own = pts.size();
            const size_t skip = static_cast<size_t>(2 * sep / h);
            bool loop = false;
            for (size_t k = 0; own > skip && k + skip < own && !loop; k += 2)
                loop = std::hypot(pts[k][0] - x, pts[k][1] - y) < 0.5 * test;
            if (loop) break;
            pts.push_back({x, y});
        }
        return pts;
    };
    for (double sy = 0.5 * sep; sy < height; sy += sep)
        for (double sx = 0.5 * sep; sx < width; sx += sep) {
            if (near(sx, sy, sep)) continue;
            Polyline back = trace(sx, sy, -1.0);
            Polyline fwd = trace(sx, sy, 1.0);
            Polyline line(back.rbegin(), back.rend());
            line.push_back({sx, sy});
            line.insert(line.end(), fwd.begin(), fwd.end());
            if (static_cast<double>(line.size()) * h < 1.5 * sep) continue;
            for (const auto& p : line) grid[cellOf(p[0], p[1])].push_back(p);
            lines.push_back(std::move(line));
        }
    return lines;
}

} // namespace gale::viz
