// Batched, multi-threaded sampling of a Field at points and on cell-centred grids.
#include "fields/grid_sample.h"

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace gale::fields {

namespace {

// Folds the status of one batch into the total.
void mergeStatus(SampleStatus& total, const SampleStatus& s) {
    total.nonFinite += s.nonFinite;
    if (!s.ok && total.ok) {
        total.ok = false;
        total.message = s.message;
    } else if (total.ok && total.message.empty() && !s.message.empty()) {
        total.message = s.message;
    }
}

// Runs fn(begin, end) over [0, count) in batches of `options.batch`, on `options.threads`
// threads, in rounds between which `options.progress` is called; merges the statuses.
template <class Fn>
SampleStatus runBatches(size_t count, const GridSampleOptions& options, Fn fn) {
    const size_t batch = std::max<size_t>(options.batch, 1);
    const size_t batches = (count + batch - 1) / batch;
    std::vector<SampleStatus> statuses(batches);
    // More threads than the hardware has would only make TBB warn; the results do not depend
    // on the count.
    const int hardware = std::max(tbb::info::default_concurrency(), 1);
    const int threads = options.threads > 0 ? std::min(options.threads, hardware) : hardware;
    tbb::task_arena arena(std::max(threads, 1));
    const size_t perRound = std::max<size_t>(64, 16 * static_cast<size_t>(std::max(threads, 1)));
    for (size_t round = 0; round < batches; round += perRound) {
        const size_t last = std::min(batches, round + perRound);
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(round, last, 1),
                              [&](const tbb::blocked_range<size_t>& r) {
                                  for (size_t b = r.begin(); b != r.end(); ++b)
                                      statuses[b] = fn(b * batch, std::min(count, (b + 1) * batch));
                              });
        });
        if (options.progress) options.progress(std::min(count, last * batch), count);
    }
    SampleStatus total;
    for (const SampleStatus& s : statuses) mergeStatus(total, s);
    return total;
}

} // namespace

SampleStatus samplePoints(const Field& field, const double* positions, size_t count,
                          const SampleTime& when, double* velocities,
                          const GridSampleOptions& options) {
    SampleTime batchTime = when;
    batchTime.threads = 1;
    return runBatches(count, options, [&](size_t begin, size_t end) {
        return field.sample(positions + 3 * begin, end - begin, batchTime, velocities + 3 * begin);
    });
}

SampleStatus sampleGrid(const Field& field, const io::GridSpec& grid, const SampleTime& when,
                        std::vector<float>& out, const GridSampleOptions& options) {
    const size_t count = grid.cellCount();
    out.assign(3 * count, 0.0f);
    SampleTime batchTime = when;
    batchTime.threads = 1;
    const size_t ny = static_cast<size_t>(grid.res[1]), nz = static_cast<size_t>(grid.res[2]);
    return runBatches(count, options, [&](size_t begin, size_t end) {
        const size_t n = end - begin;
        std::vector<double> pos(3 * n), vel(3 * n, 0.0);
        for (size_t p = 0; p < n; ++p) {
            const size_t flat = begin + p;
            const int k = static_cast<int>(flat % nz);
            const int j = static_cast<int>((flat / nz) % ny);
            const int i = static_cast<int>(flat / (nz * ny));
            const Vec3 c = grid.cellCenter(i, j, k);
            pos[3 * p] = c[0];
            pos[3 * p + 1] = c[1];
            pos[3 * p + 2] = c[2];
        }
        SampleStatus s = field.sample(pos.data(), n, batchTime, vel.data());
        // A velocity finite in double may still overflow float32: count and zero it too.
        for (size_t p = 0; p < n; ++p) {
            float f[3];
            bool finite = true;
            for (int c = 0; c < 3; ++c) {
                f[c] = static_cast<float>(vel[3 * p + static_cast<size_t>(c)]);
                finite = finite && std::isfinite(f[c]);
            }
            float* dst = out.data() + 3 * (begin + p);
            if (!finite) {
                // The Field contract zeroes non-finite doubles (and counts them); only count
                // what it passed on.
                ++s.nonFinite;
                dst[0] = dst[1] = dst[2] = 0.0f;
                continue;
            }
            dst[0] = f[0];
            dst[1] = f[1];
            dst[2] = f[2];
        }
        return s;
    });
}

} // namespace gale::fields
