// A banded LDLᵀ factorisation of a symmetric positive definite sparse matrix in its natural
// order (hair: each strand a band, strands uncoupled), refactorising only the independent
// diagonal blocks whose values changed since the last factorisation.
#pragma once

#include <Eigen/SparseCore>

#include <functional>
#include <vector>

namespace gale::solver {

// For A with half-bandwidth w (A_ij = 0 when |i − j| > w), A = L D Lᵀ, L unit lower triangular
// with the same band, D diagonal (Golub & Van Loan, "Matrix Computations", 4th ed., §4.3.5:
// band Cholesky; here its LDLᵀ form, no square roots), row by row:
//   L_ij = (A_ij − Σ_{k<j} L_ik D_k L_jk) / D_j     (i − w ≤ j < i)
//   D_i  =  A_ii − Σ_{k<i} L_ik² D_k
// with k over the band only, in O(n w²) operations. The rows split into components: ranges
// [b, e) with no entry coupling them to another (a strand of hair). A component's factor
// depends on its own values only, so a factorisation after a change in a few components (the
// contact active set's rounds: a vertex's filter changed) recomputes those and keeps the others,
// the same bits as a full factorisation; and a solve after such a change substitutes again
// only in the components whose factor or right-hand side changed since the last solve.
class BandedLdlt {
public:
    using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;

    // The band and the components of A's pattern (symmetric; its lower triangle is read).
    // Returns false when A is not square. Forgets any factor.
    bool analyze(const Matrix& A);
    int halfBandwidth() const { return mW; }
    int components() const { return static_cast<int>(mStart.size()) - 1; }

    // Factors A (the analysed pattern, any values): the components whose values differ from the
    // last successful factorisation's. False when a pivot D_i is not positive and finite (A not
    // SPD, or not finite): nothing is then kept and the next call factors every component.
    bool factorize(const Matrix& A);
    // Components refactored by the last factorize() or refactor().
    int lastRefactored() const { return mRefactored; }

    // The same factorisation when the caller knows which components changed (the matrix held
    // in another form: FilteredSolver's block rows): for each component c marked in `changed`,
    // or without a valid factor, its rows are zeroed, fill(c) writes its lower band with set(),
    // and it is factored; the others keep their factor. False as factorize().
    bool refactor(const std::vector<char>& changed, const std::function<void(int)>& fill);
    // A_ij during refactor()'s fill: i ≥ j, i − j ≤ halfBandwidth(), both in the component.
    void set(int i, int j, double value) { band(mA, i, j) = value; }
    // The component of row i, and a component's rows [first, last).
    int componentOf(int i) const { return mRowComponent[static_cast<size_t>(i)]; }
    int firstRow(int c) const { return mStart[static_cast<size_t>(c)]; }
    int endRow(int c) const { return mStart[static_cast<size_t>(c) + 1]; }

    // x = A⁻¹ b with the last factor (b and x may be the same vector). A component whose factor
    // and b are those of the last solve takes that solve's x (the same bits).
    void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);
    // Components substituted by the last solve().
    int lastSolved() const { return mSolved; }

private:
    // Band storage: row i's entries A_i,i−w .. A_ii at mA[i (w + 1) + (j − i + w)]; the same
    // layout holds L (strictly lower part) and D (the diagonal slot).
    double& band(std::vector<double>& v, int i, int j) const {
        return v[static_cast<size_t>(i) * (mW + 1) + (j - i + mW)];
    }
    bool factorComponent(int c);
    // Component c's factor from mA, counted; on failure every factor is forgotten (false).
    bool refactorComponent(int c);
    void solveComponent(int c, double* x) const; // in place: b in, A⁻¹ b out

    int mN = 0, mW = 0;
    std::vector<int> mStart;  // component c is rows [mStart[c], mStart[c + 1])
    std::vector<int> mRowComponent; // per row, its component
    std::vector<double> mA;   // A's band as last factored
    std::vector<double> mNew; // the band of the A being factored (scratch)
    std::vector<double> mLd;  // the factor: L below the diagonal, D on it
    std::vector<char> mValid; // per component: mLd holds its factor of mA
    std::vector<double> mScratch;
    int mRefactored = 0;
    // The last solve: its b and x, and per component whether they belong to the current factor.
    Eigen::VectorXd mLastB, mLastX;
    std::vector<char> mSolvedValid;
    int mSolved = 0;
};

} // namespace gale::solver
