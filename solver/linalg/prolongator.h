// The smoothed-aggregation pieces of the multigrid (multigrid.h): node aggregation, the
// rectangular block prolongator, the tentative prolongator on a filtered rigid-body near-null
// space, its damped-Jacobi smoothing and the Galerkin product Pᵀ A P, all in 3×3 blocks.
#pragma once

#include <cstdint>
#include <vector>

namespace gale::solver {

struct BsrMatrix;

// A rectangular 3×3-block sparse matrix (fine block rows × coarse block columns) and the
// pattern of its transpose.
struct BlockProlongator {
    int rows = 0, columns = 0;
    std::vector<int> start, cols;         // block CSR by rows, columns sorted
    std::vector<float> val;               // 9 per block, column-major, single precision
    std::vector<int> tStart, tRow, tSlot; // column J: rows tRow[tStart[J] ..] (increasing), slots

    void buildTranspose();
    // y = Pᵀ x (coarse), each coarse row summed in fine-row order; parallel, the same bits.
    void restrictTo(const double* x, double* y) const;
    // x += α P e (fine), parallel over fine rows.
    void prolongAdd(const double* e, double alpha, double* x) const;
};

// Vaněk–Mandel–Brezina aggregation (1996, §4) of an undirected node graph (CSR, the node itself
// listed): a node whose neighbours are all free starts an aggregate with them (nodes visited
// in `visit` order: visit[s] is the s-th node), the rest join the smallest neighbouring
// aggregate, left-overs group with their free neighbours. joined[u] = aggregate of u, numbered
// in the order found; returns their count. Reads the graph only.
int aggregateNodes(int n, const int* start, const int* cols, const std::vector<int>& visit,
                   std::vector<int>& joined);

// Tentative prolongator of smoothed aggregation (Vaněk et al. 1996, §3): the near-null space B
// (m columns, m = 3 or 6) restricted to each aggregate and orthonormalised there,
//   B_J = Q_J R_J,  Q_Jᵀ Q_J = I  (from the eigen-decomposition of B_Jᵀ B_J; directions no
// member can represent are dropped: their columns of Q and rows of R are zero, `dead`),
// so that P_tent = blockdiag(Q_J) reproduces B exactly and R_J is the coarse near-null space.
// Fine block rows r of node u are u·d .. u·d + d − 1; fineB holds 3×m per fine block row
// (column-major); Q receives 3×m per fine block row and coarseB 3×m per coarse block row
// (d_c = m / 3 block rows per coarse node); dead: one per coarse scalar unknown.
struct Aggregates {
    int d = 1;                             // fine block rows per node
    std::vector<int> nodeAgg;              // coarse node of each fine node
    std::vector<int> memberStart, members; // fine nodes of each coarse node, increasing
};
void tentativeProlongator(const Aggregates& g, int m, const std::vector<double>& fineB,
                          std::vector<double>& Q, std::vector<double>& coarseB,
                          std::vector<uint8_t>& dead);

// The pattern of P: row r holds the coarse block rows of the aggregates of its neighbours in A
// (smoothed) or of its own aggregate only (tentative). Columns in the coarse numbering
// `coarseOf(node) · d_c + q`, sorted.
void prolongatorPattern(const BsrMatrix& A, const Aggregates& g, int dc, bool smoothed,
                        BlockProlongator& P);

// P = (I − ω D⁻¹ A) P_tent (Vaněk et al. 1996, eq. 3.4; D the 3×3 block diagonal of A), or
// P = P_tent with ω = 0; rows in parallel, each summed in double and stored in float.
void smoothProlongator(const BsrMatrix& A, const Aggregates& g, int dc, double omega,
                       const std::vector<double>& Q, BlockProlongator& P);

// An estimate of ρ(D⁻¹A) (A SPD): the D-Rayleigh quotient xᵀAx / xᵀDx after `iterations` power
// steps x ← D⁻¹ A x from a fixed start. dinv: 9 per row. Deterministic for any thread count.
double spectralRadiusDinvA(const BsrMatrix& A, const double* dinv, int iterations);

// The pattern of C = Pᵀ A P (columns sorted, the diagonal present): start and cols for
// P.columns rows.
void galerkinPattern(const BsrMatrix& A, const BlockProlongator& P, std::vector<int>& start,
                     std::vector<int>& cols);
// C's values (its pattern from galerkinPattern, diag set): coarse rows in parallel, each
// summed in double in a fixed order (the same bits for any thread count); row J computes its
// diagonal and the blocks right of it, the blocks left of the diagonal are copied as their
// transposes, so C is symmetric exactly; stored in float.
void galerkinValues(const BsrMatrix& A, const BlockProlongator& P, BsrMatrix& C);

} // namespace gale::solver
