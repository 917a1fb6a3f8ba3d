// What is drawn of a wind field in 3-D, as plain data: arrows sampled on a grid in a box and
// streamlines integrated from seeds spread along a rake. A browser page (live/) draws them;
// they are computed here so every front end shows the same marks.
#pragma once

#include "fields/field.h"

#include <array>
#include <vector>

namespace gale::viz {

struct Box3 {
    std::array<double, 3> lo{-1.0, -1.0, -1.0}, hi{1.0, 1.0, 1.0};
};

// The velocity at the centres of an n x n x n grid of cells over `box` (x slowest, then y,
// then z): 3 floats per arrow for the position and 3 for the velocity (m/s).
struct ArrowVolume {
    int n = 0;
    std::vector<float> positions, velocities;
    double maxSpeed = 0.0;
};
// `n` from 1 to 64. Non-finite velocities are zeroed and counted in the status.
fields::SampleStatus sampleArrowVolume(const fields::Field& field, const fields::SampleTime& when,
                                       const Box3& box, int n, ArrowVolume& out);

// A straight rake from `a` to `b` holding `count` seeds (the ends included; one seed sits at
// the middle when count is 1).
struct Rake {
    std::array<double, 3> a{0.0, 0.0, 0.0}, b{0.0, 1.0, 0.0};
    int count = 16;
};

// One streamline: points running downstream, with the speed (m/s) at each.
struct Streamline {
    std::vector<std::array<float, 3>> points;
    std::vector<float> speed;
};

struct StreamlineOptions {
    double step = 0.05;     // arc length of one RK2 step (m)
    int maxSteps = 64;      // per direction
    double minSpeed = 1e-6; // m/s: the line stops where the wind is slower
};

// Integrates every seed of the rake upstream and downstream through the normalised velocity
// (RK2, midpoint rule, fixed arc length) until it leaves `box`, stalls or has taken maxSteps
// steps each way; all lines advance together, one batched sample per stage. `count` from 1 to
// 4096.
fields::SampleStatus traceRake(const fields::Field& field, const fields::SampleTime& when,
                               const Rake& rake, const Box3& box, const StreamlineOptions& options,
                               std::vector<Streamline>& out);

} // namespace gale::viz
