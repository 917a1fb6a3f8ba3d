// Computing one field view (field_frame.h): slice, arrows and rake streamlines, timed.
#include "live/field_frame.h"

#include <chrono>
#include <cmath>

namespace gale::live {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

bool computeFieldFrame(const fields::Field& field, double fps, const viz::Box3& box,
                       const FieldRequest& r, FieldFrame& out, std::string& error) {
    out = FieldFrame{};
    if (!std::isfinite(r.time) || !std::isfinite(r.planeValue) || r.axis < 0 || r.axis > 2) {
        error = "time and plane must be finite numbers, axis 0, 1 or 2";
        return false;
    }
    if (r.res < 8 || r.res > 512 || r.arrows < 0 || r.arrows > 32 || r.rake.count < 0 ||
        r.rake.count > 1024) {
        error = "res must be 8 to 512, arrows 0 to 32 per side, lines 0 to 1024";
        return false;
    }
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(r.rake.a[c]) || !std::isfinite(r.rake.b[c])) {
            error = "the rake's ends must be finite";
            return false;
        }
    fields::SampleTime when;
    when.time = r.time;
    when.fps = fps;
    when.threads = 0;

    // The slice spans the box across the plane's two other axes (u right, v up as gale viz draws
    // them: z=C shows x,y; y=C shows x,z; x=C shows z,y).
    auto t0 = std::chrono::steady_clock::now();
    viz::Slice& s = out.slice;
    s.normalAxis = r.axis;
    viz::planeAxes(r.axis, s.uAxis, s.vAxis);
    s.planeValue = r.planeValue;
    s.bounds = {box.lo[s.uAxis], box.lo[s.vAxis], box.hi[s.uAxis], box.hi[s.vAxis]};
    const double w = s.bounds[2] - s.bounds[0], h = s.bounds[3] - s.bounds[1];
    s.nu = w >= h ? r.res : std::max(2, static_cast<int>(std::lround(r.res * w / h)));
    s.nv = h >= w ? r.res : std::max(2, static_cast<int>(std::lround(r.res * h / w)));
    const fields::SampleStatus st = viz::sampleSlice(field, when, s);
    if (!st.ok || st.nonFinite > 0) {
        error = !st.ok ? "cannot sample the field: " + st.message
                       : std::to_string(st.nonFinite) +
                             " slice sample(s) gave a non-finite velocity at t = " +
                             std::to_string(r.time) + " s";
        return false;
    }
    out.speed = viz::speedScale(s, r.speedMax);
    out.times.slice = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    if (r.arrows > 0) {
        const fields::SampleStatus a =
            viz::sampleArrowVolume(field, when, box, r.arrows, out.arrows);
        if (!a.ok) {
            error = "cannot sample the arrows: " + a.message;
            return false;
        }
    }
    out.times.arrows = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    if (r.rake.count > 0) {
        viz::StreamlineOptions opt;
        double size = 0.0;
        for (int c = 0; c < 3; ++c) size = std::max(size, box.hi[c] - box.lo[c]);
        opt.step = size / 40.0; // 64 steps each way: 1.6 box sizes
        opt.maxSteps = 64;
        const fields::SampleStatus l =
            viz::traceRake(field, when, r.rake, box, opt, out.streamlines);
        if (!l.ok) {
            error = "cannot trace the streamlines: " + l.message;
            return false;
        }
    }
    out.times.streamlines = msSince(t0);
    return true;
}

} // namespace gale::live
