// What a viz picture shows, as plain data: a slice of a wind field (sampled velocities), the
// rigs over it (windicator arrow, gust fronts, gust timeline), simulated cloth and hair, the
// layout of the parts, and contact sheets of thumbnails. Drawing them is a backend's work
// (cairo_render.h: PNG and SVG); a browser page could draw the same data.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace gale::viz {

enum class ImageFormat { Png, Svg };
// From the extension (.png, .svg, any case); false for anything else.
bool imageFormatFromPath(const std::string& path, ImageFormat& out);

struct PixelRect {
    double x = 0, y = 0, w = 0, h = 0;
};

// Where the parts of a width x height picture go. The plot keeps the slice's aspect ratio
// (equal metres per pixel across and down) and has whole-pixel size plotW x plotH: the slice
// is sampled once per plot pixel.
struct SliceLayout {
    int width = 0, height = 0;
    double scale = 1.0; // text and line size factor (1 for a 1024-pixel picture)
    PixelRect plot;
    int plotW = 0, plotH = 0;
    PixelRect legend;   // colour bar column right of the plot
    PixelRect timeline; // the gust timeline strip (h = 0 when there is none)
};
// False when the picture is too small to hold a plot (under about 200 x 150 pixels).
bool layoutSlice(int width, int height, double boundsW, double boundsH, bool timeline,
                 SliceLayout& out);
// Why layoutSlice refused width x height, for `--size WxH` + this: what the picture holds and the
// smallest size (multiples of 32, keeping width:height, at least 224x160) at which it fits.
std::string sliceTooSmall(int width, int height, double boundsW, double boundsH, bool timeline);

// The sampled slice: the world velocity at the centre of every plot pixel.
struct Slice {
    int nu = 0, nv = 0;                       // samples across and down (= plotW, plotH)
    std::array<double, 4> bounds{};           // u0, v0, u1, v1 in metres (u right, v up)
    int uAxis = 0, vAxis = 1, normalAxis = 2; // world axes (0 x, 1 y, 2 z)
    double planeValue = 0.0;                  // the plane is normalAxis = planeValue
    std::vector<float> velocity;              // 3 per sample (world x,y,z); row 0 is the top (v1),
                                              // u fastest: velocity[3*(row*nu + col) + c]
};

// The windicator rig at the picture's time.
struct WindicatorOverlay {
    bool present = false;
    std::array<double, 3> direction{1.0, 0.0, 0.0}; // unit, world
    double speed = 0.0;                             // m/s
};

// A gust's extent at the picture's time: the band of the slice it covers, as distances
// downwind of the origin plane (along `direction`).
struct GustBand {
    std::string label;
    std::array<double, 3> direction{1.0, 0.0, 0.0}; // unit wind direction
    double front = 0.0;                             // leading edge (m downwind)
    double tail = 0.0;                              // where it has died away
};

// The timeline strip: gust envelopes and the windicator speed over time.
struct TimelineOverlay {
    bool present = false;
    double t0 = 0.0, t1 = 1.0;               // time axis (s)
    double sceneStart = 0.0, sceneEnd = 0.0; // the scene's frame range (s), shaded
    struct Curve {
        std::string label;
        std::vector<std::array<double, 2>> points; // (t, m/s)
    };
    std::vector<Curve> gusts; // strength * envelope at the origin plane
    Curve windicatorSpeed;    // empty points: none
};

// Simulated cloth or hair drawn over the slice (`gale viz --frames`): world positions, triangles
// (cloth: Lambert-shaded with a fixed light, far ones first) and polylines (hair strands),
// projected orthographically onto the plot along the slice's normal.
struct GeometryOverlay {
    std::string label;
    std::vector<std::array<double, 3>> points;
    std::vector<std::array<int, 3>> triangles;
    std::vector<std::vector<int>> polylines;
    // Per-vertex rest-relative strain (viz/strain.h); when present, drawn by strainColour.
    std::vector<double> strain;
    // A collider's surface (a moving body at the frame), drawn grey, not as cloth.
    bool body = false;
};

struct SliceOverlays {
    WindicatorOverlay windicator;
    std::vector<GustBand> gusts;
    TimelineOverlay timeline;
    std::vector<GeometryOverlay> geometry;
};

enum class FlowStyle { Arrows, Streamlines, None };

struct RenderSettings {
    ImageFormat format = ImageFormat::Png;
    std::string title;    // first line (the source)
    std::string subtitle; // second line (plane, time)
    double time = 0.0;    // the picture's time (timeline marker)
    FlowStyle style = FlowStyle::Arrows;
    double speedMax = 0.0;     // top of the colour scale, m/s (0: a round number above the max)
    double arrowSpacing = 0.0; // pixels between arrows / streamlines (0: about 22 across)
    bool fieldRaster = true;   // false: a plain backdrop instead of speed colours (no colour bar)
    bool compact = false;      // a thumbnail: the plot only (no title, axes, legend, rigs)
};

// One thumbnail of a contact sheet: a picture laid out for the cell (layoutThumbnail).
struct ContactCell {
    Slice slice;
    SliceOverlays overlays;
    RenderSettings settings; // compact
};

// A width x height thumbnail layout: the whole cell is plot (keeping the bounds' aspect).
SliceLayout layoutThumbnail(int width, int height, double boundsW, double boundsH);

// A contact sheet: rows of thumbnails (cellW x cellH each) under column headings, each row
// with label lines on its left (a wedge variant's values), written as PNG through a rename.
struct ContactSheet {
    std::string title;
    std::vector<std::string> columnHeadings;         // one per column (e.g. "frame 12")
    std::vector<std::vector<std::string>> rowLabels; // lines per row
    int cellW = 240, cellH = 240;
    int labelW = 220;
    std::vector<std::vector<ContactCell>> rows;      // rows[r][c]
};

} // namespace gale::viz
