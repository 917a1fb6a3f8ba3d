// Where the parts of a viz picture go (plot, colour bar, timeline; thumbnails) and the picture
// formats by file name: plain geometry, no drawing library.
#include "viz/picture.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace gale::viz {

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

std::string sliceTooSmall(int width, int height, double boundsW, double boundsH, bool timeline) {
    const double ratio = width > 0 && height > 0 ? static_cast<double>(height) / width : 1.0;
    std::string fits = "larger";
    SliceLayout l;
    for (int w = 224; w <= 16384; w += 32) {
        const int h = std::max(160, static_cast<int>(std::ceil(w * ratio / 32.0)) * 32);
        if (layoutSlice(w, h, boundsW, boundsH, timeline, l)) {
            fits = std::to_string(w) + "x" + std::to_string(h);
            break;
        }
    }
    return std::string("is too small for a picture of these bounds with its axes") +
           (timeline ? ", legend and gust timeline" : " and legend") + ": give --size " + fits +
           " or larger";
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

} // namespace gale::viz
