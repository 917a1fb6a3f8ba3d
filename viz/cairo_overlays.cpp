// The rigs drawn over a viz picture by the cairo backend: the windicator inset with its
// arrow key, the bands of the gust fronts on the plot and the gust timeline strip.
#include "viz/cairo_painter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gale::viz::cairo_detail {

void Painter::drawArrowKey(double x, double y) {
    double key = niceStep(mArrowRef, 1);
    while (key > mArrowRef) key /= 2;
    const double len = 0.9 * mArrowCell * key / mArrowRef;
    setFont(mCr, 11 * mS);
    setColor(mCr, kMuted);
    text(mCr, x, y + 10 * mS, "arrows: in-plane");
    const double ay = y + 26 * mS;
    cairo_rectangle(mCr, x - 2 * mS, ay - 9 * mS, len + 4 * mS, 18 * mS);
    setColor(mCr, viridis(0.15));
    cairo_fill(mCr);
    haloArrow(mCr, x, ay, x + len, ay, std::min(9.0 * mS, 0.4 * 0.9 * mArrowCell), 1.3 * mS);
    setFont(mCr, 12 * mS);
    setColor(mCr, kInk);
    text(mCr, x + len + 6 * mS, ay + 4 * mS, "= " + tickLabel(key, key) + " m/s");
}

void Painter::drawWindicator() {
    const WindicatorOverlay& w = mOver.windicator;
    const double bx = mL.plot.x + 10 * mS, by = mL.plot.y + 10 * mS;
    const double bw = 190 * mS, bh = 66 * mS;
    if (bw > mL.plot.w - 20 * mS || bh > mL.plot.h - 20 * mS) return;
    roundedRect(mCr, bx, by, bw, bh, 6 * mS);
    cairo_set_source_rgba(mCr, 1, 1, 1, 0.9);
    cairo_fill_preserve(mCr);
    setColor(mCr, kMuted, 0.6);
    cairo_set_line_width(mCr, 1.0);
    cairo_stroke(mCr);
    const double cx = bx + 33 * mS, cy = by + bh / 2, r = 24 * mS;
    cairo_arc(mCr, cx, cy, r, 0, 2 * M_PI);
    setColor(mCr, kMuted, 0.35);
    cairo_stroke(mCr);
    const double du = w.direction[static_cast<size_t>(mSlice.uAxis)];
    const double dv = w.direction[static_cast<size_t>(mSlice.vAxis)];
    const double dn = w.direction[static_cast<size_t>(mSlice.normalAxis)];
    const double inPlane = std::hypot(du, dv);
    setColor(mCr, kWindicator);
    cairo_set_line_width(mCr, 3 * mS);
    cairo_set_line_cap(mCr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_join(mCr, CAIRO_LINE_JOIN_ROUND);
    if (inPlane >= 0.2) {
        const double ux = du / inPlane, uy = -dv / inPlane, len = 2 * r * 0.85 * inPlane;
        arrowPath(mCr, cx - 0.5 * len * ux, cy - 0.5 * len * uy, cx + 0.5 * len * ux,
                  cy + 0.5 * len * uy, 11 * mS);
        cairo_stroke_preserve(mCr);
        cairo_fill(mCr);
    } else {
        // Mostly across the plane: towards the viewer (dot) or away (cross). The viewer
        // looks along -(u x v).
        const int uxv = (mSlice.uAxis + 1) % 3 == mSlice.vAxis ? 1 : -1; // u x v = +-normal
        const bool towards = dn * uxv > 0;
        cairo_arc(mCr, cx, cy, 0.55 * r, 0, 2 * M_PI);
        cairo_stroke(mCr);
        if (towards) {
            cairo_arc(mCr, cx, cy, 3.5 * mS, 0, 2 * M_PI);
            cairo_fill(mCr);
        } else {
            const double k = 0.55 * r * 0.7;
            cairo_move_to(mCr, cx - k, cy - k);
            cairo_line_to(mCr, cx + k, cy + k);
            cairo_move_to(mCr, cx + k, cy - k);
            cairo_line_to(mCr, cx - k, cy + k);
            cairo_stroke(mCr);
        }
    }
    const double tx = bx + 66 * mS;
    setColor(mCr, kInk);
    setFont(mCr, 12 * mS, Weight::Bold);
    text(mCr, tx, by + 20 * mS, "windicator");
    setFont(mCr, 15 * mS);
    setColor(mCr, kWindicator);
    text(mCr, tx, by + 40 * mS, speedText(w.speed) + " m/s");
    setFont(mCr, 11 * mS);
    setColor(mCr, kMuted);
    text(mCr, tx, by + 57 * mS,
         "dir " + fixed(w.direction[0], 2) + ", " + fixed(w.direction[1], 2) + ", " +
             fixed(w.direction[2], 2));
}

bool Painter::planeLine(double du, double dv, double s, double& x0, double& y0, double& x1,
               double& y1) const {
    const double u0 = mSlice.bounds[0], v0 = mSlice.bounds[1];
    const double u1 = mSlice.bounds[2], v1 = mSlice.bounds[3];
    std::vector<std::array<double, 2>> hits;
    if (std::fabs(dv) > 1e-12)
        for (double u : {u0, u1}) {
            const double v = (s - du * u) / dv;
            if (v >= v0 && v <= v1) hits.push_back({u, v});
        }
    if (std::fabs(du) > 1e-12)
        for (double v : {v0, v1}) {
            const double u = (s - dv * v) / du;
            if (u >= u0 && u <= u1) hits.push_back({u, v});
        }
    if (hits.size() < 2) return false;
    x0 = pxOfU(hits[0][0]);
    y0 = pyOfV(hits[0][1]);
    x1 = pxOfU(hits.back()[0]);
    y1 = pyOfV(hits.back()[1]);
    return std::hypot(x1 - x0, y1 - y0) > 1.0;
}

void Painter::drawGustBands() {
    cairo_save(mCr);
    clipToPlot();
    struct Label {
        std::string text;
        double x, y;
        bool front;
    };
    std::vector<Label> labels; // drawn after every line, so no line crosses a label
    for (const GustBand& g : mOver.gusts) {
        const double du = g.direction[static_cast<size_t>(mSlice.uAxis)];
        const double dv = g.direction[static_cast<size_t>(mSlice.vAxis)];
        const double off =
            g.direction[static_cast<size_t>(mSlice.normalAxis)] * mSlice.planeValue;
        if (std::hypot(du, dv) < 0.2) continue; // fronts nearly parallel to the slice
        for (int edge = 0; edge < 2; ++edge) {
            double x0, y0, x1, y1;
            const double s = (edge == 0 ? g.front : g.tail) - off;
            if (!planeLine(du, dv, s, x0, y0, x1, y1)) continue;
            const double dash[] = {8 * mS, 5 * mS};
            cairo_set_dash(mCr, dash, 2, 0);
            cairo_move_to(mCr, x0, y0);
            cairo_line_to(mCr, x1, y1);
            cairo_set_source_rgba(mCr, 1, 1, 1, 0.8);
            cairo_set_line_width(mCr, (edge == 0 ? 4.5 : 3.0) * mS);
            cairo_stroke_preserve(mCr);
            setColor(mCr, kGustEdge);
            cairo_set_line_width(mCr, (edge == 0 ? 2.2 : 1.2) * mS);
            cairo_stroke(mCr);
            cairo_set_dash(mCr, nullptr, 0, 0);
            // Label the front near its lower end, the tail near its upper end.
            const double lx = (y0 > y1) == (edge == 0) ? x0 : x1;
            const double ly = edge == 0 ? std::max(y0, y1) : std::min(y0, y1) + 26 * mS;
            labels.push_back({g.label + (edge == 0 ? " front" : " tail"), lx, ly, edge == 0});
        }
    }
    for (const Label& l : labels) {
        setFont(mCr, 12 * mS, l.front ? Weight::Bold : Weight::Normal);
        const double tw = textWidth(mCr, l.text);
        const double px =
            std::clamp(l.x + 6 * mS, mL.plot.x + 4 * mS, mL.plot.x + mL.plot.w - tw - 8 * mS);
        const double py =
            std::clamp(l.y - 10 * mS, mL.plot.y + 16 * mS, mL.plot.y + mL.plot.h - 8 * mS);
        roundedRect(mCr, px - 3 * mS, py - 12 * mS, tw + 6 * mS, 16 * mS, 3 * mS);
        cairo_set_source_rgba(mCr, 1, 1, 1, 0.85);
        cairo_fill(mCr);
        setColor(mCr, kGustEdge);
        text(mCr, px, py, l.text);
    }
    cairo_restore(mCr);
}

void Painter::drawTimeline() {
    const TimelineOverlay& tl = mOver.timeline;
    const PixelRect& r = mL.timeline;
    const double left = r.x, right = r.x + r.w;
    const double top = r.y + 26 * mS, bottom = r.y + r.h - 30 * mS;
    if (!(tl.t1 > tl.t0) || bottom - top < 20) return;
    auto xOf = [&](double t) { return left + (t - tl.t0) / (tl.t1 - tl.t0) * (right - left); };
    double vmax = 0.0;
    for (const auto& c : tl.gusts)
        for (const auto& p : c.points) vmax = std::max(vmax, p[1]);
    for (const auto& p : tl.windicatorSpeed.points) vmax = std::max(vmax, p[1]);
    vmax = niceCeil(vmax > 0 ? 1.1 * vmax : 1.0); // headroom for the labels
    auto yOf = [&](double v) { return bottom - v / vmax * (bottom - top); };

    setColor(mCr, kInk);
    setFont(mCr, 13 * mS, Weight::Bold);
    text(mCr, left, r.y + 14 * mS, "timeline");
    const double described = left + textWidth(mCr, "timeline") + 12 * mS;
    // Frame: the scene's frame range on white, the rest light grey.
    cairo_rectangle(mCr, left, top, right - left, bottom - top);
    cairo_set_source_rgb(mCr, 0.95, 0.955, 0.96);
    cairo_fill(mCr);
    if (tl.sceneEnd > tl.sceneStart) {
        cairo_rectangle(mCr, xOf(tl.sceneStart), top, xOf(tl.sceneEnd) - xOf(tl.sceneStart),
                        bottom - top);
        cairo_set_source_rgb(mCr, 1, 1, 1);
        cairo_fill(mCr);
    }
    // Value grid lines.
    double step;
    setFont(mCr, 11 * mS);
    cairo_set_line_width(mCr, 1.0);
    for (double v : ticks(0.0, vmax, 3, step)) {
        const double y = std::round(yOf(v)) + 0.5;
        cairo_move_to(mCr, left, y);
        cairo_line_to(mCr, right, y);
        setColor(mCr, kMuted, 0.25);
        cairo_stroke(mCr);
        setColor(mCr, kMuted);
        text(mCr, left - 6 * mS, y + 4 * mS, tickLabel(v, step), 1.0);
    }
    // Gusts: filled envelopes with their names at the peak.
    for (const auto& c : tl.gusts) {
        if (c.points.empty()) continue;
        cairo_move_to(mCr, xOf(c.points.front()[0]), yOf(0));
        for (const auto& p : c.points) cairo_line_to(mCr, xOf(p[0]), yOf(p[1]));
        cairo_line_to(mCr, xOf(c.points.back()[0]), yOf(0));
        cairo_close_path(mCr);
        setColor(mCr, kGust, 0.35);
        cairo_fill_preserve(mCr);
        setColor(mCr, kGustEdge);
        cairo_set_line_width(mCr, 1.5 * mS);
        cairo_stroke(mCr);
        const auto peak =
            *std::max_element(c.points.begin(), c.points.end(),
                              [](const auto& a, const auto& b) { return a[1] < b[1]; });
        setFont(mCr, 11 * mS, Weight::Bold);
        setColor(mCr, kGustEdge);
        text(mCr, xOf(peak[0]), std::max(yOf(peak[1]) - 4 * mS, top + 11 * mS), c.label, 0.5);
    }
    if (!tl.windicatorSpeed.points.empty()) {
        const auto& pts = tl.windicatorSpeed.points;
        cairo_move_to(mCr, xOf(pts[0][0]), yOf(pts[0][1]));
        for (const auto& p : pts) cairo_line_to(mCr, xOf(p[0]), yOf(p[1]));
        setColor(mCr, kSpeedLine);
        cairo_set_line_width(mCr, 2 * mS);
        cairo_stroke(mCr);
    }
    setColor(mCr, kInk);
    cairo_set_line_width(mCr, 1.0);
    cairo_rectangle(mCr, left - 0.5, top - 0.5, right - left + 1, bottom - top + 1);
    cairo_stroke(mCr);
    // Time ticks.
    setFont(mCr, 11 * mS);
    const int count = std::max(2, static_cast<int>((right - left) / (80 * mS)));
    for (double t : ticks(tl.t0, tl.t1, count, step)) {
        const double x = std::round(xOf(t)) + 0.5;
        cairo_move_to(mCr, x, bottom);
        cairo_line_to(mCr, x, bottom + 4 * mS);
        cairo_stroke(mCr);
        text(mCr, x, bottom + 16 * mS, tickLabel(t, step), 0.5);
    }
    text(mCr, right, bottom + 28 * mS, "t (s)", 1.0);
    // Now.
    const double x = xOf(std::clamp(mSet.time, tl.t0, tl.t1));
    cairo_move_to(mCr, x, top - 4 * mS);
    cairo_line_to(mCr, x, bottom);
    setColor(mCr, kNow);
    cairo_set_line_width(mCr, 2 * mS);
    cairo_stroke(mCr);
    setFont(mCr, 11 * mS, Weight::Bold);
    const std::string now = "t = " + tickLabel(mSet.time, 0.01) + " s";
    const double tw = textWidth(mCr, now);
    const double tx = x + 5 * mS + tw > right ? x - 5 * mS - tw : x + 5 * mS;
    roundedRect(mCr, tx - 2 * mS, top + 2 * mS, tw + 4 * mS, 15 * mS, 2 * mS);
    cairo_set_source_rgba(mCr, 1, 1, 1, 0.85);
    cairo_fill(mCr);
    setColor(mCr, kNow);
    text(mCr, tx, top + 13 * mS, now);
    // Key.
    setFont(mCr, 11 * mS);
    double kx = right - 4 * mS;
    auto key = [&](const std::string& label, const Rgb& c, bool box) {
        const double w = textWidth(mCr, label);
        kx -= w;
        setColor(mCr, kMuted);
        text(mCr, kx, r.y + 14 * mS, label);
        kx -= 20 * mS;
        setColor(mCr, c, box ? 0.6 : 1.0);
        if (box)
            cairo_rectangle(mCr, kx + 2 * mS, r.y + 5 * mS, 14 * mS, 10 * mS);
        else
            cairo_rectangle(mCr, kx + 2 * mS, r.y + 9 * mS, 14 * mS, 2.5 * mS);
        cairo_fill(mCr);
        kx -= 14 * mS;
    };
    if (!tl.windicatorSpeed.points.empty()) key("windicator", kSpeedLine, false);
    if (!tl.gusts.empty()) key("gust", kGust, true);
    // What the strip shows, as much as fits left of the key.
    setFont(mCr, 12 * mS);
    setColor(mCr, kMuted);
    for (const char* d : {"gust envelopes at the origin plane and windicator speed (m/s)",
                          "at the origin plane (m/s)", "(m/s)"})
        if (described + textWidth(mCr, d) < kx - 8 * mS) {
            text(mCr, described, r.y + 14 * mS, d);
            break;
        }
}

} // namespace gale::viz::cairo_detail
