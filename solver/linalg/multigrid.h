// An aggregation algebraic-multigrid preconditioner for the filtered 3×3-block cloth system
// (Tamstorf, Jones, McCormick 2015), applied as one symmetric V-cycle per CG iteration, and the
// block-CSR (BSR) copy of the filtered matrix Â that the multigrid CG multiplies with.
#pragma once

#include "solver/linalg/bsr_kernels.h"
#include "solver/linalg/types.h"

#include <Eigen/Cholesky>

#include <cstdint>
#include <vector>

namespace gale::solver {

class BlockMatrix;
struct Constraints;

// How the filtered system is preconditioned inside conjugate gradient.
enum class Preconditioner { BlockJacobi, Multigrid };

// A symmetric 3×3-block sparse matrix in block CSR: block k of row i is val[9k .. 9k+8],
// column-major, column cols[k]; columns sorted, the diagonal present; val ends in kBsrPad
// zeros (bsr_kernels.h).
struct BsrMatrix {
    int n = 0;
    std::vector<int> start, cols, diag, mirror; // mirror[k]: slot of the transposed block
    std::vector<double> val;

    int blocks() const { return static_cast<int>(cols.size()); }
    BsrPattern pattern() const { return {start.data(), cols.data(), diag.data(), n}; }
    // y = M x, parallel over rows (deterministic: each row is summed in column order).
    void multiply(const double* x, double* y) const;
    // y = M x and returns xᵀy, summed in chunks of kReduceChunk entries like deterministicDot
    // (same bits; one pass over x and y instead of two). `partial` is scratch.
    // With `single` (these values in float), the product reads those instead of val.
    double multiplyDot(const double* x, double* y, std::vector<double>& partial, const float* single = nullptr) const;
};

// Plain (unsmoothed) aggregation AMG with a constraint-filtered tentative prolongator:
//   P₀ = S P_tent,  P_tent(i, I) = I₃ when vertex i is in aggregate I  (translations: the
// near-null space of the membrane stiffness), so the Galerkin operators
//   A_{l+1} = P_lᵀ A_l P_l
// are sums of the fine blocks and the coarse levels never see the constrained directions
// (Tamstorf et al. 2015, §4). Aggregates (Vaněk, Mandel, Brezina 1996: a root plus its
// neighbours, then the rest joined to a neighbouring aggregate) are chosen once per matrix
// pattern, from the pattern alone; every later refresh only re-sums the values.
// The V-cycle uses damped block-Jacobi smoothing (ν sweeps before and the same after) or a
// forward/backward multicolour block Gauss–Seidel pair, and a dense Cholesky on the coarsest
// level, so the preconditioner is symmetric positive definite.
//
// Multicolour ordering (Adams 2001, "A distributed memory unstructured Gauss–Seidel algorithm
// for multigrid smoothers"; Saad, "Iterative Methods for Sparse Linear Systems" §12.4, here
// by blocks of rows): each level's rows, in natural order, are cut into blocks of
// Settings::rowBlock, the blocks coloured greedily in block order so that no two blocks of a
// colour are coupled, and the level is stored renumbered colour by colour (blocks and rows in
// natural order within a colour). Gauss–Seidel in that row order is lexicographic inside a
// block and multicolour between blocks: the blocks of one colour read only the other colours'
// x, so they are swept in parallel and the result is the same bits on any number of threads
// (and the same as the one sequential sweep small levels take). The backward sweep visits the
// colours in reverse, each block backwards: it stays the exact adjoint of the forward one.
// Whole blocks keep the natural order's memory locality and most of its coupling, so the
// smoother is nearly as strong as the lexicographic one (bench/README.md). Aggregation visits
// the rows in their natural order, so the renumbering does not change the aggregates. Vectors
// passed to apply, multiply and
// multiplyDot are in this level-0 order (toLevelOrder / fromLevelOrder). The smoother reads a
// single-precision copy of each level's matrix (half the memory traffic; the V-cycle only
// approximates Â⁻¹ anyway), while conjugate gradient multiplies with Â in double precision.
class BlockMultigrid {
public:
    struct Settings {
        bool gaussSeidel = true;    // symmetric block Gauss–Seidel, else damped block Jacobi
        int sweeps = 1;             // smoothing sweeps before and after the coarse correction
        double jacobiWeight = 0.6;  // ω of damped block Jacobi
        double coarseWeight = 1.0;  // α: x += α P e (over-correction for plain aggregation)
        int coarsest = 48;          // stop coarsening at this many block rows
        int parallelRows = 1024;    // levels with fewer rows sweep sequentially (the same bits)
        int rowBlock = 128;         // rows per block of the multicolour ordering
        bool multicolour = true;    // false: the natural row order, lexicographic Gauss–Seidel,
                                    // always sequential (the benchmark's baseline)
    };

    // The settings new instances start with (process-wide, like setWideKernels: change them
    // only while no solver is being built; the benchmark compares orderings with it).
    static Settings& defaults();

    Settings& settings() { return mSettings; }

    // Builds Â = S A S + I − S into level 0 and the coarse operators; aggregates and colours are
    // built when the pattern of A is new. `constrained` lists A's rows with S ≠ I. Returns false
    // when a value is not finite.
    bool refresh(const BlockMatrix& A, const Constraints& c, const std::vector<int>& constrained);
    // 3n vectors from A's vertex order to level 0's colour order and back.
    void toLevelOrder(const double* natural, double* level) const;
    void fromLevelOrder(const double* level, double* natural) const;
    // A level's matrix (in its colour order) and its multicolour ordering (its order lists the
    // natural index of each row).
    const BsrMatrix& matrix(int level) const { return mLevels[level].a; }
    const ColouredBlocks& colouring(int level) const { return mLevels[level].colouring; }
    // z = B r with B ≈ Â⁻¹ symmetric positive definite (one V-cycle from zero, written into z
    // directly; z must not overlap r); returns rᵀz (deterministicDot).
    double apply(const double* r, double* z);
    // y = Â x with the level-0 copy.
    void multiply(const double* x, double* y) const { mLevels[0].a.multiply(x, y); }
    // y = Â x and returns xᵀÂx (deterministicDot's summation order); `single`: with the
    // single-precision copy of Â (half the memory traffic; see FilteredSolver::solvePcgMultigrid).
    double multiplyDot(const double* x, double* y, bool single) {
        return mLevels[0].a.multiplyDot(x, y, mPartial, single ? mLevels[0].lowVal.data() : nullptr);
    }

    int levelCount() const { return static_cast<int>(mLevels.size()); }
    int rows(int level) const { return mLevels[level].a.n; }

private:
    struct Level {
        BsrMatrix a;
        std::vector<float> lowVal;     // a.val in single precision, read by the smoother
        std::vector<double> dinv;      // 9 per row: inverse diagonal block
        std::vector<int> agg;          // aggregate (row of the next level) per row
        std::vector<int> memberStart, members; // rows of each aggregate
        std::vector<int> coarseSlot;   // slot of the next level's matrix per slot
        std::vector<int> gatherStart,
            gather;                    // per slot of the next level: the slots summed into it
        ColouredBlocks colouring;      // order[p]: the natural index of row p (types.h)
        std::vector<int> visit;        // row of each natural index (the aggregation's order)
        std::vector<double> r, x, t;   // 3n work vectors
        const double* rp = nullptr;    // the r and x in use: r, x, or at level 0 apply's
        double* xp = nullptr;
    };

    void buildHierarchy(const BlockMatrix& A);
    void aggregate(Level& fine, Level& coarse);
    void coarsen(int l);
    // residual: (forward from zero only) also leave t = r − A x in L.t — or, after a parallel
    // sweep, return true: t is then to be pulled row by row (bsrUpperResidualRows).
    bool smooth(int l, bool forward, bool fromZero, bool residual = false);
    void cycle(int l);

    Settings mSettings = defaults();
    std::vector<Level> mLevels;
    int mPatternRows = -1, mPatternSlots = -1;
    std::vector<double> mPartial; // chunk sums of the fused dot products
    std::vector<int> mOrder;      // A's row of each level-0 row
    std::vector<int> mSrcSlot;    // A's slot of each level-0 slot
    std::vector<uint8_t> mKind; // level-0 filter kind per row (0 free, 1 full, 2 plane)
    std::vector<double> mNormal;
    Eigen::LLT<Eigen::MatrixXd> mCoarseLlt;
    Eigen::MatrixXd mCoarseDense;
    bool mCoarseOk = false;
};

} // namespace gale::solver
