// Arrows on a grid and streamlines from a rake, computed from a field (volume_marks.h).
#include "viz/volume_marks.h"

#include "fields/grid_sample.h"

#include <algorithm>
#include <cmath>

namespace gale::viz {

namespace {

bool inside(const Box3& box, const double* p) {
    for (int c = 0; c < 3; ++c)
        if (!(p[c] >= box.lo[c] && p[c] <= box.hi[c])) return false;
    return true;
}

// Samples `count` points; non-finite velocities come back as zero.
fields::SampleStatus sampleAt(const fields::Field& field, const fields::SampleTime& when,
                              const std::vector<double>& positions,
                              std::vector<double>& velocities) {
    const size_t count = positions.size() / 3;
    velocities.assign(3 * count, 0.0);
    fields::GridSampleOptions sampling;
    sampling.threads = when.threads;
    fields::SampleStatus status =
        fields::samplePoints(field, positions.data(), count, when, velocities.data(), sampling);
    for (double& v : velocities)
        if (!std::isfinite(v)) v = 0.0;
    return status;
}

} // namespace

fields::SampleStatus sampleArrowVolume(const fields::Field& field, const fields::SampleTime& when,
                                       const Box3& box, int n, ArrowVolume& out) {
    out = ArrowVolume{};
    fields::SampleStatus status;
    if (n < 1 || n > 64) {
        status.ok = false;
        status.message = "arrow grid " + std::to_string(n) + " out of range (1 to 64 per side)";
        return status;
    }
    const size_t count = static_cast<size_t>(n) * n * n;
    std::vector<double> positions(3 * count), velocities;
    size_t i = 0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b)
            for (int c = 0; c < n; ++c, ++i) {
                const int idx[3] = {a, b, c};
                for (int k = 0; k < 3; ++k)
                    positions[3 * i + k] = box.lo[k] + (idx[k] + 0.5) / n * (box.hi[k] - box.lo[k]);
            }
    status = sampleAt(field, when, positions, velocities);
    if (!status.ok) return status;
    out.n = n;
    out.positions.assign(positions.begin(), positions.end());
    out.velocities.assign(velocities.begin(), velocities.end());
    for (size_t p = 0; p < count; ++p)
        out.maxSpeed =
            std::max(out.maxSpeed, std::sqrt(velocities[3 * p] * velocities[3 * p] +
                                             velocities[3 * p + 1] * velocities[3 * p + 1] +
                                             velocities[3 * p + 2] * velocities[3 * p + 2]));
    return status;
}

fields::SampleStatus traceRake(const fields::Field& field, const fields::SampleTime& when,
                               const Rake& rake, const Box3& box, const StreamlineOptions& options,
                               std::vector<Streamline>& out) {
    out.clear();
    fields::SampleStatus status;
    if (rake.count < 1 || rake.count > 4096 || !(options.step > 0) || options.maxSteps < 1 ||
        options.maxSteps > 4096) {
        status.ok = false;
        status.message = "rake of " + std::to_string(rake.count) +
                         " seeds: expected 1 to 4096 seeds, a positive step and 1 to 4096 steps";
        return status;
    }
    // Line 2s runs downstream from seed s, line 2s+1 upstream; both start at the seed.
    const int seeds = rake.count, lines = 2 * seeds;
    std::vector<std::vector<std::array<double, 4>>> paths(lines); // x, y, z, speed
    std::vector<std::array<double, 3>> at(lines);
    std::vector<char> alive(lines, 1);
    for (int s = 0; s < seeds; ++s) {
        const double u = seeds == 1 ? 0.5 : double(s) / (seeds - 1);
        for (int c = 0; c < 3; ++c) at[2 * s][c] = rake.a[c] + u * (rake.b[c] - rake.a[c]);
        at[2 * s + 1] = at[2 * s];
        if (!inside(box, at[2 * s].data())) alive[2 * s] = alive[2 * s + 1] = 0;
    }
    std::vector<int> live;
    std::vector<double> pos, vel;
    auto gather = [&](const std::vector<std::array<double, 3>>& points) {
        pos.resize(3 * live.size());
        for (size_t k = 0; k < live.size(); ++k)
            for (int c = 0; c < 3; ++c) pos[3 * k + c] = points[live[k]][c];
        return sampleAt(field, when, pos, vel);
    };
    std::vector<std::array<double, 3>> mid(lines);
    for (int step = 0; step <= options.maxSteps; ++step) {
        live.clear();
        for (int l = 0; l < lines; ++l)
            if (alive[l]) live.push_back(l);
        if (live.empty()) break;
        // Stage 1: the velocity at the current points (also the speed recorded there).
        if (fields::SampleStatus st = gather(at); !st.ok) return st;
        std::vector<int> next;
        for (size_t k = 0; k < live.size(); ++k) {
            const int l = live[k];
            const double* v = vel.data() + 3 * k;
            const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            paths[l].push_back({at[l][0], at[l][1], at[l][2], speed});
            if (step == options.maxSteps || !(speed > options.minSpeed)) {
                alive[l] = 0;
                continue;
            }
            const double h = (l % 2 == 0 ? 0.5 : -0.5) * options.step / speed;
            for (int c = 0; c < 3; ++c) mid[l][c] = at[l][c] + h * v[c];
            next.push_back(l);
        }
        live = next;
        if (live.empty()) break;
        // Stage 2: the velocity at the midpoints gives the step.
        if (fields::SampleStatus st = gather(mid); !st.ok) return st;
        for (size_t k = 0; k < live.size(); ++k) {
            const int l = live[k];
            const double* v = vel.data() + 3 * k;
            const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (!(speed > options.minSpeed)) {
                alive[l] = 0;
                continue;
            }
            const double h = (l % 2 == 0 ? 1.0 : -1.0) * options.step / speed;
            for (int c = 0; c < 3; ++c) at[l][c] += h * v[c];
            if (!inside(box, at[l].data())) alive[l] = 0;
        }
    }
    for (int s = 0; s < seeds; ++s) {
        Streamline line;
        const auto& up = paths[2 * s + 1];
        const auto& down = paths[2 * s];
        for (size_t k = up.size(); k-- > 1;) { // upstream reversed, without the seed twice
            line.points.push_back({float(up[k][0]), float(up[k][1]), float(up[k][2])});
            line.speed.push_back(float(up[k][3]));
        }
        for (const auto& p : down) {
            line.points.push_back({float(p[0]), float(p[1]), float(p[2])});
            line.speed.push_back(float(p[3]));
        }
        if (line.points.size() >= 2) out.push_back(std::move(line));
    }
    return status;
}

} // namespace gale::viz
