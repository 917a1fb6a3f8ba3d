// Internals the self-collision pass's files share (self_collision.cpp, the broad phase in
// self_collision_broad.cpp, the contact planes in self_collision_planes.cpp): tuning constants,
// an ordered parallel collection and disjoint sets. Not part of the solver's interface.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <numeric>
#include <vector>

namespace gale::solver::self_collision_detail {

constexpr double kTouching = 1e-9; // m: pairs this close at x₀ have no side to keep
constexpr int kChunk = 64;         // primitives per parallel chunk (results ordered by chunk)
// Candidates stay valid while no vertex moves more than this × ξ from where they were gathered.
constexpr double kMoveAllowance = 0.5;
// A re-gather queries only the moved vertices' primitives while at most 1/kRegatherShare of the
// vertices moved beyond the allowance (ensureCandidates).
constexpr size_t kRegatherShare = 8;
// Relative margin of the early outs on box distances (far above the 1e-15 rounding of distances).
constexpr double kBoundMargin = 1e-6;
// Proximity: the fraction of the way back to ξ a pair already closer at the start is eased per
// substep.
constexpr double kEase = 0.25;
// The inverse-mass factor of vertices touching a collider (gather()).
constexpr double kHeldByCollider = 0.01;
// The slack (× ξ) a flat patch's vertices may stray from the path it was certified for: a
// larger one lets corrections move further before the patch is certified again, but widens
// every triangle's normal cone, so a curved sheet breaks into more, smaller patches (the cape
// benchmark: ξ/8 left 12.3M candidates, ξ/4 14.1–15.0M, ξ/2 23.5M, against 27.8M without).
constexpr double kFlatSlack = 0.125;

inline double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Runs fn(i, out) for i in [0, n) in parallel and appends the outputs to `all` in index order,
// so the result does not depend on the threads. `all` is the caller's buffer, kept from pass to
// pass: a resting pile's proximity pairs are megabytes a pass, and a fresh vector each pass had
// the kernel fault its pages in anew (a fifth of the pass's time).
template <class T, class Fn>
void parallelCollect(size_t n, Fn&& fn, std::vector<T>& all) {
    const size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<std::vector<T>> parts(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const size_t end = std::min(n, (c + 1) * kChunk);
        for (size_t i = c * kChunk; i < end; ++i) fn(i, parts[c]);
    });
    size_t total = all.size();
    for (const auto& p : parts) total += p.size();
    all.reserve(total);
    for (auto& p : parts) all.insert(all.end(), p.begin(), p.end());
}
// Disjoint sets of vertices (union–find with path halving); a set's root is its smallest member,
// so the sets do not depend on the order they were joined in.
class DisjointSets {
public:
    explicit DisjointSets(size_t n) : mParent(n) { std::iota(mParent.begin(), mParent.end(), 0); }
    int find(int i) {
        while (mParent[i] != i) i = mParent[i] = mParent[mParent[i]];
        return i;
    }
    void join(int a, int b) {
        a = find(a);
        b = find(b);
        if (a != b) mParent[std::max(a, b)] = std::min(a, b);
    }

private:
    std::vector<int> mParent;
};

} // namespace gale::solver::self_collision_detail
