// cairo drawing of `gale viz` pictures: speed raster (viridis), colour bar with m/s ticks,
// axes, arrows or RK2 streamlines, windicator inset, gust bands and the gust timeline; PNG
// via an image surface, SVG via an SVG surface, both written atomically.
#include "viz/render.h"

#include "viz/plot_geometry.h"
#include "fields/grid_sample.h"

#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>

namespace gale::cli {

namespace {

// ---- colours ----

const Rgb kInk{0.13, 0.13, 0.15};
const Rgb kMuted{0.42, 0.44, 0.47};
const Rgb kWindicator{0.85, 0.28, 0.06};
const Rgb kGust{0.94, 0.55, 0.0};
const Rgb kGustEdge{0.91, 0.35, 0.05};
const Rgb kNow{0.88, 0.19, 0.19};
const Rgb kSpeedLine{0.11, 0.49, 0.84};

void setColor(cairo_t* cr, const Rgb& c, double alpha = 1.0) {
    cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

// ---- text ----

enum class Weight { Normal, Bold };

void setFont(cairo_t* cr, double size, Weight w = Weight::Normal) {
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           w == Weight::Bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
}

double textWidth(cairo_t* cr, const std::string& s) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    return e.x_advance;
}

// Draws `s` with its baseline at y; align 0 left, 0.5 centre, 1 right of x.
void text(cairo_t* cr, double x, double y, const std::string& s, double align = 0.0) {
    cairo_move_to(cr, x - align * textWidth(cr, s), y);
    cairo_show_text(cr, s.c_str());
}

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

// Speeds: 12.3, 3.14, 0.052, 2.4e-06.
std::string speedText(double v) {
    const double a = std::fabs(v);
    if (a > 0 && a < 0.01) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.2g", v);
        return buf;
    }
    return fixed(v, a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 2 : 3);
}

// ---- shapes ----

void roundedRect(cairo_t* cr, double x, double y, double w, double h, double r) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, x + w - r, y + r, r, -M_PI / 2, 0);
    cairo_arc(cr, x + w - r, y + h - r, r, 0, M_PI / 2);
    cairo_arc(cr, x + r, y + h - r, r, M_PI / 2, M_PI);
    cairo_arc(cr, x + r, y + r, r, M_PI, 3 * M_PI / 2);
    cairo_close_path(cr);
}

// An arrow from (x0,y0) to (x1,y1) with a filled head of length `head`; stroked in the
// current source at `width`.
void arrowPath(cairo_t* cr, double x0, double y0, double x1, double y1, double head) {
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
void haloArrow(cairo_t* cr, double x0, double y0, double x1, double y1, double head, double width) {
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

    void paint() {
        cairo_set_source_rgb(mCr, 1, 1, 1);
        cairo_paint(mCr);
        computeSpeeds();
        if (!mSet.compact) drawTitle();
        if (mSet.fieldRaster && !mSpeed.empty()) {
            drawRaster();
            if (mSet.style == FlowStyle::Arrows) drawArrows();
            if (mSet.style == FlowStyle::Streamlines) drawStreamlines();
        } else {
            drawBackdrop();
        }
        if (!mSet.compact) drawGustBands();
        drawGeometry();
        if (mSet.compact) return;
        drawAxes();
        if (mSet.fieldRaster && !mSpeed.empty()) drawColorBar();
        if (mOver.windicator.present) drawWindicator();
        if (mOver.timeline.present && mL.timeline.h > 0) drawTimeline();
    }

private:
    // In-plane velocity of sample (col,row) in pixel directions (right, down).
    void inPlane(int col, int row, double& px, double& py) const {
        const float* v = mSlice.velocity.data() + 3 * (static_cast<size_t>(row) * mSlice.nu + col);
        px = v[mSlice.uAxis];
        py = -v[mSlice.vAxis];
    }
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

    void computeSpeeds() {
        const size_t n = static_cast<size_t>(mSlice.nu) * static_cast<size_t>(mSlice.nv);
        if (mSlice.velocity.size() < 3 * n) return; // no field sampled: a backdrop instead
        mSpeed.resize(n);
        mMaxSpeed = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const float* v = mSlice.velocity.data() + 3 * i;
            mSpeed[i] = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
            mMaxSpeed = std::max(mMaxSpeed, mSpeed[i]);
        }
        mScaleTop = mSet.speedMax > 0 ? mSet.speedMax : niceCeil(mMaxSpeed > 0 ? mMaxSpeed : 1.0);
    }

    void drawTitle() {
        setColor(mCr, kInk);
        setFont(mCr, 17 * mS, Weight::Bold);
        text(mCr, 16 * mS, 24 * mS, mSet.title);
        setFont(mCr, 13 * mS);
        setColor(mCr, kMuted);
        text(mCr, 16 * mS, 44 * mS, mSet.subtitle);
    }

    void drawRaster() {
        cairo_surface_t* img = cairo_image_surface_create(CAIRO_FORMAT_RGB24, mSlice.nu, mSlice.nv);
        cairo_surface_flush(img);
        unsigned char* data = cairo_image_surface_get_data(img);
        const int stride = cairo_image_surface_get_stride(img);
        for (int row = 0; row < mSlice.nv; ++row) {
            uint32_t* line = reinterpret_cast<uint32_t*>(data + static_cast<size_t>(row) * stride);
            for (int col = 0; col < mSlice.nu; ++col) {
                const Rgb c =
                    viridis(mSpeed[static_cast<size_t>(row) * mSlice.nu + col] / mScaleTop);
                const uint32_t r = static_cast<uint32_t>(std::lround(c.r * 255));
                const uint32_t g = static_cast<uint32_t>(std::lround(c.g * 255));
                const uint32_t b = static_cast<uint32_t>(std::lround(c.b * 255));
                line[col] = 0xff000000u | (r << 16) | (g << 8) | b;
            }
        }
        cairo_surface_mark_dirty(img);
        cairo_save(mCr);
        cairo_translate(mCr, mL.plot.x, mL.plot.y);
        cairo_scale(mCr, mL.plot.w / mSlice.nu, mL.plot.h / mSlice.nv);
        cairo_set_source_surface(mCr, img, 0, 0);
        cairo_pattern_set_filter(cairo_get_source(mCr), mSet.format == ImageFormat::Png
                                                            ? CAIRO_FILTER_NEAREST
                                                            : CAIRO_FILTER_GOOD);
        cairo_rectangle(mCr, 0, 0, mSlice.nu, mSlice.nv);
        cairo_fill(mCr);
        cairo_restore(mCr);
        cairo_surface_destroy(img);
    }

    double spacing() const {
        if (mSet.arrowSpacing > 0) return mSet.arrowSpacing;
        return std::max(26.0 * mS, std::max(mL.plot.w, mL.plot.h) / 22.0);
    }

    // A soft vertical gradient behind geometry drawn without a field slice.
    void drawBackdrop() {
        cairo_pattern_t* g = cairo_pattern_create_linear(0, mL.plot.y, 0, mL.plot.y + mL.plot.h);
        cairo_pattern_add_color_stop_rgb(g, 0, 0.93, 0.95, 0.97);
        cairo_pattern_add_color_stop_rgb(g, 1, 0.82, 0.85, 0.89);
        cairo_rectangle(mCr, mL.plot.x, mL.plot.y, mL.plot.w, mL.plot.h);
        cairo_set_source(mCr, g);
        cairo_fill(mCr);
        cairo_pattern_destroy(g);
    }

    // Cloth triangles and hair segments, far ones first (painter's algorithm); the viewer looks
    // along -(u x v), the light comes from the upper left, in front.
    void drawGeometry() {
        if (mOver.geometry.empty()) return;
        const int u = mSlice.uAxis, v = mSlice.vAxis, n = mSlice.normalAxis;
        const double towardsViewer = (u + 1) % 3 == v ? 1.0 : -1.0;
        double light[3] = {0, 0, 0};
        light[u] = -0.45;
        light[v] = 0.6;
        light[n] = 0.66 * towardsViewer;
        const double ll = std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
        for (double& c : light) c /= ll;
        struct Item {
            double depth;
            const GeometryOverlay* g;
            int index;  // triangle, or first point of a segment
            int second; // -1 for a triangle
            double shade;
        };
        std::vector<Item> items;
        for (const GeometryOverlay& g : mOver.geometry) {
            const auto& p = g.points;
            const int count = static_cast<int>(p.size());
            for (size_t t = 0; t < g.triangles.size(); ++t) {
                const auto& tri = g.triangles[t];
                if (tri[0] < 0 || tri[1] < 0 || tri[2] < 0 || tri[0] >= count || tri[1] >= count || tri[2] >= count)
                    continue;
                const auto &a = p[tri[0]], &b = p[tri[1]], &c = p[tri[2]];
                const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
                const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
                const double nn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                      e1[0] * e2[1] - e1[1] * e2[0]};
                const double len = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
                if (!(len > 0)) continue;
                const double shade = std::fabs(nn[0] * light[0] + nn[1] * light[1] + nn[2] * light[2]) / len;
                items.push_back({towardsViewer * (a[n] + b[n] + c[n]) / 3, &g, static_cast<int>(t), -1, shade});
            }
            for (const std::vector<int>& line : g.polylines)
                for (size_t k = 0; k + 1 < line.size(); ++k) {
                    const int i = line[k], j = line[k + 1];
                    if (i < 0 || j < 0 || i >= count || j >= count) continue;
                    double d[3] = {p[j][0] - p[i][0], p[j][1] - p[i][1], p[j][2] - p[i][2]};
                    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    const double tl = len > 0 ? (d[0] * light[0] + d[1] * light[1] + d[2] * light[2]) / len : 0;
                    items.push_back({towardsViewer * (p[i][n] + p[j][n]) / 2, &g, i, j,
                                     std::sqrt(std::max(0.0, 1 - tl * tl))});
                }
        }
        std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.depth < b.depth; });
        cairo_save(mCr);
        clipToPlot();
        cairo_set_line_join(mCr, CAIRO_LINE_JOIN_ROUND);
        cairo_set_line_cap(mCr, CAIRO_LINE_CAP_ROUND);
        const Rgb cloth{0.42, 0.6, 0.86}, hair{0.62, 0.42, 0.2};
        auto at = [&](const std::array<double, 3>& q, double& x, double& y) {
            x = pxOfU(q[u]);
            y = pyOfV(q[v]);
        };
        for (const Item& it : items) {
            const auto& p = it.g->points;
            const double k = 0.28 + 0.72 * it.shade;
            double x = 0, y = 0;
            if (it.second < 0) {
                const auto& tri = it.g->triangles[static_cast<size_t>(it.index)];
                for (int c = 0; c < 3; ++c) {
                    at(p[tri[c]], x, y);
                    c == 0 ? cairo_move_to(mCr, x, y) : cairo_line_to(mCr, x, y);
                }
                cairo_close_path(mCr);
                setColor(mCr, {cloth.r * k, cloth.g * k, cloth.b * k});
                cairo_fill_preserve(mCr);
                cairo_set_line_width(mCr, 0.6);
                cairo_stroke(mCr);
            } else {
                at(p[it.index], x, y);
                cairo_move_to(mCr, x, y);
                at(p[it.second], x, y);
                cairo_line_to(mCr, x, y);
                setColor(mCr, {hair.r * (0.4 + k), hair.g * (0.4 + k), hair.b * (0.4 + k)});
                cairo_set_line_width(mCr, std::max(1.0, 1.6 * mS));
                cairo_stroke(mCr);
            }
        }
        cairo_restore(mCr);
    }

    void clipToPlot() {
        cairo_rectangle(mCr, mL.plot.x, mL.plot.y, mL.plot.w, mL.plot.h);
        cairo_clip(mCr);
    }

    void drawArrows() {
        const double sp = spacing();
        const int na = std::max(1, static_cast<int>(std::lround(mL.plot.w / sp)));
        const int nb = std::max(1, static_cast<int>(std::lround(mL.plot.h / sp)));
        const double cw = mL.plot.w / na, ch = mL.plot.h / nb;
        struct A {
            double x, y, vx, vy, m;
        };
        std::vector<A> arrows;
        double ref = 0.0;
        for (int b = 0; b < nb; ++b)
            for (int a = 0; a < na; ++a) {
                const double cx = (a + 0.5) * cw, cy = (b + 0.5) * ch;
                const int col =
                    std::min(mSlice.nu - 1, static_cast<int>(cx * mSlice.nu / mL.plot.w));
                const int row =
                    std::min(mSlice.nv - 1, static_cast<int>(cy * mSlice.nv / mL.plot.h));
                double vx, vy;
                inPlane(col, row, vx, vy);
                const double m = std::hypot(vx, vy);
                ref = std::max(ref, m);
                arrows.push_back({mL.plot.x + cx, mL.plot.y + cy, vx, vy, m});
            }
        mArrowRef = ref;
        mArrowCell = std::min(cw, ch);
        cairo_save(mCr);
        clipToPlot();
        const double maxLen = 0.9 * mArrowCell;
        for (const A& a : arrows) {
            if (ref <= 0 || a.m < 0.03 * ref) {
                cairo_arc(mCr, a.x, a.y, 1.6 * mS, 0, 2 * M_PI);
                cairo_set_source_rgba(mCr, 1, 1, 1, 0.8);
                cairo_fill(mCr);
                continue;
            }
            const double len = maxLen * a.m / ref;
            const double ux = a.vx / a.m, uy = a.vy / a.m;
            haloArrow(mCr, a.x - 0.5 * len * ux, a.y - 0.5 * len * uy, a.x + 0.5 * len * ux,
                      a.y + 0.5 * len * uy, std::min(9.0 * mS, 0.4 * maxLen), 1.3 * mS);
        }
        cairo_restore(mCr);
    }

    // Bilinear in-plane direction at plot-relative pixel position (x, y); false outside the
    // plot or where the flow stalls.
    bool direction(double x, double y, double& dx, double& dy) const {
        if (x < 0 || y < 0 || x > mL.plot.w || y > mL.plot.h) return false;
        const double fx = std::clamp(x * mSlice.nu / mL.plot.w - 0.5, 0.0, mSlice.nu - 1.0);
        const double fy = std::clamp(y * mSlice.nv / mL.plot.h - 0.5, 0.0, mSlice.nv - 1.0);
        const int c0 = std::min(static_cast<int>(fx), mSlice.nu - 1);
        const int r0 = std::min(static_cast<int>(fy), mSlice.nv - 1);
        const int c1 = std::min(c0 + 1, mSlice.nu - 1), r1 = std::min(r0 + 1, mSlice.nv - 1);
        const double tx = fx - c0, ty = fy - r0;
        double a[2], b[2], c[2], d[2];
        inPlane(c0, r0, a[0], a[1]);
        inPlane(c1, r0, b[0], b[1]);
        inPlane(c0, r1, c[0], c[1]);
        inPlane(c1, r1, d[0], d[1]);
        dx = (1 - ty) * ((1 - tx) * a[0] + tx * b[0]) + ty * ((1 - tx) * c[0] + tx * d[0]);
        dy = (1 - ty) * ((1 - tx) * a[1] + tx * b[1]) + ty * ((1 - tx) * c[1] + tx * d[1]);
        const double m = std::hypot(dx, dy);
        if (!(m > 1e-6 * std::max(mMaxSpeed, 1e-12))) return false;
        dx /= m;
        dy /= m;
        return true;
    }

    // Evenly spaced streamlines (seeded on a grid, RK2 midpoint steps on the normalised
    // in-plane direction, stopped near other lines), each with an arrowhead at its middle.
    void drawStreamlines() {
        const double sep = 0.75 * spacing();
        const std::vector<Polyline> lines = traceStreamlines(
            [this](double x, double y, double& dx, double& dy) { return direction(x, y, dx, dy); },
            mL.plot.w, mL.plot.h, sep, std::max(1.0, 1.5 * mS));
        cairo_save(mCr);
        clipToPlot();
        cairo_translate(mCr, mL.plot.x, mL.plot.y);
        cairo_set_line_join(mCr, CAIRO_LINE_JOIN_ROUND);
        cairo_set_line_cap(mCr, CAIRO_LINE_CAP_ROUND);
        // The arrowhead at a line's middle, pointing downstream (a closed triangle path).
        auto head = [&](const Polyline& line) {
            const size_t m = line.size() / 2, m2 = std::min(line.size() - 1, m + 2);
            const double dx = line[m2][0] - line[m][0], dy = line[m2][1] - line[m][1];
            const double len = std::hypot(dx, dy);
            if (!(len > 0)) return;
            const double ux = dx / len, uy = dy / len, hd = 7.0 * mS;
            const double tx = line[m][0] + ux * hd * 0.5, ty = line[m][1] + uy * hd * 0.5;
            cairo_move_to(mCr, tx, ty);
            cairo_line_to(mCr, tx - ux * hd - uy * hd * 0.45, ty - uy * hd + ux * hd * 0.45);
            cairo_line_to(mCr, tx - ux * hd + uy * hd * 0.45, ty - uy * hd - ux * hd * 0.45);
            cairo_close_path(mCr);
        };
        auto polyline = [&](const Polyline& line) {
            cairo_move_to(mCr, line[0][0], line[0][1]);
            for (size_t i = 1; i < line.size(); ++i) cairo_line_to(mCr, line[i][0], line[i][1]);
        };
        // First every white halo, then every dark line, so crossings stay clean.
        cairo_set_source_rgba(mCr, 1, 1, 1, 0.7);
        cairo_set_line_width(mCr, 3.2 * mS);
        for (const auto& line : lines) {
            polyline(line);
            head(line);
            cairo_stroke(mCr);
        }
        setColor(mCr, kInk, 0.9);
        cairo_set_line_width(mCr, 1.1 * mS);
        for (const auto& line : lines) {
            polyline(line);
            cairo_stroke(mCr);
            head(line);
            cairo_stroke_preserve(mCr);
            cairo_fill(mCr);
        }
        cairo_restore(mCr);
    }

    void drawAxes() {
        const char* names = "xyz";
        setColor(mCr, kInk);
        cairo_set_line_width(mCr, 1.0);
        cairo_rectangle(mCr, mL.plot.x - 0.5, mL.plot.y - 0.5, mL.plot.w + 1, mL.plot.h + 1);
        cairo_stroke(mCr);
        setFont(mCr, 12 * mS);
        const double tick = 5 * mS;
        double step;
        const int countU = std::max(2, static_cast<int>(mL.plot.w / (90 * mS)));
        for (double u : ticks(mSlice.bounds[0], mSlice.bounds[2], countU, step)) {
            const double x = std::round(pxOfU(u)) + 0.5;
            cairo_move_to(mCr, x, mL.plot.y + mL.plot.h);
            cairo_line_to(mCr, x, mL.plot.y + mL.plot.h + tick);
            cairo_stroke(mCr);
            text(mCr, x, mL.plot.y + mL.plot.h + tick + 14 * mS, tickLabel(u, step), 0.5);
        }
        const int countV = std::max(2, static_cast<int>(mL.plot.h / (70 * mS)));
        double widest = 0.0;
        for (double v : ticks(mSlice.bounds[1], mSlice.bounds[3], countV, step)) {
            const double y = std::round(pyOfV(v)) + 0.5;
            cairo_move_to(mCr, mL.plot.x - tick, y);
            cairo_line_to(mCr, mL.plot.x, y);
            cairo_stroke(mCr);
            const std::string label = tickLabel(v, step);
            widest = std::max(widest, textWidth(mCr, label));
            text(mCr, mL.plot.x - tick - 3 * mS, y + 4 * mS, label, 1.0);
        }
        setFont(mCr, 13 * mS);
        text(mCr, mL.plot.x + mL.plot.w / 2, mL.plot.y + mL.plot.h + tick + 34 * mS,
             std::string(1, names[mSlice.uAxis]) + " (m)", 0.5);
        cairo_save(mCr);
        // Left of the widest tick label, but inside the picture.
        const double axisX = std::max(16 * mS, mL.plot.x - tick - widest - 14 * mS);
        cairo_translate(mCr, axisX, mL.plot.y + mL.plot.h / 2);
        cairo_rotate(mCr, -M_PI / 2);
        text(mCr, 0, 0, std::string(1, names[mSlice.vAxis]) + " (m)", 0.5);
        cairo_restore(mCr);
    }

    void drawColorBar() {
        const PixelRect& g = mL.legend;
        const double x = g.x + 6 * mS, w = 18 * mS;
        const double top = mL.plot.y + 44 * mS;
        const double keyRoom = mSet.style == FlowStyle::Arrows ? 96 * mS : 30 * mS;
        // Beside the plot; a wide, short plot still gets a readable bar (the column below the
        // plot's right edge is free).
        const double bottom =
            std::max(mL.plot.y + mL.plot.h - keyRoom,
                     std::min(top + 260 * mS, static_cast<double>(mL.height) - keyRoom - 24 * mS));
        setColor(mCr, kInk);
        setFont(mCr, 13 * mS, Weight::Bold);
        text(mCr, x, mL.plot.y + 14 * mS, "speed |v|");
        setFont(mCr, 12 * mS);
        setColor(mCr, kMuted);
        text(mCr, x, mL.plot.y + 31 * mS, "m/s");
        // The bar: a vertical gradient of many stops, low speeds at the bottom.
        cairo_pattern_t* grad = cairo_pattern_create_linear(0, bottom, 0, top);
        for (int i = 0; i <= 64; ++i) {
            const Rgb c = viridis(i / 64.0);
            cairo_pattern_add_color_stop_rgb(grad, i / 64.0, c.r, c.g, c.b);
        }
        cairo_rectangle(mCr, x, top, w, bottom - top);
        cairo_set_source(mCr, grad);
        cairo_fill(mCr);
        cairo_pattern_destroy(grad);
        setColor(mCr, kInk);
        cairo_set_line_width(mCr, 1.0);
        cairo_rectangle(mCr, x - 0.5, top - 0.5, w + 1, bottom - top + 1);
        cairo_stroke(mCr);
        double step;
        setFont(mCr, 12 * mS);
        const int count = std::clamp(static_cast<int>((bottom - top) / (70 * mS)), 2, 8);
        for (double s : ticks(0.0, mScaleTop, count, step)) {
            const double y = std::round(bottom - s / mScaleTop * (bottom - top)) + 0.5;
            cairo_move_to(mCr, x + w, y);
            cairo_line_to(mCr, x + w + 4 * mS, y);
            cairo_stroke(mCr);
            text(mCr, x + w + 7 * mS, y + 4 * mS, tickLabel(s, step));
        }
        // The slice's maximum: a marker beside the bar.
        const double my = bottom - std::min(mMaxSpeed / mScaleTop, 1.0) * (bottom - top);
        cairo_move_to(mCr, x - 1, my);
        cairo_line_to(mCr, x - 8 * mS, my - 5 * mS);
        cairo_line_to(mCr, x - 8 * mS, my + 5 * mS);
        cairo_close_path(mCr);
        setColor(mCr, kNow);
        cairo_fill(mCr);
        setFont(mCr, 11 * mS);
        setColor(mCr, kMuted);
        text(mCr, x, bottom + 16 * mS,
             "max " + speedText(mMaxSpeed) + (mMaxSpeed > mScaleTop ? " (clipped)" : ""));
        if (mSet.style == FlowStyle::Arrows && mArrowRef > 0) drawArrowKey(x, bottom + 34 * mS);
    }

    // "arrow = N m/s": a reference arrow for the in-plane speed.
    void drawArrowKey(double x, double y) {
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

    void drawWindicator() {
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

    // The line of the plot where (u,v) . (du,dv) = s, clipped to the plot: false if it misses.
    bool planeLine(double du, double dv, double s, double& x0, double& y0, double& x1,
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

    // Each active gust: dashed lines at its front and tail where they cross the slice.
    void drawGustBands() {
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

    void drawTimeline() {
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

// cairo's stream callbacks over a FILE*, so that errors carry errno.
struct FileSink {
    std::FILE* f = nullptr;
    int err = 0;
};

cairo_status_t writeToFile(void* closure, const unsigned char* data, unsigned int length) {
    FileSink* sink = static_cast<FileSink*>(closure);
    if (std::fwrite(data, 1, length, sink->f) != length) {
        sink->err = errno ? errno : EIO;
        return CAIRO_STATUS_WRITE_ERROR;
    }
    return CAIRO_STATUS_SUCCESS;
}

io::IoError cairoError(const std::string& path, cairo_status_t status, int err) {
    io::IoError e;
    e.kind = io::IoError::Io;
    e.file = path;
    e.message =
        "cannot write: " + std::string(err ? std::strerror(err) : cairo_status_to_string(status));
    return e;
}

} // namespace

bool imageFormatFromPath(const std::string& path, ImageFormat& out) {
    if (path.size() < 4) return false;
    std::string ext = path.substr(path.size() - 4);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".png")
        out = ImageFormat::Png;
    else if (ext == ".svg")
        out = ImageFormat::Svg;
    else
        return false;
    return true;
}

bool layoutSlice(int width, int height, double boundsW, double boundsH, bool timeline,
                 SliceLayout& out) {
    SliceLayout l;
    l.width = width;
    l.height = height;
    // Text grows more slowly than the picture: readable at 640 pixels, not huge at 4096.
    l.scale = std::clamp(std::sqrt(std::min(width, height) / 1024.0), 0.8, 2.5);
    const double s = l.scale;
    const double left = std::round(76 * s), right = std::round(150 * s);
    const double top = std::round(64 * s), bottom = std::round(56 * s);
    const double strip = timeline ? std::round(150 * s) : 0.0;
    const double availW = width - left - right, availH = height - top - bottom - strip;
    if (availW < 80 || availH < 60 || !(boundsW > 0) || !(boundsH > 0)) return false;
    const double aspect = boundsW / boundsH;
    double w = availW, h = availW / aspect;
    if (h > availH) {
        h = availH;
        w = availH * aspect;
    }
    l.plotW = std::max(1, static_cast<int>(std::floor(w)));
    l.plotH = std::max(1, static_cast<int>(std::floor(h)));
    // Centred across, right under the title (a wide slice leaves room below, not above).
    l.plot = {left + std::floor((availW - l.plotW) / 2), top, static_cast<double>(l.plotW),
              static_cast<double>(l.plotH)};
    l.legend = {l.plot.x + l.plot.w + 16 * s, l.plot.y, right - 16 * s, l.plot.h};
    // The timeline right under the plot's axis labels.
    if (timeline) l.timeline = {left, l.plot.y + l.plot.h + bottom + 8 * s, availW, strip - 12 * s};
    out = l;
    return true;
}

io::IoError renderSlice(const std::string& path, const SliceLayout& layout, const Slice& slice,
                        const SliceOverlays& overlays, const RenderSettings& settings) {
    auto draw = [&](cairo_surface_t* surface) {
        cairo_t* cr = cairo_create(surface);
        Painter(cr, layout, slice, overlays, settings).paint();
        const cairo_status_t status = cairo_status(cr);
        cairo_destroy(cr);
        return status;
    };
    std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> image(nullptr,
                                                                       cairo_surface_destroy);
    if (settings.format == ImageFormat::Png) {
        image.reset(cairo_image_surface_create(CAIRO_FORMAT_RGB24, layout.width, layout.height));
        const cairo_status_t status = draw(image.get());
        if (status != CAIRO_STATUS_SUCCESS) {
            io::IoError e;
            e.kind = io::IoError::Data;
            e.file = path;
            e.message = std::string("cannot draw the picture: ") + cairo_status_to_string(status);
            return e;
        }
    }
    return io::writeFileAtomic(path, [&](const std::string& tmp) -> io::IoError {
        FileSink sink;
        errno = 0;
        sink.f = std::fopen(tmp.c_str(), "wb");
        if (!sink.f) return cairoError(path, CAIRO_STATUS_WRITE_ERROR, errno);
        cairo_status_t status;
        if (settings.format == ImageFormat::Png) {
            status = cairo_surface_write_to_png_stream(image.get(), writeToFile, &sink);
        } else {
            cairo_surface_t* svg = cairo_svg_surface_create_for_stream(writeToFile, &sink,
                                                                       layout.width, layout.height);
            cairo_svg_surface_set_document_unit(svg,
                                                CAIRO_SVG_UNIT_PX); // not pt: the size asked for
            status = draw(svg);
            cairo_surface_finish(svg);
            if (status == CAIRO_STATUS_SUCCESS) status = cairo_surface_status(svg);
            cairo_surface_destroy(svg);
        }
        const bool closed = std::fclose(sink.f) == 0;
        if (!closed && !sink.err) sink.err = errno;
        if (status != CAIRO_STATUS_SUCCESS || !closed) return cairoError(path, status, sink.err);
        return {};
    });
}

SliceLayout layoutThumbnail(int width, int height, double boundsW, double boundsH) {
    SliceLayout l;
    l.width = width;
    l.height = height;
    l.scale = 0.6;
    const double aspect = boundsW > 0 && boundsH > 0 ? boundsW / boundsH : 1.0;
    double w = width, h = width / aspect;
    if (h > height) {
        h = height;
        w = height * aspect;
    }
    l.plotW = std::max(1, static_cast<int>(std::floor(w)));
    l.plotH = std::max(1, static_cast<int>(std::floor(h)));
    l.plot = {std::floor((width - l.plotW) / 2.0), std::floor((height - l.plotH) / 2.0),
              static_cast<double>(l.plotW), static_cast<double>(l.plotH)};
    return l;
}

io::IoError renderContactSheet(const std::string& path, const ContactSheet& sheet) {
    const int gap = 8, top = 64, head = 22;
    const int cols = static_cast<int>(sheet.columnHeadings.size());
    const int rows = static_cast<int>(sheet.rows.size());
    const int width = sheet.labelW + cols * (sheet.cellW + gap) + gap;
    const int height = top + head + rows * (sheet.cellH + gap) + gap;
    std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> image(
        cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), cairo_surface_destroy);
    cairo_t* cr = cairo_create(image.get());
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    setColor(cr, kInk);
    setFont(cr, 17, Weight::Bold);
    text(cr, 16, 28, sheet.title);
    setFont(cr, 13, Weight::Bold);
    for (int c = 0; c < cols; ++c)
        text(cr, sheet.labelW + c * (sheet.cellW + gap) + sheet.cellW / 2.0, top + head - 6,
             sheet.columnHeadings[static_cast<size_t>(c)], 0.5);
    for (int r = 0; r < rows; ++r) {
        const double y0 = top + head + r * (sheet.cellH + gap);
        const auto& labels = r < static_cast<int>(sheet.rowLabels.size()) ? sheet.rowLabels[static_cast<size_t>(r)]
                                                                          : std::vector<std::string>{};
        for (size_t k = 0; k < labels.size(); ++k) {
            setFont(cr, 13, k == 0 ? Weight::Bold : Weight::Normal);
            setColor(cr, k == 0 ? kInk : kMuted);
            text(cr, 16, y0 + 20 + 18 * static_cast<double>(k), labels[k]);
        }
        const auto& cells = sheet.rows[static_cast<size_t>(r)];
        for (int c = 0; c < cols && c < static_cast<int>(cells.size()); ++c) {
            const ContactCell& cell = cells[static_cast<size_t>(c)];
            const double x0 = sheet.labelW + c * (sheet.cellW + gap);
            cairo_save(cr);
            cairo_translate(cr, x0, y0);
            cairo_rectangle(cr, 0, 0, sheet.cellW, sheet.cellH);
            cairo_clip(cr);
            const SliceLayout layout = layoutThumbnail(sheet.cellW, sheet.cellH, cell.slice.bounds[2] - cell.slice.bounds[0],
                                                       cell.slice.bounds[3] - cell.slice.bounds[1]);
            Painter(cr, layout, cell.slice, cell.overlays, cell.settings).paint();
            cairo_restore(cr);
            cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, sheet.cellW - 1, sheet.cellH - 1);
            setColor(cr, kMuted, 0.5);
            cairo_set_line_width(cr, 1);
            cairo_stroke(cr);
        }
    }
    const cairo_status_t status = cairo_status(cr);
    cairo_destroy(cr);
    if (status != CAIRO_STATUS_SUCCESS) {
        io::IoError e;
        e.kind = io::IoError::Data;
        e.file = path;
        e.message = std::string("cannot draw the contact sheet: ") + cairo_status_to_string(status);
        return e;
    }
    return io::writeFileAtomic(path, [&](const std::string& tmp) -> io::IoError {
        FileSink sink;
        errno = 0;
        sink.f = std::fopen(tmp.c_str(), "wb");
        if (!sink.f) return cairoError(path, CAIRO_STATUS_WRITE_ERROR, errno);
        const cairo_status_t st = cairo_surface_write_to_png_stream(image.get(), writeToFile, &sink);
        const bool closed = std::fclose(sink.f) == 0;
        if (!closed && !sink.err) sink.err = errno;
        if (st != CAIRO_STATUS_SUCCESS || !closed) return cairoError(path, st, sink.err);
        return {};
    });
}

} // namespace gale::cli
