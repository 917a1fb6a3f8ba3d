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

// The inverse of a 3×3 block, or I / max|d_ii| when it is singular or its inverse not finite
// (the fallback of the block-Jacobi and multigrid smoother diagonals).
Mat3 invertBlockOrScale(const Mat3& d);

// Dot product summed in fixed chunks of kReduceChunk entries, the partial sums added in chunk
// order: the same bits on 1 or 64 threads.
constexpr std::size_t kReduceChunk = 3072; // a multiple of 3: chunks hold whole vertices
double deterministicDot(const double* a, const double* b, std::size_t n);

} // namespace gale::solver
