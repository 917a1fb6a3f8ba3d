// Threading helpers with thread-count-independent results, and the guarded 3×3 block inverse
// (see types.h).
#include "solver/linalg/types.h"

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

ColouredBlocks colourBlocks(int items, int blockSize,
                            const std::vector<std::vector<int>>& blockNeighbours) {
    ColouredBlocks cb;
    const int blocks = static_cast<int>(blockNeighbours.size());
    std::vector<int> colour(blocks, -1), seen; // seen[c] == b: a neighbour of b holds colour c
    for (int b = 0; b < blocks; ++b) {
        for (int nb : blockNeighbours[b])
            if (nb != b && colour[nb] >= 0) seen[colour[nb]] = b;
        int c = 0;
        while (c < static_cast<int>(seen.size()) && seen[c] == b) ++c;
        if (c == static_cast<int>(seen.size())) seen.push_back(-1);
        colour[b] = c;
    }
    cb.colourStart.assign(seen.size() + 1, 0);
    for (int b = 0; b < blocks; ++b) ++cb.colourStart[colour[b] + 1];
    for (size_t c = 0; c + 1 < cb.colourStart.size(); ++c)
        cb.colourStart[c + 1] += cb.colourStart[c];
    std::vector<int> fill(cb.colourStart.begin(), cb.colourStart.end() - 1), blockOrder(blocks);
    for (int b = 0; b < blocks; ++b) blockOrder[fill[colour[b]]++] = b;
    cb.order.reserve(items);
    cb.blockStart.assign(1, 0);
    for (int b : blockOrder) {
        for (int i = b * blockSize; i < std::min(items, (b + 1) * blockSize); ++i)
            cb.order.push_back(i);
        cb.blockStart.push_back(static_cast<int>(cb.order.size()));
    }
    return cb;
}

ColouredBlocks naturalBlocks(int items) {
    ColouredBlocks cb;
    cb.order.resize(items);
    for (int i = 0; i < items; ++i) cb.order[i] = i;
    cb.blockStart = {0, items};
    cb.colourStart = {0, 1};
    return cb;
}

void forEachColour(const ColouredBlocks& cb, bool reverse, bool parallel,
                   const std::function<void(std::size_t, std::size_t)>& fn) {
    const int colours = cb.colours();
    if (!parallel || colours < 2) {
        fn(0, cb.order.size());
        return;
    }
    for (int s = 0; s < colours; ++s) {
        const int c = reverse ? colours - 1 - s : s;
        const int b0 = cb.colourStart[c];
        parallelChunks(static_cast<std::size_t>(cb.colourStart[c + 1] - b0), 1,
                       [&](std::size_t k0, std::size_t k1) {
                           fn(cb.blockStart[b0 + k0], cb.blockStart[b0 + k1]);
                       });
    }
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
