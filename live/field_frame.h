// One update of the live page's field view, as data: the slice (speeds, colour scale), the
// arrows on a grid, the streamlines from the rake and the rigs' overlays at a time, computed
// from a field with the viz library's functions, with the time each stage took.
#pragma once

#include "fields/field.h"
#include "viz/picture.h"
#include "viz/slice_marks.h"
#include "viz/volume_marks.h"

#include <string>
#include <vector>

namespace gale::live {

struct FieldRequest {
    double time = 0.0;
    int axis = 2;            // the slice's normal axis (0 x, 1 y, 2 z)
    double planeValue = 0.0; // the plane is axis = planeValue
    int res = 128;           // slice samples along the longer side (8 to 512)
    int arrows = 16;         // arrows per side of the box (0 for none, up to 32)
    viz::Rake rake;          // streamline seeds (count 0 for none, up to 1024)
    double speedMax = 0.0;   // top of the colour scale (0: a round number above the max)
};

struct StageTimes {
    double slice = 0, arrows = 0, streamlines = 0; // ms
};

struct FieldFrame {
    viz::Slice slice; // velocities of the slice's samples
    viz::SpeedScale speed;
    viz::ArrowVolume arrows;
    std::vector<viz::Streamline> streamlines;
    StageTimes times;
};

// Checks `request` against its limits (false with `error` naming the bad value), then samples.
// False with `error` when the field cannot be sampled or gives non-finite velocities on the
// slice.
bool computeFieldFrame(const fields::Field& field, double fps, const viz::Box3& box,
                       const FieldRequest& request, FieldFrame& out, std::string& error);

} // namespace gale::live
