// What is drawn on a sampled slice, as data: sampling the slice, the speed scale, the arrow
// grid and the streamlines (slice_marks.h). The cairo backend and the live page both use these.
#include "viz/slice_marks.h"

#include "fields/grid_sample.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gale::viz {

namespace {

// In-plane velocity of sample (col,row) in pixel directions (right, down).
void inPlane(const Slice& s, int col, int row, double& px, double& py) {
    const float* v = s.velocity.data() + 3 * (static_cast<size_t>(row) * s.nu + col);
    px = v[s.uAxis];
    py = -v[s.vAxis];
}

} // namespace

void planeAxes(int normal, int& uAxis, int& vAxis) {
    uAxis = normal == 2 ? 0 : normal == 1 ? 0 : 2;
    vAxis = normal == 2 ? 1 : normal == 1 ? 2 : 1;
}

bool geometryBounds(const std::vector<const GeometryOverlay*>& all, int uAxis, int vAxis,
                    std::array<double, 4>& b) {
    double lo[2] = {std::numeric_limits<double>::infinity(),
                    std::numeric_limits<double>::infinity()};
    double hi[2] = {-lo[0], -lo[1]};
    for (const GeometryOverlay* g : all)
        for (const auto& p : g->points) {
            if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
            lo[0] = std::min(lo[0], p[uAxis]);
            hi[0] = std::max(hi[0], p[uAxis]);
            lo[1] = std::min(lo[1], p[vAxis]);
            hi[1] = std::max(hi[1], p[vAxis]);
        }
    if (!(hi[0] >= lo[0]) || !(hi[1] >= lo[1])) return false;
    const double pad = std::max(0.05, 0.15 * std::max(hi[0] - lo[0], hi[1] - lo[1]));
    b = {lo[0] - pad, lo[1] - pad, hi[0] + pad, hi[1] + pad};
    return true;
}

fields::SampleStatus sampleSlice(const fields::Field& field, const fields::SampleTime& when,
                                 viz::Slice& slice) {
    const int uAxis = slice.uAxis, vAxis = slice.vAxis, normal = slice.normalAxis;
    const std::array<double, 4>& b = slice.bounds;
    const size_t n = static_cast<size_t>(slice.nu) * static_cast<size_t>(slice.nv);
    std::vector<double> positions(3 * n), velocities(3 * n, 0.0);
    for (int row = 0; row < slice.nv; ++row)
        for (int col = 0; col < slice.nu; ++col) {
            double* p = positions.data() + 3 * (static_cast<size_t>(row) * slice.nu + col);
            p[uAxis] = b[0] + (col + 0.5) / slice.nu * (b[2] - b[0]);
            p[vAxis] = b[3] - (row + 0.5) / slice.nv * (b[3] - b[1]);
            p[normal] = slice.planeValue;
        }
    fields::GridSampleOptions sampling;
    sampling.threads = when.threads;
    fields::SampleStatus status =
        fields::samplePoints(field, positions.data(), n, when, velocities.data(), sampling);
    slice.velocity.clear();
    if (!status.ok || status.nonFinite > 0) return status;
    slice.velocity.resize(3 * n);
    for (size_t i = 0; i < 3 * n; ++i) slice.velocity[i] = static_cast<float>(velocities[i]);
    return status;
}

SpeedScale speedScale(const Slice& slice, double speedMax) {
    SpeedScale s;
    const size_t n = static_cast<size_t>(slice.nu) * static_cast<size_t>(slice.nv);
    if (slice.velocity.size() < 3 * n) return s; // no field sampled: a backdrop instead
    s.speed.resize(n);
    for (size_t i = 0; i < n; ++i) {
        const float* v = slice.velocity.data() + 3 * i;
        s.speed[i] = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
        s.max = std::max(s.max, s.speed[i]);
    }
    s.top = speedMax > 0 ? speedMax : niceCeil(s.max > 0 ? s.max : 1.0);
    return s;
}

double markSpacing(const RenderSettings& settings, double plotW, double plotH, double scale) {
    if (settings.arrowSpacing > 0) return settings.arrowSpacing;
    return std::max(26.0 * scale, std::max(plotW, plotH) / 22.0);
}

ArrowGrid sliceArrows(const Slice& slice, double plotW, double plotH, double spacing) {
    ArrowGrid g;
    const int na = std::max(1, static_cast<int>(std::lround(plotW / spacing)));
    const int nb = std::max(1, static_cast<int>(std::lround(plotH / spacing)));
    const double cw = plotW / na, ch = plotH / nb;
    for (int b = 0; b < nb; ++b)
        for (int a = 0; a < na; ++a) {
            const double cx = (a + 0.5) * cw, cy = (b + 0.5) * ch;
            const int col = std::min(slice.nu - 1, static_cast<int>(cx * slice.nu / plotW));
            const int row = std::min(slice.nv - 1, static_cast<int>(cy * slice.nv / plotH));
            ArrowMark m;
            m.x = cx;
            m.y = cy;
            inPlane(slice, col, row, m.vx, m.vy);
            m.magnitude = std::hypot(m.vx, m.vy);
            g.reference = std::max(g.reference, m.magnitude);
            g.arrows.push_back(m);
        }
    g.cell = std::min(cw, ch);
    return g;
}

bool sliceDirection(const Slice& s, double plotW, double plotH, double maxSpeed, double x, double y,
                    double& dx, double& dy) {
    if (x < 0 || y < 0 || x > plotW || y > plotH) return false;
    const double fx = std::clamp(x * s.nu / plotW - 0.5, 0.0, s.nu - 1.0);
    const double fy = std::clamp(y * s.nv / plotH - 0.5, 0.0, s.nv - 1.0);
    const int c0 = std::min(static_cast<int>(fx), s.nu - 1);
    const int r0 = std::min(static_cast<int>(fy), s.nv - 1);
    const int c1 = std::min(c0 + 1, s.nu - 1), r1 = std::min(r0 + 1, s.nv - 1);
    const double tx = fx - c0, ty = fy - r0;
    double a[2], b[2], c[2], d[2];
    inPlane(s, c0, r0, a[0], a[1]);
    inPlane(s, c1, r0, b[0], b[1]);
    inPlane(s, c0, r1, c[0], c[1]);
    inPlane(s, c1, r1, d[0], d[1]);
    dx = (1 - ty) * ((1 - tx) * a[0] + tx * b[0]) + ty * ((1 - tx) * c[0] + tx * d[0]);
    dy = (1 - ty) * ((1 - tx) * a[1] + tx * b[1]) + ty * ((1 - tx) * c[1] + tx * d[1]);
    const double m = std::hypot(dx, dy);
    if (!(m > 1e-6 * std::max(maxSpeed, 1e-12))) return false;
    dx /= m;
    dy /= m;
    return true;
}

std::vector<Polyline> sliceStreamlines(const Slice& slice, double plotW, double plotH,
                                       double maxSpeed, double separation, double step) {
    return traceStreamlines(
        [&](double x, double y, double& dx, double& dy) {
            return sliceDirection(slice, plotW, plotH, maxSpeed, x, y, dx, dy);
        },
        plotW, plotH, separation, step);
}

} // namespace gale::viz
