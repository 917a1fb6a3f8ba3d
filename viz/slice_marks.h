// What is drawn on a sampled slice, as plain data: the speed of every sample and the colour
// scale's top, the sub-sampled arrows and the evenly spaced streamlines, in the plot's pixels
// (x right, y down from the plot's top-left corner). Backends draw these; none computes them.
#pragma once

#include "fields/field.h"
#include "viz/picture.h"
#include "viz/plot_geometry.h"

#include <vector>

namespace gale::viz {

// The plane's axes as drawn (u right, v up): z=C shows x,y; y=C shows x,z; x=C shows z,y.
void planeAxes(int normal, int& uAxis, int& vAxis);

// The (u, v) extent of every geometry's finite points, padded by 15 % of the larger side (at
// least 5 cm): u0, v0, u1, v1. False when there is no finite point.
bool geometryBounds(const std::vector<const GeometryOverlay*>& all, int uAxis, int vAxis,
                    std::array<double, 4>& bounds);

// The world velocity at the centre of every sample of `slice` (nu, nv, bounds, axes and plane
// set): positions as slice.velocity's layout, sampled through fields::samplePoints. On a
// non-finite velocity the status counts it and `slice.velocity` is left empty.
fields::SampleStatus sampleSlice(const fields::Field& field, const fields::SampleTime& when,
                                 viz::Slice& slice);

// |v| of every sample (full 3-D speed), the largest, and the top of the colour scale: `speedMax`
// when positive, else a round number at or above the largest (niceCeil). Empty `speed` when the
// slice holds no velocities (a backdrop is drawn instead).
struct SpeedScale {
    std::vector<double> speed; // row-major as Slice::velocity
    double max = 0.0;
    double top = 1.0;
};
SpeedScale speedScale(const Slice& slice, double speedMax);

// The pixels between arrows or streamlines: `arrowSpacing` when positive, else about 22
// across the plot's longer side (never under 26 px at scale 1).
double markSpacing(const RenderSettings& settings, double plotW, double plotH, double scale);

// One arrow at the centre of a grid cell: its in-plane velocity in pixel directions (right,
// down) and its length |(vx, vy)| in m/s.
struct ArrowMark {
    double x = 0.0, y = 0.0; // plot pixels
    double vx = 0.0, vy = 0.0, magnitude = 0.0;
};
struct ArrowGrid {
    std::vector<ArrowMark> arrows;
    double reference = 0.0; // the largest magnitude: drawn 0.9 cells long
    double cell = 0.0;      // the smaller side of a grid cell (px)
};
// Arrows on a grid `spacing` pixels apart over a plotW x plotH plot, each taking the sample
// under its centre.
ArrowGrid sliceArrows(const Slice& slice, double plotW, double plotH, double spacing);

// The bilinear in-plane unit direction at plot pixel (x, y) of a plotW x plotH plot; false
// outside the plot or where the in-plane speed is under 1e-6 of `maxSpeed`.
bool sliceDirection(const Slice& slice, double plotW, double plotH, double maxSpeed, double x,
                    double y, double& dx, double& dy);

// Evenly spaced streamlines of the in-plane flow (traceStreamlines over sliceDirection),
// `separation` pixels apart with RK2 steps of `step` pixels.
std::vector<Polyline> sliceStreamlines(const Slice& slice, double plotW, double plotH,
                                       double maxSpeed, double separation, double step);

} // namespace gale::viz
