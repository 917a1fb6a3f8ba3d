// Helpers shared by the point-set readers and writers (pointset.cpp, pointset_ply.cpp).
// Internal to gale::io: not part of the public API.
#pragma once

#include "io/pointset.h"

#include <iosfwd>
#include <string>

namespace gale::io::detail {

IoError dataError(const std::string& file, int line, int col, std::string message);
IoError ioError(const std::string& file, std::string message);

// Appends the shortest round-trip decimal of `v` (as a float when `asFloat32`) to `out`:
// the same text formatNumber gives, without a temporary string per value.
void appendNumber(std::string& out, double v, bool asFloat32);

// PLY writer (binary little-endian or ascii); every column becomes a `float` property.
IoError writePly(std::ostream& out, const PointSet& points, bool binary);

} // namespace gale::io::detail
