// Sampling a Field on a regular, cell-centred grid (io/grid.h) or at arbitrary points:
// batched, multi-threaded sampling into float32 (grids) or double (points) buffers.
#pragma once

#include "fields/field.h"
#include "io/grid.h"

#include <cstddef>
#include <functional>
#include <vector>

namespace gale::fields {

struct GridSampleOptions {
    int threads = 0;     // 0: all hardware threads
    size_t batch = 4096; // points per Field::sample call
    // Called now and then from the calling thread with (cells done, total); may be empty.
    std::function<void(size_t, size_t)> progress;
};

// Samples `field` at `count` arbitrary points (positions[3*i+k]) into velocities[3*i+k],
// in batches on several threads (each batch's Field::sample gets threads = 1). The merged
// status counts every non-finite velocity (they are zero in the output).
SampleStatus samplePoints(const Field& field, const double* positions, size_t count,
                          const SampleTime& when, double* velocities,
                          const GridSampleOptions& options = {});

// Samples `field` at every cell centre of `grid` into `out` (float32, resized to
// 3 * cellCount, x slowest: out[3*grid.index(i,j,k) + c]). Velocities that are not finite
// in double, or that overflow float32, are zero in `out` and counted in `nonFinite`.
SampleStatus sampleGrid(const Field& field, const io::GridSpec& grid, const SampleTime& when,
                        std::vector<float>& out, const GridSampleOptions& options = {});

} // namespace gale::fields
