// The drawing-library-free parts of viz pictures: the viridis colour map, round tick
// values and their labels, and evenly spaced streamlines traced through a direction field.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace gale::viz {

struct Rgb {
    double r, g, b;
};

// matplotlib's viridis at s in [0, 1] (clamped; NaN is 0), components in [0, 1].
Rgb viridis(double s);

// A 1-2-5 step giving about `count` ticks over `range` (1 for an empty range).
double niceStep(double range, int count);
// The smallest "round" value (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 x 10^k) >= v (1 for v <= 0).
double niceCeil(double v);
// Multiples of niceStep(hi - lo, count) within [lo, hi]; the step is returned in `step`.
std::vector<double> ticks(double lo, double hi, int count, double& step);
// `v` with as many decimals as `step` needs ("-0" printed as "0"): 0.5 step -> "1.5"; for
// steps under 1e-4 or values from 1e6 up, %g with the digits the step needs ("2.5e-07").
std::string tickLabel(double v, double step);

using Polyline = std::vector<std::array<double, 2>>;
// The unit direction of the flow at (x, y) in a width x height box; false where there is
// none (outside the box, or the flow stalls there).
using DirectionFn = std::function<bool(double x, double y, double& dx, double& dy)>;

// Evenly spaced streamlines over [0,width] x [0,height]: seeds on a grid `separation` apart,
// each traced both ways with RK2 (midpoint) steps of length `step` until it leaves the box,
// stalls, comes within separation/2 of another line, or closes on itself. Lines shorter
// than 1.5 separations are dropped. Points run downstream.
std::vector<Polyline> traceStreamlines(const DirectionFn& direction, double width, double height,
                                       double separation, double step);

} // namespace gale::viz
