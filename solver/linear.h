// The implicit step's linear algebra: a symmetric 3×3-block sparse matrix stored as an Eigen
// row-major SparseMatrix with a fixed pattern, constraint filters (Baraff–Witkin), and two
// solvers of the filtered system — preconditioned conjugate gradient (3×3 block Jacobi, or
// aggregation multigrid from multigrid.h) and a sparse LDLᵀ — both returning a status, never
// throwing.
#pragma once

#include "solver/multigrid.h"
#include "solver/types.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace gale::solver {

class BlockMatrix {
public:
    // n block rows; `pairs` lists coupled vertices (i ≠ j, either order, repeats allowed). The
    // pattern is the diagonal plus both (i, j) and (j, i).
    void build(int n, const std::vector<std::pair<int, int>>& pairs);

    int size() const { return mN; }
    // Slot of block (i, j), -1 when not in the pattern.
    int slot(int i, int j) const;
    int diagonalSlot(int i) const { return mDiagSlot[i]; }
    int slotCount() const { return static_cast<int>(mSlotBase.size()); }

    void setZero();
    // values(i, j) += scale * b
    void addBlock(int slot, const Mat3& b, double scale = 1.0) {
        double* p = mA.valuePtr() + mSlotBase[slot];
        const int s = mSlotStride[slot];
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c) p[a * s + c] += scale * b(a, c);
    }
    void addDiagonal(int slot, double value) {
        double* p = mA.valuePtr() + mSlotBase[slot];
        const int s = mSlotStride[slot];
        p[0] += value;
        p[s + 1] += value;
        p[2 * s + 2] += value;
    }
    Mat3 block(int slot) const;
    void setBlock(int slot, const Mat3& b);

    // y = A x (3n vectors), parallel over rows, deterministic.
    void multiply(const double* x, double* y) const;

    // The block pattern: block row i holds columns blockCols()[blockRowStart()[i] .. [i+1]),
    // sorted; slot k is the k-th entry of blockCols().
    const std::vector<int>& blockRowStart() const { return mBlockRowStart; }
    const std::vector<int>& blockCols() const { return mBlockCols; }

    const Eigen::SparseMatrix<double, Eigen::RowMajor>& matrix() const { return mA; }
    Eigen::SparseMatrix<double, Eigen::RowMajor>& matrix() { return mA; }

private:
    int mN = 0;
    Eigen::SparseMatrix<double, Eigen::RowMajor> mA;
    std::vector<int> mBlockRowStart, mBlockCols; // block CSR of the pattern
    std::vector<int> mSlotBase, mSlotStride, mDiagSlot;
};

// Per-vertex constraint of the Baraff–Witkin filter: Δv_i = S_i y_i + z_i with z_i the
// prescribed change in the constrained directions. Free: S = I; Full (a pin): S = 0;
// Plane (a contact, normal n): S = I − n nᵀ.
struct Constraints {
    std::vector<uint8_t> kind; // 0 free, 1 full, 2 plane
    std::vector<double> normal; // 3 per vertex (kind 2)
    std::vector<double> z;      // 3 per vertex: prescribed velocity change (m/s)

    void reset(size_t n) {
        kind.assign(n, 0);
        normal.assign(3 * n, 0.0);
        z.assign(3 * n, 0.0);
    }
    bool any() const;
    Mat3 filter(size_t i) const;
    // x ← S x in place.
    void apply(double* x) const;
};

struct SolveStatus {
    bool converged = false;
    int iterations = 0;
    double residual = 0.0; // ‖Â y − r‖ / ‖r‖ of the filtered system
    bool failed = false;   // a factorisation failed or a value became non-finite
};

enum class LinearSolverKind { Pcg, Direct };

// Solves (M + hD + h²K) Δv = b subject to the constraints, as the SPD filtered system
//   (S A S + I − S) y = S (b − A z),   Δv = y + z
// (Ascher & Boxerman 2003; Tamstorf, Jones, McCormick 2015), which is equivalent to
// Baraff–Witkin's modified PCG. `dv` holds the initial guess on entry (warm start).
class FilteredSolver {
public:
    // The PCG preconditioner (block Jacobi by default; see multigrid.h).
    void setPreconditioner(Preconditioner p) { mPreconditioner = p; }
    Preconditioner preconditioner() const { return mPreconditioner; }
    BlockMultigrid& multigrid() { return mMultigrid; }

    SolveStatus solve(const BlockMatrix& A, const Constraints& c, const VecX& b, VecX& dv,
                      LinearSolverKind kind, double tolerance, int maxIterations);

private:
    SolveStatus solvePcg(const BlockMatrix& A, const Constraints& c, const VecX& rhs, VecX& y,
                         double tolerance, int maxIterations);
    SolveStatus solvePcgMultigrid(const BlockMatrix& A, const Constraints& c, const VecX& rhs, VecX& y,
                                  double tolerance, int maxIterations);
    SolveStatus solveDirect(const BlockMatrix& A, const Constraints& c, const VecX& rhs, VecX& y);
    void applyFiltered(const BlockMatrix& A, const Constraints& c, const VecX& x, VecX& out);

    Preconditioner mPreconditioner = Preconditioner::BlockJacobi;
    BlockMultigrid mMultigrid;
    VecX mTmp, mTmp2, mR, mZ, mP, mQ;
    std::vector<double> mPartial;
    std::vector<int> mConstrained; // vertices with S ≠ I
    std::vector<Mat3> mPrecond;
    using ColMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;
    ColMatrix mFilteredA;
    std::unique_ptr<Eigen::SimplicialLDLT<ColMatrix>> mLdlt;
};

} // namespace gale::solver
