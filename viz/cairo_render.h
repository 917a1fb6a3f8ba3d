// The cairo backend of viz pictures: draws a picture's data (picture.h) as PNG or SVG and
// writes it through a temporary file and a rename. Only the viz/cairo_*.cpp files include cairo.
#pragma once

#include "io/pointset.h"
#include "viz/picture.h"

#include <string>

namespace gale::viz {

// Draws the picture and writes it to `path` through a temporary file and a rename.
io::IoError renderSlice(const std::string& path, const SliceLayout& layout, const Slice& slice,
                        const SliceOverlays& overlays, const RenderSettings& settings);

// A contact sheet as PNG, through a rename.
io::IoError renderContactSheet(const std::string& path, const ContactSheet& sheet);

} // namespace gale::viz
