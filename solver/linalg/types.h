// Small shared vocabulary of the solver: Eigen vector/matrix aliases, the threading helpers
// whose results do not depend on the thread count, and SI-unit conventions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <functional>
#include <vector>

namespace gale::solver {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using VecX = Eigen::VectorXd;

// Units everywhere: metres, seconds, kilograms (forces in N, stiffness in N/m, ...).

// A 3-vector stored at p[3*i .. 3*i+2] of a flat array.
inline Eigen::Map<Vec3> vec3At(double* p, std::size_t i) { return Eigen::Map<Vec3>(p + 3 * i); }
inline Eigen::Map<const Vec3> vec3At(const double* p, std::size_t i) {
    return Eigen::Map<const Vec3>(p + 3 * i);
}

// Runs fn(begin, end) over [0, n) in chunks, in parallel when the calling thread's TBB arena
// has more than one thread. Every index is handled by exactly one call, so code that writes
// only its own indices gives identical results for any thread count.
void parallelChunks(std::size_t n, std::size_t grain,
                    const std::function<void(std::size_t, std::size_t)>& fn);

// The number of threads of the calling thread's TBB arena (1: parallelChunks runs inline).
int arenaConcurrency();

// A deterministic parallel order for a loop whose items may not run at the same time as their
// neighbours (Gauss–Seidel rows that share a block, triangles that share a vertex): the items
// cut into consecutive blocks of a fixed size, the blocks coloured greedily in block order (a
// block takes the smallest colour no earlier neighbouring block holds), then listed colour by
// colour, blocks and items in index order. Running the colours in order, the blocks of one
// colour in parallel and each block's items in order gives every item the same inputs on any
// number of threads — the same bits as running `order` sequentially. Consecutive blocks keep
// the memory locality of the item order (a colour-major order of single items would scatter
// every pass over the whole mesh).
struct ColouredBlocks {
    std::vector<int> order;       // the items, colour by colour
    std::vector<int> blockStart;  // block b is order[blockStart[b] .. blockStart[b+1])
    std::vector<int> colourStart; // colour c is blocks colourStart[c] .. colourStart[c+1]
    int colours() const { return static_cast<int>(colourStart.size()) - 1; }
};
// blockNeighbours[b]: the blocks whose items neighbour an item of block b (b itself ignored).
ColouredBlocks colourBlocks(int items, int blockSize,
                            const std::vector<std::vector<int>>& blockNeighbours);
// All items in one block and one colour: the plain index order.
ColouredBlocks naturalBlocks(int items);
// Runs fn(begin, end) over ranges of positions in cb.order covering it once: colour by colour
// (the last colour first with `reverse`), each colour's blocks in parallel chunks; with
// `parallel` false, or a single colour, one call fn(0, n).
void forEachColour(const ColouredBlocks& cb, bool reverse, bool parallel,
                   const std::function<void(std::size_t, std::size_t)>& fn);

// The inverse of a 3×3 block, or I / max|d_ii| when it is singular or its inverse not finite
// (the fallback of the block-Jacobi and multigrid smoother diagonals).
Mat3 invertBlockOrScale(const Mat3& d);

// Dot product summed in fixed chunks of kReduceChunk entries, the partial sums added in chunk
// order: the same bits on 1 or 64 threads.
constexpr std::size_t kReduceChunk = 3072; // a multiple of 3: chunks hold whole vertices
double deterministicDot(const double* a, const double* b, std::size_t n);

} // namespace gale::solver
