// An aggregation algebraic-multigrid preconditioner for the filtered 3×3-block cloth system
// (Tamstorf, Jones, McCormick 2015), applied as one symmetric V-cycle per CG iteration, and the
// block-CSR (BSR) copy of the filtered matrix Â that the multigrid CG multiplies with.
#pragma once

#include "solver/linalg/bsr_kernels.h"
#include "solver/linalg/prolongator.h"
#include "solver/linalg/types.h"

#include <Eigen/Cholesky>

#include <cstdint>
#include <vector>

namespace gale::solver {

class BlockMatrix;
struct Constraints;

// How the filtered system is preconditioned inside conjugate gradient.
enum class Preconditioner { BlockJacobi, Multigrid };
// Which multigrid hierarchy (BlockMultigrid::Settings::smoothed, smoothedMinRows, rotations).
enum class MultigridKind { Automatic, Plain, Smoothed, SmoothedRotations };
// The scene key's value of each kind: "auto", "plain", "smoothed", "smoothed-rotations".
inline const char* multigridKindName(MultigridKind k) {
    return k == MultigridKind::Plain               ? "plain"
           : k == MultigridKind::Smoothed          ? "smoothed"
           : k == MultigridKind::SmoothedRotations ? "smoothed-rotations"
                                                   : "auto";
}

// A symmetric 3×3-block sparse matrix in block CSR: block k of row i is val[9k .. 9k+8],
// column-major, column cols[k]; columns sorted, the diagonal present; val ends in kBsrPad
// zeros (bsr_kernels.h). Values in single precision: the multigrid's levels are read by the
// smoother and the set-up only (conjugate gradient's double-precision products read the
// assembled matrix itself, BlockMultigrid::multiply).
struct BsrMatrix {
    int n = 0;
    std::vector<int> start, cols, diag;
    std::vector<float> val;

    int blocks() const { return static_cast<int>(cols.size()); }
    BsrPattern pattern() const { return {start.data(), cols.data(), diag.data(), n}; }
    // y = M x, parallel over rows (deterministic: each row is summed in column order).
    void multiply(const double* x, double* y) const;
    // y = M x and returns xᵀy, summed in chunks of kReduceChunk entries like deterministicDot
    // (same bits; one pass over x and y instead of two). `partial` is scratch. With `dval`
    // (these blocks in double), the product reads those instead of val.
    double multiplyDot(const double* x, double* y, std::vector<double>& partial,
                       const double* dval = nullptr) const;
};

// Smoothed-aggregation AMG (Vaněk, Mandel, Brezina 1996) for the filtered system
//   Â = S A S + I − S                                        (Tamstorf, Jones, McCormick 2015)
// with a near-null space B of rigid-body modes filtered by the constraints: for vertex i at x_i
// in an aggregate with centroid c,
//   B_i = S_i [ I₃ | −[x_i − c]× / ρ ]   (translations and rotations; ρ the aggregate's radius),
// or the translations S_i alone (the default: Settings::rotations off, or no positions given).
// Per level:
//   P_tent = blockdiag(Q_J),  B_J = Q_J R_J  (orthonormalised on each aggregate J),
//   P = (I − ω D⁻¹ Â) P_tent,  ω = (4/3) / ρ(D⁻¹Â)  (ρ by a few power steps),
//   A_{l+1} = Pᵀ A_l P,   B_{l+1} = R,
// so every level holds 6 unknowns per aggregate (two 3×3 block rows; one with translations
// only). Rows of P lie in range(S_i) by construction (D_i⁻¹ keeps range(S_i)), so the coarse
// levels never see the constrained directions, whatever the per-vertex filter (I, I − nnᵀ, 0).
// Coarse unknowns no mode reaches (a fully pinned aggregate, a straight strand's twist) get an
// identity diagonal and stay zero. Aggregates (a root plus its neighbours, then the rest joined
// to a neighbouring aggregate) are chosen once per matrix pattern, from the pattern alone, on
// the graph of nodes (a coarse node's two block rows aggregate together); every later refresh
// recomputes the values (B, P, ω and the Galerkin products) from the current matrix and
// positions only, so a resumed run builds the same hierarchy bit for bit. With `smoothed` off
// and `rotations` off this is plain aggregation with translations (the benchmark's baseline).
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
// multiplyDot are in this level-0 order (toLevelOrder / fromLevelOrder).
//
// Memory (bench/README.md, issue 26 fourth pass): with smoothed aggregation every level and
// the prolongators are held in single precision only (half the memory traffic; the V-cycle only
// approximates Â⁻¹ anyway; the set-up reads them and sums in double). Conjugate gradient's
// double-precision products (multiply, multiplyDot without `single`) read the assembled A
// itself through the level-0 slot map, filtering on the fly, so no double copy of Â is held.
// The near-null space and the tentative prolongator are set-up scratch, freed by refresh.
// Plain aggregation (small meshes) keeps its levels in double too, as before, so that its
// results stay those of the path before issue 26 bit for bit.
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
        // Smoothed aggregation with the rigid-body near-null space from this many block rows
        // of A up; below (and with `smoothed` off) plain aggregation with translations,
        // P = S P_tent, bit for bit the path before issue 26: its set-up is cheap and on small
        // meshes costs less than the iterations smoothing saves (bench/README.md, crossover).
        bool smoothed = true;
        int smoothedMinRows = 12000;
        // Rotations in the near-null space (when positions are set). Off by default: with the
        // translations alone the counts stay as bounded from 32² to 256² (grid, 1/24 s: 8, 9,
        // 11, 11 against 6, 7, 9, 9), the hierarchy holds 655 B/vertex instead of 1054 and
        // the wind-onset flag's 256² frame costs 0.37 s instead of 0.62 (bench/README.md,
        // "Smoothed aggregation with translations only").
        bool rotations = false;
        // K-cycle (Notay & Vassilevski 2008): each coarse level but the last solved by two
        // steps of flexible CG preconditioned by its own cycle, instead of one cycle. The
        // preconditioner is then not a fixed linear map: CG uses the flexible (Polak–Ribière) β.
        // On with the rotations (setKind): a slack cloth's plate-like rows at 256², 81 → 42 CG
        // iterations; on a taut sheet, whose counts were already bounded, it only adds work
        // (bench/README.md, "A K-cycle").
        bool kCycle = false;
        double prolongatorDamping = 4.0 / 3.0; // ω ρ(D⁻¹Â)
        int powerIterations = 8;    // power steps of the ρ(D⁻¹Â) estimate
    };

    // The settings new instances start with (process-wide, like setWideKernels: change them
    // only while no solver is being built; the benchmark compares orderings with it).
    static Settings& defaults();

    Settings& settings() { return mSettings; }
    // Sets smoothed, smoothedMinRows, rotations and kCycle for `kind` (Automatic: the defaults'
    // threshold; SmoothedRotations: smoothed at every size with the rotations and the K-cycle).
    void setKind(MultigridKind kind) {
        mSettings.smoothed = kind != MultigridKind::Plain;
        mSettings.smoothedMinRows = kind == MultigridKind::Automatic ? defaults().smoothedMinRows : 0;
        mSettings.rotations = kind == MultigridKind::SmoothedRotations || defaults().rotations;
        mSettings.kCycle = kind == MultigridKind::SmoothedRotations || defaults().kCycle;
    }

    // Vertex positions (m, 3 per vertex of A, A's order) for the rotations of the near-null
    // space; copied when Settings::rotations is on (set it first), else dropped. Without them
    // (or with another count) the near-null space is translations.
    void setPositions(const double* x, int n) {
        if (mSettings.rotations)
            mPositions.assign(x, x + 3 * static_cast<size_t>(n));
        else
            std::vector<double>().swap(mPositions);
    }

    // Builds Â = S A S + I − S into level 0 and the coarse operators; aggregates and colours are
    // built when the pattern of A is new. `constrained` lists A's rows with S ≠ I. Returns false
    // when a value is not finite. A and c must stay alive and unchanged while the products
    // below (multiply, multiplyDot in double) are used: they read them.
    // keepCoarse: only level 0 takes A's values; the coarse levels and prolongators stay those
    // of the last full refresh (still an SPD preconditioner, for a matrix that changed little:
    // Newton's iterates, GMRES's repeated solves with one matrix). Ignored when the pattern
    // or the constrained rows changed.
    bool refresh(const BlockMatrix& A, const Constraints& c, const std::vector<int>& constrained,
                 bool keepCoarse = false);
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
    // y = Â x in double precision: A's values (the last refresh's A) read through the level-0
    // slot map, Â = S A S + I − S applied on the fly; each row summed in level-0 column order.
    void multiply(const double* x, double* y) const;
    // y = Â x and returns xᵀÂx (deterministicDot's summation order); `single`: with level 0's
    // single-precision Â (half the memory traffic; see FilteredSolver::solvePcgMultigrid),
    // else as multiply.
    double multiplyDot(const double* x, double* y, bool single);

    int levelCount() const { return static_cast<int>(mLevels.size()); }
    int rows(int level) const { return mLevels[level].a.n; }
    // Near-null modes per node of the coarse levels (6 with rotations, else 3).
    int modes() const { return mModes; }
    // The hierarchy in use is plain aggregation (Settings::smoothed, smoothedMinRows).
    bool plain() const { return mPlain; }
    // Bytes held by the hierarchy between solves (matrices, prolongators, maps, work vectors);
    // peakBytes: the most held during the last refresh, its scratch included.
    size_t bytes() const;
    size_t peakBytes() const { return mPeakBytes; }

private:
    struct Level {
        BsrMatrix a;                   // in single precision (the smoother's and set-up's copy)
        std::vector<double> dval;      // plain aggregation only: a's values in double, summed
                                       // into the next level and read by CG's double products
                                       // (the path before issue 26, kept bit for bit)
        std::vector<double> dinv;      // 9 per row: inverse diagonal block (+ kBsrPad), double: the
                                       // sweep then solves its row to rounding, as the fused
                                       // residual assumes (the V-cycle stays symmetric)
        ColouredBlocks colouring;      // order[p]: the natural index of row p (types.h)
        std::vector<int> visit;        // row of each natural index (the aggregation's order)
        std::vector<uint8_t> dead;     // per scalar unknown: no mode reaches it (coarse levels)
        std::vector<int> graphStart, graphCols; // node graph (colour-order nodes) to aggregate
                                                // (only while the next level's pattern is built)
        Aggregates agg;                // nodes of this level → nodes of the next (agg.d: rows per node)
        BlockProlongator P;            // to the next level
        // Plain aggregation only (aggregatePlain): the aggregate of each row, the rows of each
        // aggregate, the next level's slot of each slot and its inverse (the slots summed).
        std::vector<int> plainAgg, plainStart, plainMembers, coarseSlot, gatherStart, gather;
        std::vector<double> r, x, t;   // 3n work vectors (level 0: t only)
        std::vector<double> kr, kc, kv, kw; // K-cycle work vectors (coarse levels, kCycle)
        const double* rp = nullptr;    // the r and x in use: r, x, or at level 0 apply's
        double* xp = nullptr;
    };

    void buildHierarchy(const BlockMatrix& A);
    bool buildCoarse(int l); // false: coarsening stalls
    void levelZeroNullSpace(std::vector<double>& B) const;
    Mat3 levelZeroBlock(int i, int k) const; // block k of level-0 row i of Â in double
    void coarsenValues(int l, std::vector<double>& fineB, std::vector<double>& coarseB,
                       std::vector<double>& Q);
    void aggregatePlain(Level& fine, Level& coarse);
    void coarsenPlain(int l);
    void finishLevel(int l);
    // residual: (forward from zero only) return true: t = r − A x is then to be pulled into L.t
    // row by row (bsrUpperResidualRows; no slot map of transposed blocks is kept to push it).
    bool smooth(int l, bool forward, bool fromZero, bool residual = false);
    void cycle(int l);
    void coarseCycle(int c); // level c's correction from its r: one cycle, or the K-cycle's two
    void cyclePlainCoarse(int l, bool pull);

    Settings mSettings = defaults();
    std::vector<Level> mLevels;
    int mPatternRows = -1, mPatternSlots = -1;
    std::vector<double> mPartial; // chunk sums of the fused dot products
    const std::vector<int>& order() const {
        return mLevels[0].colouring.order;
    }                             // A's row of each level-0 row
    std::vector<int> mSrcSlot;    // A's slot of each level-0 slot
    std::vector<uint8_t> mKind; // level-0 filter kind per row (0 free, 1 full, 2 plane)
    std::vector<double> mNormal;         // 3 per mConstrainedRows entry
    const double* normalOf(int i) const; // the plane normal of level-0 row i (kind 2)
    std::vector<double> mPositions; // A's order, for the rotations
    const BlockMatrix* mSource = nullptr; // the last refresh's A (multiply in double)
    std::vector<int> mConstrainedRows;    // level-0 rows with S ≠ I, increasing
    size_t mPeakBytes = 0;
    int mModes = 3;
    bool mPlain = false;
    bool mHaveCoarse = false; // the coarse levels hold values (keepCoarse may reuse them)
    Eigen::LLT<Eigen::MatrixXd> mCoarseLlt;
    Eigen::MatrixXd mCoarseDense;
    bool mCoarseOk = false;
};

} // namespace gale::solver
