// Smoothed aggregation in 3×3 blocks (see prolongator.h). References: Vaněk, Mandel, Brezina,
// "Algebraic multigrid by smoothed aggregation for second and fourth order elliptic problems",
// Computing 56 (1996); Tamstorf, Jones, McCormick, "Smoothed aggregation multigrid for cloth
// simulation", SIGGRAPH Asia 2015.
#include "solver/linalg/prolongator.h"

#include "solver/linalg/multigrid.h"
#include "solver/linalg/types.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {

using BlockMap = Eigen::Map<Mat3>;
using ConstBlockMap = Eigen::Map<const Mat3>;

// A single-precision block (column-major, 9 floats) as a double 3×3 matrix.
inline Mat3 blockAt(const float* p) {
    return Eigen::Map<const Eigen::Matrix3f>(p).cast<double>();
}
inline void storeBlock(float* p, const Mat3& m) {
    Eigen::Map<Eigen::Matrix3f> out(p);
    out = m.cast<float>();
}

int findSlot(const std::vector<int>& cols, int k0, int k1, int col) {
    for (int k = k0; k < k1; ++k)
        if (cols[k] == col) return k;
    return -1; // not reached: the pattern holds every column written
}

} // namespace

// ---------------------------------------------------------------------------------------------
// BlockProlongator

void BlockProlongator::buildTranspose() {
    tStart.assign(columns + 1, 0);
    for (int c : cols) ++tStart[c + 1];
    for (int J = 0; J < columns; ++J) tStart[J + 1] += tStart[J];
    tRow.resize(cols.size());
    tSlot.resize(cols.size());
    std::vector<int> fill(tStart.begin(), tStart.end() - 1);
    for (int r = 0; r < rows; ++r)
        for (int k = start[r]; k < start[r + 1]; ++k) {
            const int p = fill[cols[k]]++;
            tRow[p] = r;
            tSlot[p] = k;
        }
}

// (Written out in scalars: the float blocks are read once each, without temporaries. The
// transposed walk reads P's blocks out of storage order, mostly cache misses: the blocks a few
// steps ahead are prefetched.)
void BlockProlongator::restrictTo(const double* x, double* y) const {
    parallelChunks(static_cast<size_t>(columns), 256, [&](size_t J0, size_t J1) {
        const float* __restrict v = val.data();
        const int ahead = 12, last = tStart[J1];
        for (size_t J = J0; J < J1; ++J) {
            double s0 = 0.0, s1 = 0.0, s2 = 0.0;
            for (int t = tStart[J]; t < tStart[J + 1]; ++t) {
                if (t + ahead < last) {
                    const float* p = v + 9 * static_cast<size_t>(tSlot[t + ahead]);
                    __builtin_prefetch(p);
                    __builtin_prefetch(p + 8);
                    __builtin_prefetch(x + 3 * static_cast<size_t>(tRow[t + ahead]));
                }
                const float* b =
                    v + 9 * static_cast<size_t>(tSlot[t]); // column-major: column c of P_rJ
                const double* xr =
                    x + 3 * static_cast<size_t>(tRow[t]); // is row c of its transpose
                s0 += double(b[0]) * xr[0] + double(b[1]) * xr[1] + double(b[2]) * xr[2];
                s1 += double(b[3]) * xr[0] + double(b[4]) * xr[1] + double(b[5]) * xr[2];
                s2 += double(b[6]) * xr[0] + double(b[7]) * xr[1] + double(b[8]) * xr[2];
            }
            y[3 * J] = s0;
            y[3 * J + 1] = s1;
            y[3 * J + 2] = s2;
        }
    });
}

void BlockProlongator::prolongAdd(const double* e, double alpha, double* x) const {
    parallelChunks(static_cast<size_t>(rows), 512, [&](size_t r0, size_t r1) {
        const float* __restrict v = val.data();
        for (size_t r = r0; r < r1; ++r) {
            double s0 = 0.0, s1 = 0.0, s2 = 0.0;
            for (int k = start[r]; k < start[r + 1]; ++k) {
                const float* b = v + 9 * static_cast<size_t>(k);
                const double* ec = e + 3 * static_cast<size_t>(cols[k]);
                s0 += double(b[0]) * ec[0] + double(b[3]) * ec[1] + double(b[6]) * ec[2];
                s1 += double(b[1]) * ec[0] + double(b[4]) * ec[1] + double(b[7]) * ec[2];
                s2 += double(b[2]) * ec[0] + double(b[5]) * ec[1] + double(b[8]) * ec[2];
            }
            x[3 * r] += alpha * s0;
            x[3 * r + 1] += alpha * s1;
            x[3 * r + 2] += alpha * s2;
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Aggregation

int aggregateNodes(int n, const int* start, const int* cols, const std::vector<int>& visit,
                   std::vector<int>& joined) {
    std::vector<int> agg(n, -1), size;
    // 1. Roots: a node whose neighbours are all unaggregated starts an aggregate with them.
    for (int s = 0; s < n; ++s) {
        const int i = visit[s];
        if (agg[i] >= 0) continue;
        bool free = true;
        for (int k = start[i]; k < start[i + 1] && free; ++k)
            if (agg[cols[k]] >= 0) free = false;
        if (!free) continue;
        for (int k = start[i]; k < start[i + 1]; ++k) agg[cols[k]] = static_cast<int>(size.size());
        size.push_back(start[i + 1] - start[i]);
    }
    // 2. The rest join the smallest neighbouring aggregate (ties: the lower index), decided
    // from the phase-1 labels only, so the order of the nodes does not matter.
    joined = agg;
    for (int i = 0; i < n; ++i) {
        if (agg[i] >= 0) continue;
        for (int k = start[i]; k < start[i + 1]; ++k) {
            const int J = agg[cols[k]];
            if (J >= 0 && (joined[i] < 0 || size[J] < size[joined[i]] ||
                           (size[J] == size[joined[i]] && J < joined[i])))
                joined[i] = J;
        }
    }
    // 3. Left-overs (no aggregated neighbour) form aggregates with their unaggregated neighbours.
    int count = static_cast<int>(size.size());
    for (int s = 0; s < n; ++s) {
        const int i = visit[s];
        if (joined[i] >= 0) continue;
        joined[i] = count;
        for (int k = start[i]; k < start[i + 1]; ++k)
            if (joined[cols[k]] < 0) joined[cols[k]] = count;
        ++count;
    }
    return count;
}

// ---------------------------------------------------------------------------------------------
// Tentative prolongator

namespace {

// The tentative prolongator for M near-null modes (fixed-size eigen-decompositions).
template <int M>
void tentativeFixed(const Aggregates& g, const std::vector<double>& fineB, std::vector<double>& Q,
                    std::vector<double>& coarseB, std::vector<uint8_t>& dead) {
    using MatM = Eigen::Matrix<double, M, M>;
    using Mat3M = Eigen::Matrix<double, 3, M>;
    const int nc = static_cast<int>(g.memberStart.size()) - 1;
    const int dc = M / 3, d = g.d;
    const size_t stride = 3 * static_cast<size_t>(M); // values per block row of B and Q
    Q.resize(fineB.size());
    coarseB.assign(stride * dc * nc, 0.0);
    dead.assign(static_cast<size_t>(M) * nc, 0);
    parallelChunks(static_cast<size_t>(nc), 32, [&](size_t J0, size_t J1) {
        for (size_t J = J0; J < J1; ++J) {
            MatM G = MatM::Zero();
            for (int t = g.memberStart[J]; t < g.memberStart[J + 1]; ++t)
                for (int q = 0; q < d; ++q) {
                    const size_t r = static_cast<size_t>(g.members[t]) * d + q;
                    const Eigen::Map<const Mat3M> B(fineB.data() + stride * r);
                    G.noalias() += B.transpose() * B;
                }
            // G = Lᵀ-Cholesky with a column dropped when its pivot falls below 1e-8 of its
            // diagonal (it lies in the span of the columns before it): R = Lᵀ, T = R⁻¹ on
            // the kept columns, Q = B T (Gram–Schmidt in the fixed column order: a continuous
            // function of B, so the rounding of either kernel set cannot turn the basis).
            MatM L = MatM::Zero();
            for (int k = 0; k < M; ++k) {
                const double pivot = G(k, k) - L.row(k).head(k).squaredNorm();
                if (!(G(k, k) > 0.0) || !(pivot > 1e-8 * G(k, k))) {
                    dead[static_cast<size_t>(M) * J + k] = 1;
                    continue;
                }
                L(k, k) = std::sqrt(pivot);
                for (int i = k + 1; i < M; ++i)
                    L(i, k) = (G(i, k) - L.row(i).head(k).dot(L.row(k).head(k))) / L(k, k);
            }
            const MatM R = L.transpose();
            MatM T = MatM::Zero();
            for (int k = 0; k < M; ++k) {
                if (dead[static_cast<size_t>(M) * J + k]) continue;
                Eigen::Matrix<double, M, 1> t = Eigen::Matrix<double, M, 1>::Zero();
                t[k] = 1.0;
                for (int j = 0; j < k; ++j) t -= R(j, k) * T.col(j);
                T.col(k) = t / R(k, k);
            }
            for (int t = g.memberStart[J]; t < g.memberStart[J + 1]; ++t)
                for (int q = 0; q < d; ++q) {
                    const size_t r = static_cast<size_t>(g.members[t]) * d + q;
                    const Eigen::Map<const Mat3M> B(fineB.data() + stride * r);
                    Eigen::Map<Mat3M>(Q.data() + stride * r).noalias() = B * T;
                }
            for (int q = 0; q < dc; ++q)
                Eigen::Map<Mat3M>(coarseB.data() + stride * (J * dc + q)) = R.middleRows(3 * q, 3);
        }
    });
}

} // namespace

void tentativeProlongator(const Aggregates& g, int m, const std::vector<double>& fineB,
                          std::vector<double>& Q, std::vector<double>& coarseB,
                          std::vector<uint8_t>& dead) {
    if (m == 6)
        tentativeFixed<6>(g, fineB, Q, coarseB, dead);
    else
        tentativeFixed<3>(g, fineB, Q, coarseB, dead);
}

// ---------------------------------------------------------------------------------------------
// Smoothed prolongator

void prolongatorPattern(const BsrMatrix& A, const Aggregates& g, int dc, bool smoothed,
                        BlockProlongator& P) {
    const int d = g.d;
    P.rows = A.n;
    P.columns = dc * static_cast<int>(g.memberStart.size() - 1);
    P.start.assign(A.n + 1, 0);
    P.cols.clear();
    std::vector<int> row;
    for (int r = 0; r < A.n; ++r) {
        row.clear();
        if (smoothed) {
            for (int k = A.start[r]; k < A.start[r + 1]; ++k)
                for (int q = 0; q < dc; ++q) row.push_back(g.nodeAgg[A.cols[k] / d] * dc + q);
        } else {
            for (int q = 0; q < dc; ++q) row.push_back(g.nodeAgg[r / d] * dc + q);
        }
        std::sort(row.begin(), row.end());
        row.erase(std::unique(row.begin(), row.end()), row.end());
        P.cols.insert(P.cols.end(), row.begin(), row.end());
        P.start[r + 1] = static_cast<int>(P.cols.size());
    }
    P.cols.shrink_to_fit();
    P.val.assign(9 * P.cols.size(), 0.0f);
    P.val.shrink_to_fit();
}

void smoothProlongator(const BsrMatrix& A, const Aggregates& g, int dc, double omega,
                       const std::vector<double>& Q, BlockProlongator& P) {
    const int d = g.d;
    const size_t stride = 9 * static_cast<size_t>(dc);
    parallelChunks(static_cast<size_t>(A.n), 256, [&](size_t r0, size_t r1) {
        std::vector<double> row; // the row's blocks in double, rounded to float when complete
        for (size_t r = r0; r < r1; ++r) {
            const int k0 = P.start[r], k1 = P.start[r + 1];
            row.assign(9 * static_cast<size_t>(k1 - k0), 0.0);
            if (omega == 0.0) {
                const int U = g.nodeAgg[r / d];
                for (int q = 0; q < dc; ++q) {
                    const int slot = findSlot(P.cols, k0, k1, U * dc + q);
                    BlockMap(row.data() + 9 * static_cast<size_t>(slot - k0)) =
                        ConstBlockMap(Q.data() + stride * r + 9 * q);
                }
            } else {
                const Mat3 dinv =
                    invertBlockOrScale(blockAt(A.val.data() + 9 * static_cast<size_t>(A.diag[r])));
                for (int k = A.start[r]; k < A.start[r + 1]; ++k) {
                    const int s = A.cols[k];
                    Mat3 M = -omega * dinv * blockAt(A.val.data() + 9 * static_cast<size_t>(k));
                    if (s == static_cast<int>(r)) M += Mat3::Identity();
                    const int U = g.nodeAgg[s / d];
                    for (int q = 0; q < dc; ++q) {
                        const int slot = findSlot(P.cols, k0, k1, U * dc + q);
                        BlockMap(row.data() + 9 * static_cast<size_t>(slot - k0)).noalias() +=
                            M * ConstBlockMap(Q.data() + stride * s + 9 * q);
                    }
                }
            }
            for (size_t q = 0; q < row.size(); ++q)
                P.val[9 * static_cast<size_t>(k0) + q] = static_cast<float>(row[q]);
        }
    });
}

double spectralRadiusDinvA(const BsrMatrix& A, const double* dinv, int iterations) {
    const size_t n3 = 3 * static_cast<size_t>(A.n);
    if (n3 == 0) return 1.0;
    std::vector<double> x(n3), y(n3);
    for (size_t k = 0; k < n3; ++k) // a fixed, rough start: every mode present
        x[k] = static_cast<double>((k * 2654435761u) % 1000u) / 1000.0 - 0.5;
    for (int it = 0; it < iterations; ++it) {
        A.multiply(x.data(), y.data());
        parallelChunks(static_cast<size_t>(A.n), 1024, [&](size_t i0, size_t i1) {
            for (size_t i = i0; i < i1; ++i)
                Eigen::Map<Vec3>(x.data() + 3 * i) =
                    ConstBlockMap(dinv + 9 * i) * Eigen::Map<const Vec3>(y.data() + 3 * i);
        });
        const double norm = std::sqrt(deterministicDot(x.data(), x.data(), n3));
        if (!(norm > 0.0) || !std::isfinite(norm)) return 1.0;
        for (double& v : x) v /= norm;
    }
    A.multiply(x.data(), y.data());
    const double num = deterministicDot(x.data(), y.data(), n3);
    parallelChunks(static_cast<size_t>(A.n), 1024, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i)
            Eigen::Map<Vec3>(y.data() + 3 * i) =
                blockAt(A.val.data() + 9 * static_cast<size_t>(A.diag[i])) *
                Eigen::Map<const Vec3>(x.data() + 3 * i);
    });
    const double den = deterministicDot(x.data(), y.data(), n3);
    return den > 0.0 && num > 0.0 ? num / den : 1.0;
}

// ---------------------------------------------------------------------------------------------
// Galerkin product

void galerkinPattern(const BsrMatrix& A, const BlockProlongator& P, std::vector<int>& start,
                     std::vector<int>& cols) {
    const int nc = P.columns;
    start.assign(nc + 1, 0);
    cols.clear();
    std::vector<int> mark(nc, -1), row;
    for (int J = 0; J < nc; ++J) {
        row.clear();
        mark[J] = J;
        row.push_back(J);
        for (int t = P.tStart[J]; t < P.tStart[J + 1]; ++t) {
            const int r = P.tRow[t];
            for (int k = A.start[r]; k < A.start[r + 1]; ++k) {
                const int s = A.cols[k];
                for (int m = P.start[s]; m < P.start[s + 1]; ++m)
                    if (mark[P.cols[m]] != J) {
                        mark[P.cols[m]] = J;
                        row.push_back(P.cols[m]);
                    }
            }
        }
        std::sort(row.begin(), row.end());
        cols.insert(cols.end(), row.begin(), row.end());
        start[J + 1] = static_cast<int>(cols.size());
    }
}

// Row J of C = Pᵀ (A P): Y_s = Σ_r P_rJᵀ A_rs over the fine rows r of column J of P (in
// increasing order), then C_JK = Σ_s Y_s P_sK for K ≥ J only, over the s in the order first
// reached, in double. The row's diagonal block is symmetrised (its two triangles are summed in
// different orders), each block rounded to float; then each row copies its blocks left of the
// diagonal as the transposes of those (C is symmetric exactly). Scratch per thread (its
// contents never outlive a row).
void galerkinValues(const BsrMatrix& A, const BlockProlongator& P, BsrMatrix& C) {
    parallelChunks(static_cast<size_t>(C.n), 16, [&](size_t J0, size_t J1) {
        thread_local std::vector<int> pos, cpos, touched;
        thread_local std::vector<double> Y, row;
        if (pos.size() < static_cast<size_t>(A.n)) pos.resize(A.n, -1);
        if (cpos.size() < static_cast<size_t>(C.n)) cpos.resize(C.n, -1);
        for (size_t J = J0; J < J1; ++J) {
            const int d0 = C.diag[J], k1 = C.start[J + 1];
            for (int m = d0; m < k1; ++m) cpos[C.cols[m]] = m - d0;
            row.assign(9 * static_cast<size_t>(k1 - d0), 0.0);
            touched.clear();
            Y.clear();
            for (int t = P.tStart[J]; t < P.tStart[J + 1]; ++t) {
                const int r = P.tRow[t];
                const Mat3 Wt =
                    blockAt(P.val.data() + 9 * static_cast<size_t>(P.tSlot[t])).transpose();
                for (int k = A.start[r]; k < A.start[r + 1]; ++k) {
                    const int s = A.cols[k];
                    if (pos[s] < 0) {
                        pos[s] = static_cast<int>(touched.size());
                        touched.push_back(s);
                        Y.resize(Y.size() + 9, 0.0);
                    }
                    BlockMap(Y.data() + 9 * static_cast<size_t>(pos[s])).noalias() +=
                        Wt * blockAt(A.val.data() + 9 * static_cast<size_t>(k));
                }
            }
            for (size_t idx = 0; idx < touched.size(); ++idx) {
                const int s = touched[idx];
                const ConstBlockMap Ys(Y.data() + 9 * idx);
                // P's columns are sorted: those from J on.
                const int* c0 = P.cols.data() + P.start[s];
                const int* c1 = P.cols.data() + P.start[s + 1];
                for (const int* c = std::lower_bound(c0, c1, static_cast<int>(J)); c < c1; ++c) {
                    const size_t m = static_cast<size_t>(c - P.cols.data());
                    BlockMap(row.data() + 9 * static_cast<size_t>(cpos[*c])).noalias() +=
                        Ys * blockAt(P.val.data() + 9 * m);
                }
                pos[s] = -1;
            }
            for (int m = d0; m < k1; ++m) {
                Mat3 b = ConstBlockMap(row.data() + 9 * static_cast<size_t>(m - d0));
                if (m == d0) b = (0.5 * (b + b.transpose())).eval();
                storeBlock(C.val.data() + 9 * static_cast<size_t>(m), b);
                cpos[C.cols[m]] = -1;
            }
        }
    });
    parallelChunks(static_cast<size_t>(C.n), 256, [&](size_t K0, size_t K1) {
        for (size_t K = K0; K < K1; ++K)
            for (int m = C.start[K]; m < C.diag[K]; ++m) {
                const int J = C.cols[m];
                const int* c0 = C.cols.data() + C.diag[J];
                const int* c1 = C.cols.data() + C.start[J + 1];
                const size_t mt = static_cast<size_t>(
                    std::lower_bound(c0, c1, static_cast<int>(K)) - C.cols.data());
                const float* src = C.val.data() + 9 * mt;
                float* dst = C.val.data() + 9 * static_cast<size_t>(m);
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c) dst[3 * c + r] = src[3 * r + c];
            }
    });
}

} // namespace gale::solver
