// Internals of the cairo backend, shared by cairo_slice.cpp (the plot: speed raster, arrows,
// streamlines, simulated geometry, axes, colour bar; PNG and SVG output, contact sheets) and
// cairo_overlays.cpp (the windicator inset, gust bands and the gust timeline). Only these
// files include cairo. Not part of the public API.
#pragma once

#include "viz/cairo_render.h"
#include "viz/plot_geometry.h"

#include <cairo.h>

#include <cmath>
#include <string>
#include <vector>

namespace gale::viz::cairo_detail {

// ---- colours ----

inline const Rgb kInk{0.13, 0.13, 0.15};
inline const Rgb kMuted{0.42, 0.44, 0.47};
inline const Rgb kWindicator{0.85, 0.28, 0.06};
inline const Rgb kGust{0.94, 0.55, 0.0};
inline const Rgb kGustEdge{0.91, 0.35, 0.05};
inline const Rgb kNow{0.88, 0.19, 0.19};
inline const Rgb kSpeedLine{0.11, 0.49, 0.84};

inline void setColor(cairo_t* cr, const Rgb& c, double alpha = 1.0) {
    cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

// ---- text ----

enum class Weight { Normal, Bold };

inline void setFont(cairo_t* cr, double size, Weight w = Weight::Normal) {
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           w == Weight::Bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
}

inline double textWidth(cairo_t* cr, const std::string& s) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    return e.x_advance;
}

// Draws `s` with its baseline at y; align 0 left, 0.5 centre, 1 right of x.
inline void text(cairo_t* cr, double x, double y, const std::string& s, double align = 0.0) {
    cairo_move_to(cr, x - align * textWidth(cr, s), y);
    cairo_show_text(cr, s.c_str());
}

inline std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

// Speeds: 12.3, 3.14, 0.052, 2.4e-06.
inline std::string speedText(double v) {
    const double a = std::fabs(v);
    if (a > 0 && a < 0.01) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.2g", v);
        return buf;
    }
    return fixed(v, a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 2 : 3);
}

// ---- shapes ----

inline void roundedRect(cairo_t* cr, double x, double y, double w, double h, double r) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, x + w - r, y + r, r, -M_PI / 2, 0);
    cairo_arc(cr, x + w - r, y + h - r, r, 0, M_PI / 2);
    cairo_arc(cr, x + r, y + h - r, r, M_PI / 2, M_PI);
    cairo_arc(cr, x + r, y + r, r, M_PI, 3 * M_PI / 2);
    cairo_close_path(cr);
}

// An arrow from (x0,y0) to (x1,y1) with a filled head of length `head`; stroked in the
// current source at `width`.
inline void arrowPath(cairo_t* cr, double x0, double y0, double x1, double y1, double head) {
    const double dx = x1 - x0, dy = y1 - y0, len = std::hypot(dx, dy);
    if (len <= 0) return;
    const double ux = dx / len, uy = dy / len;
    head = std::min(head, 0.6 * len);
    const double bx = x1 - ux * head, by = y1 - uy * head;
    cairo_move_to(cr, x0, y0);
    cairo_line_to(cr, bx, by);
    cairo_move_to(cr, x1, y1);
    cairo_line_to(cr, bx - uy * head * 0.5, by + ux * head * 0.5);
    cairo_line_to(cr, bx + uy * head * 0.5, by - ux * head * 0.5);
    cairo_close_path(cr);
}

// Black arrow with a white halo: readable on every colour of the map.
inline void haloArrow(cairo_t* cr, double x0, double y0, double x1, double y1, double head, double width) {
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    arrowPath(cr, x0, y0, x1, y1, head);
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_set_line_width(cr, width * 2.6);
    cairo_stroke_preserve(cr);
    setColor(cr, kInk);
    cairo_set_line_width(cr, width);
    cairo_stroke_preserve(cr);
    cairo_fill(cr);
}

// ---- the picture ----

class Painter {
public:
    Painter(cairo_t* cr, const SliceLayout& layout, const Slice& slice,
            const SliceOverlays& overlays, const RenderSettings& settings)
        : mCr(cr), mL(layout), mSlice(slice), mOver(overlays), mSet(settings), mS(layout.scale) {}

    void paint();

private:
    double metresPerPixel() const { return (mSlice.bounds[2] - mSlice.bounds[0]) / mL.plot.w; }
    // World (u, v) in metres -> picture pixels.
    double pxOfU(double u) const {
        return mL.plot.x +
               (u - mSlice.bounds[0]) / (mSlice.bounds[2] - mSlice.bounds[0]) * mL.plot.w;
    }
    double pyOfV(double v) const {
        return mL.plot.y +
               (mSlice.bounds[3] - v) / (mSlice.bounds[3] - mSlice.bounds[1]) * mL.plot.h;
    }

    void computeSpeeds();

    void drawTitle();

    void drawRaster();

    double spacing() const;

    // A soft vertical gradient behind geometry drawn without a field slice.
    void drawBackdrop();

    // Cloth triangles and hair segments, far ones first (painter's algorithm); the viewer looks
    // along -(u x v), the light comes from the upper left, in front.
    void drawGeometry();

    void clipToPlot();

    void drawArrows();

    // Evenly spaced streamlines (seeded on a grid, RK2 midpoint steps on the normalised
    // in-plane direction, stopped near other lines), each with an arrowhead at its middle.
    void drawStreamlines();

    void drawAxes();

    void drawColorBar();

    // "arrow = N m/s": a reference arrow for the in-plane speed.
    void drawArrowKey(double x, double y);

    void drawWindicator();

    // The line of the plot where (u,v) . (du,dv) = s, clipped to the plot: false if it misses.
    bool planeLine(double du, double dv, double s, double& x0, double& y0, double& x1,
                   double& y1) const;

    // Each active gust: dashed lines at its front and tail where they cross the slice.
    void drawGustBands();

    void drawTimeline();

    cairo_t* mCr;
    const SliceLayout& mL;
    const Slice& mSlice;
    const SliceOverlays& mOver;
    const RenderSettings& mSet;
    double mS;
    std::vector<double> mSpeed;
    double mMaxSpeed = 0.0, mScaleTop = 1.0;
    double mArrowRef = 0.0, mArrowCell = 0.0;
};

} // namespace gale::viz::cairo_detail
