// The implicit step's linear algebra: a symmetric 3×3-block sparse matrix stored as an Eigen
// row-major SparseMatrix with a fixed pattern, constraint filters (Baraff–Witkin), and two
// solvers of the filtered system — preconditioned conjugate gradient (3×3 block Jacobi, or
// aggregation multigrid from multigrid.h) and a sparse LDLᵀ — both returning a status, never
// throwing.
#pragma once

#include "solver/linalg/banded_ldlt.h"
#include "solver/linalg/multigrid.h"
#include "solver/linalg/types.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace gale::solver {

// Values in block CSR (BSR): slot k holds the 3×3 block (i, blockCols()[k]) of block row i
// column-major at values()[9k .. 9k+8] — the layout the kernels of bsr_kernels.h and the
// multigrid read directly, so the assembled matrix reaches them with one copy.
class BlockMatrix {
public:
    using ScalarMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;

    // n block rows; `pairs` lists coupled vertices (i ≠ j, either order, repeats allowed). The
    // pattern is the diagonal plus both (i, j) and (j, i).
    void build(int n, const std::vector<std::pair<int, int>>& pairs);

    int size() const { return mN; }
    // Slot of block (i, j), -1 when not in the pattern.
    int slot(int i, int j) const;
    int diagonalSlot(int i) const { return mDiagSlot[i]; }
    int slotCount() const { return static_cast<int>(mBlockCols.size()); }
    // Slot of the transposed block: (j, i) for slot (i, j).
    int mirrorSlot(int slot) const { return mMirror[slot]; }

    void setZero();
    // values(i, j) += scale * b
    void addBlock(int slot, const Mat3& b, double scale = 1.0) {
        double* __restrict p = mVal.data() + 9 * static_cast<size_t>(slot);
        const double* __restrict q = b.data(); // column-major, as stored; never inside mVal
        for (int k = 0; k < 9; ++k) p[k] += scale * q[k];
    }
    void addDiagonal(int slot, double value) {
        double* p = mVal.data() + 9 * static_cast<size_t>(slot);
        p[0] += value;
        p[4] += value;
        p[8] += value;
    }
    Mat3 block(int slot) const { return Eigen::Map<const Mat3>(mVal.data() + 9 * static_cast<size_t>(slot)); }
    void setBlock(int slot, const Mat3& b) { Eigen::Map<Mat3>(mVal.data() + 9 * static_cast<size_t>(slot)) = b; }
    // 9 × slotCount() values (+ kBsrPad zeros).
    const double* values() const { return mVal.data(); }

    // y = A x (3n vectors), parallel over rows, deterministic.
    void multiply(const double* x, double* y) const;

    // The block pattern: block row i holds columns blockCols()[blockRowStart()[i] .. [i+1]),
    // sorted; slot k is the k-th entry of blockCols().
    const std::vector<int>& blockRowStart() const { return mBlockRowStart; }
    const std::vector<int>& blockCols() const { return mBlockCols; }
    BsrPattern pattern() const { return {mBlockRowStart.data(), mBlockCols.data(), mDiagSlot.data(), mN}; }

    // The scalar (3n × 3n) matrix; `toScalar` reuses out's pattern when it already has it.
    void toScalar(ScalarMatrix& out) const;
    ScalarMatrix scalar() const {
        ScalarMatrix m;
        toScalar(m);
        return m;
    }

private:
    int mN = 0;
    std::vector<double> mVal;
    std::vector<int> mBlockRowStart, mBlockCols; // block CSR of the pattern
    std::vector<int> mDiagSlot, mMirror;
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
    Mat3 filter(size_t i) const { return filterOf(kind[i], normal.data() + 3 * i); }
    // S for a filter kind (0, 1, 2) and, for a plane, its normal.
    static Mat3 filterOf(uint8_t kind, const double* normal);
    // x ← S x in place.
    void apply(double* x) const;
};

struct SolveStatus {
    bool converged = false;
    int iterations = 0;
    double residual = 0.0; // ‖Â y − r‖ / ‖r‖ of the filtered system
    bool failed = false;   // a factorisation failed or a value became non-finite
    int skewFallbacks = 0; // skew aerodynamic corrections dropped (Body::solveLinear)
};

enum class LinearSolverKind { Pcg, Direct };

// Multigrid PCG multiplies with a single-precision copy of the matrix at tolerances from this
// one up (and checks the result in double; see FilteredSolver::solvePcgMultigrid).
constexpr double kSinglePrecisionTolerance = 1e-5;

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
    // Multigrid only: the next solves refresh level 0 alone and keep the coarse levels
    // (BlockMultigrid::refresh's keepCoarse) — for solves with the same or a nearby matrix.
    void setKeepCoarse(bool keep) { mKeepCoarse = keep; }
    // PCG stops at ‖r‖ ≤ max(tolerance ‖rhs‖, floor): an absolute floor (the rhs's units, N·s)
    // below which the residual is physically nothing (Body: a tenth of the tolerance of
    // gravity's impulse over the step). 0: relative only.
    void setResidualFloor(double floor) { mResidualFloor = floor; }
    // PCG measures ‖W r‖ against tolerance ‖W rhs‖, W = diag(w) per block row (empty: W = I).
    // A row whose diagonal a stiff term (a soft attachment's h²k) makes 10³× its neighbours'
    // would otherwise own ‖rhs‖, and PCG would stop with the rest of the cloth unsolved: Body
    // gives such rows w = d/(d + h²k), d the row's diagonal without the spring.
    void setResidualWeights(std::vector<double> w) { mWeights = std::move(w); }

    SolveStatus solve(const BlockMatrix& A, const Constraints& c, const VecX& b, VecX& dv,
                      LinearSolverKind kind, double tolerance, int maxIterations);

private:
    SolveStatus solvePcg(const BlockMatrix& A, const Constraints& c, const VecX& rhs, VecX& y,
                         double tolerance, int maxIterations);
    SolveStatus solvePcgMultigrid(const BlockMatrix& A, const Constraints& c, const VecX& rhs, VecX& y,
                                  double tolerance, int maxIterations);
    double multigridCg(VecX& y, double rNorm, double target, bool single, int maxIterations, int& it,
                       SolveStatus& st);
    SolveStatus solveDirect(const BlockMatrix& A, const Constraints& c, const VecX& rhs, VecX& y);
    void applyFiltered(const BlockMatrix& A, const Constraints& c, const VecX& x, VecX& out);

    Preconditioner mPreconditioner = Preconditioner::BlockJacobi;
    bool mKeepCoarse = false;
    double mResidualFloor = 0.0;
    std::vector<double> mWeights; // per block row, natural order (setResidualWeights)
    VecX mW2, mWr;                // w² per row component, in the order the solve runs in; w² r
    // ‖r‖ or, with weights, ‖W r‖ (mW2 set up for the solve's order).
    double residualNorm(const VecX& r);
    void squaredWeights(size_t n3); // mW2 from mWeights, natural order
    BlockMultigrid mMultigrid;
    VecX mTmp2, mR, mZ, mP, mQ;
    VecX mRhsLevel, mYLevel; // multigrid PCG's rhs and y in the multigrid's level-0 order
    std::vector<double> mPartial;
    std::vector<int> mConstrained; // vertices with S ≠ I
    std::vector<Mat3> mPrecond;
    using ColMatrix = BlockMatrix::ScalarMatrix;
    ColMatrix mFilteredA;
    std::unique_ptr<Eigen::SimplicialLDLT<ColMatrix>> mLdlt; // fill-reducing (AMD) order
    // A banded matrix (hair: each vertex coupled to its strand's next two) in its own order: no
    // fill outside the band, no permuted copy of the matrix per factorisation (Eigen's AMD path
    // copies it, permute_symm_to_symm: 8 % of examples/10_hair_turn's time), and only the
    // strands whose filtered values changed refactored (the contact active set's rounds).
    std::unique_ptr<BandedLdlt> mLdltBanded;
    // The banded factor's block rows as last written (values, each vertex's filter kind and
    // plane normal): a round compares against them and rewrites only the strands that changed,
    // from the blocks (no scalar copy of the whole matrix a round).
    bool factorBanded(const BlockMatrix& A, const Constraints& c);
    std::vector<double> mBandValues, mBandNormal;
    std::vector<uint8_t> mBandKind;
    std::vector<char> mBandChanged;
};

} // namespace gale::solver
