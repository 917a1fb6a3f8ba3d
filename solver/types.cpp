// Threading helpers with thread-count-independent results, and the guarded 3×3 block inverse
// (see types.h).
#include "solver/types.h"

#include <Eigen/LU>

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace gale::solver {

void parallelChunks(std::size_t n, std::size_t grain,
                    const std::function<void(std::size_t, std::size_t)>& fn) {
    if (n == 0) return;
    if (grain == 0) grain = 1;
    if (n <= grain || tbb::this_task_arena::max_concurrency() <= 1) {
        fn(0, n);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) { fn(r.begin(), r.end()); });
}

int arenaConcurrency() {
    return tbb::this_task_arena::max_concurrency();
}

Mat3 invertBlockOrScale(const Mat3& d) {
    Mat3 inv;
    bool ok = false;
    double det = 0.0;
    d.computeInverseAndDetWithCheck(inv, det, ok, 0.0);
    if (!ok || !inv.allFinite()) inv = Mat3::Identity() / std::max(d.diagonal().cwiseAbs().maxCoeff(), 1e-300);
    return inv;
}

double deterministicDot(const double* a, const double* b, std::size_t n) {
    const std::size_t chunks = (n + kReduceChunk - 1) / kReduceChunk;
    if (chunks <= 1) {
        double s = 0.0;
        for (std::size_t i = 0; i < n; ++i) s += a[i] * b[i];
        return s;
    }
    // Reused between calls; workers write through this reference (a thread_local named inside
    // the lambda would be the worker's own).
    thread_local std::vector<double> buffer;
    std::vector<double>& partial = buffer;
    partial.assign(chunks, 0.0);
    parallelChunks(chunks, 1, [&](std::size_t c0, std::size_t c1) {
        for (std::size_t c = c0; c < c1; ++c) {
            const std::size_t e = std::min(n, (c + 1) * kReduceChunk);
            double s = 0.0;
            for (std::size_t i = c * kReduceChunk; i < e; ++i) s += a[i] * b[i];
            partial[c] = s;
        }
    });
    double s = 0.0;
    for (double p : partial) s += p;
    return s;
}

} // namespace gale::solver
