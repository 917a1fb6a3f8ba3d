// Cloth and hair strain as a picture shows it: each vertex's largest rest-relative stretch or
// compression over its edges (len / rest − 1, signed; the one of larger magnitude), and the
// diverging colour map it is drawn with (the same in `gale viz --sim` and on the live page).
#pragma once

#include "viz/picture.h"
#include "viz/plot_geometry.h"

#include <vector>

namespace gale::viz {

// The strain at which the map reaches its ends (±25 %).
constexpr double kStrainTop = 0.25;

// Per-vertex strain of `frame` against `rest` (the same topology: triangles' edges, or the
// polylines' segments): over the edges at a vertex, the strain l/l₀ − 1 of largest magnitude
// (0 where a vertex has no edge or a rest length is 0). Empty when the point counts differ.
std::vector<double> vertexStrain(const GeometryOverlay& rest, const GeometryOverlay& frame);

// The strain colour: `base` (the material's own colour) at 0, towards yellow then red as it
// stretches to +top, towards teal as it compresses to −top; clamped beyond.
Rgb strainColour(double strain, Rgb base, double top = kStrainTop);

} // namespace gale::viz
