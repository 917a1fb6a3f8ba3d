// The cairo backend of viz pictures: the plot (speed raster in viridis, arrows or RK2
// streamlines, simulated geometry, axes, colour bar with m/s ticks; the rigs' overlays are in
// cairo_overlays.cpp), PNG via an image surface, SVG via an SVG surface, both written
// atomically, and contact sheets of thumbnails.
#include "viz/cairo_painter.h"
#include "viz/slice_marks.h"
#include "viz/strain.h"

#include "io/atomic_file.h"

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

namespace gale::viz {

namespace cairo_detail {

void Painter::paint() {
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

void Painter::computeSpeeds() {
    SpeedScale scale = speedScale(mSlice, mSet.speedMax);
    mSpeed = std::move(scale.speed);
    mMaxSpeed = scale.max;
    mScaleTop = scale.top;
}

void Painter::drawTitle() {
    setColor(mCr, kInk);
    setFont(mCr, 17 * mS, Weight::Bold);
    text(mCr, 16 * mS, 24 * mS, mSet.title);
    setFont(mCr, 13 * mS);
    setColor(mCr, kMuted);
    text(mCr, 16 * mS, 44 * mS, mSet.subtitle);
}

void Painter::drawRaster() {
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

double Painter::spacing() const {
    return markSpacing(mSet, mL.plot.w, mL.plot.h, mS);
}

void Painter::drawBackdrop() {
    cairo_pattern_t* g = cairo_pattern_create_linear(0, mL.plot.y, 0, mL.plot.y + mL.plot.h);
    cairo_pattern_add_color_stop_rgb(g, 0, 0.93, 0.95, 0.97);
    cairo_pattern_add_color_stop_rgb(g, 1, 0.82, 0.85, 0.89);
    cairo_rectangle(mCr, mL.plot.x, mL.plot.y, mL.plot.w, mL.plot.h);
    cairo_set_source(mCr, g);
    cairo_fill(mCr);
    cairo_pattern_destroy(g);
}

void Painter::drawGeometry() {
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
    const Rgb cloth{0.42, 0.6, 0.86}, hair{0.62, 0.42, 0.2}, bodyGrey{0.72, 0.72, 0.7};
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
            Rgb col = it.g->body ? bodyGrey : cloth;
            const std::vector<double>& strain = it.g->strain;
            if (strain.size() == p.size()) // the triangle's largest-magnitude vertex strain
                col = strainColour(std::max({strain[tri[0]], strain[tri[1]], strain[tri[2]]},
                                            [](double a, double b) { return std::fabs(a) < std::fabs(b); }),
                                   cloth);
            setColor(mCr, {col.r * k, col.g * k, col.b * k});
            if (it.g->body) { // a body: filled, no mesh lines (dense bodies would turn black)
                cairo_fill(mCr);
                continue;
            }
            cairo_fill_preserve(mCr);
            cairo_set_line_width(mCr, 0.6);
            cairo_stroke(mCr);
        } else {
            at(p[it.index], x, y);
            cairo_move_to(mCr, x, y);
            at(p[it.second], x, y);
            cairo_line_to(mCr, x, y);
            Rgb col = hair;
            const std::vector<double>& strain = it.g->strain;
            if (strain.size() == p.size()) {
                const double a = strain[it.index], b = strain[it.second];
                col = strainColour(std::fabs(a) > std::fabs(b) ? a : b, hair);
            }
            setColor(mCr, {col.r * (0.4 + k), col.g * (0.4 + k), col.b * (0.4 + k)});
            cairo_set_line_width(mCr, std::max(1.0, 1.6 * mS));
            cairo_stroke(mCr);
        }
    }
    cairo_restore(mCr);
}

void Painter::clipToPlot() {
    cairo_rectangle(mCr, mL.plot.x, mL.plot.y, mL.plot.w, mL.plot.h);
    cairo_clip(mCr);
}

void Painter::drawArrows() {
    const ArrowGrid grid = sliceArrows(mSlice, mL.plot.w, mL.plot.h, spacing());
    const double ref = grid.reference;
    mArrowRef = ref;
    mArrowCell = grid.cell;
    cairo_save(mCr);
    clipToPlot();
    const double maxLen = 0.9 * mArrowCell;
    for (const ArrowMark& a : grid.arrows) {
        const double ax = mL.plot.x + a.x, ay = mL.plot.y + a.y;
        if (ref <= 0 || a.magnitude < 0.03 * ref) {
            cairo_arc(mCr, ax, ay, 1.6 * mS, 0, 2 * M_PI);
            cairo_set_source_rgba(mCr, 1, 1, 1, 0.8);
            cairo_fill(mCr);
            continue;
        }
        const double len = maxLen * a.magnitude / ref;
        const double ux = a.vx / a.magnitude, uy = a.vy / a.magnitude;
        haloArrow(mCr, ax - 0.5 * len * ux, ay - 0.5 * len * uy, ax + 0.5 * len * ux,
                  ay + 0.5 * len * uy, std::min(9.0 * mS, 0.4 * maxLen), 1.3 * mS);
    }
    cairo_restore(mCr);
}

void Painter::drawStreamlines() {
    const double sep = 0.75 * spacing();
    const std::vector<Polyline> lines =
        sliceStreamlines(mSlice, mL.plot.w, mL.plot.h, mMaxSpeed, sep, std::max(1.0, 1.5 * mS));
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

void Painter::drawAxes() {
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

void Painter::drawColorBar() {
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

} // namespace cairo_detail

namespace {

using namespace cairo_detail;

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

} // namespace gale::viz
