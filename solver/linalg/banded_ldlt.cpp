// The banded LDLᵀ of banded_ldlt.h: the band and components from the pattern, a factorisation
// that skips unchanged components, forward and back substitution.
#include "solver/linalg/banded_ldlt.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace gale::solver {

bool BandedLdlt::analyze(const Matrix& A) {
    mN = 0;
    mW = 0;
    mStart.clear();
    mValid.clear();
    if (A.rows() != A.cols()) return false;
    const int n = static_cast<int>(A.rows());
    // reach[j]: the last row of column j's lower part; the band is the widest reach.
    std::vector<int> reach(n);
    int w = 0;
    for (int j = 0; j < n; ++j) {
        reach[j] = j;
        for (Matrix::InnerIterator it(A, j); it; ++it)
            if (it.row() > j) {
                reach[j] = std::max(reach[j], static_cast<int>(it.row()));
                w = std::max(w, static_cast<int>(it.row()) - j);
            }
    }
    // A component ends before row r when no column left of r reaches r.
    mStart.push_back(0);
    int far = -1;
    for (int r = 0; r < n; ++r) {
        if (r > 0 && far < r) mStart.push_back(r);
        far = std::max(far, reach[r]);
    }
    mStart.push_back(n);
    if (n == 0) mStart.assign(1, 0);
    mRowComponent.assign(static_cast<size_t>(n), 0);
    for (size_t c = 0; c + 1 < mStart.size(); ++c)
        std::fill(mRowComponent.begin() + mStart[c], mRowComponent.begin() + mStart[c + 1],
                  static_cast<int>(c));
    mN = n;
    mW = w;
    const size_t size = static_cast<size_t>(n) * (w + 1);
    mA.assign(size, 0.0);
    mNew.assign(size, 0.0);
    mLd.assign(size, 0.0);
    mValid.assign(mStart.size() - 1, 0);
    mSolvedValid.assign(mStart.size() - 1, 0);
    mLastB.setZero(n);
    mLastX.setZero(n);
    return true;
}

bool BandedLdlt::factorComponent(int c) {
    const int b = mStart[c], e = mStart[c + 1];
    const size_t row = static_cast<size_t>(mW) + 1;
    std::vector<double>& t = mScratch; // t_k = L_ik D_k of the row being factored
    t.resize(row);
    for (int i = b; i < e; ++i) {
        const int lo = std::max(b, i - mW), m = i - lo; // row i's band: columns lo .. i
        const double* a = &mA[i * row + (mW - m)];
        double* li = &mLd[i * row + (mW - m)];
        for (int q = 0; q < m; ++q) { // column j = lo + q
            const int j = lo + q;
            // Row j's entries at columns lo .. j − 1 (all within its band: j − w ≤ i − w ≤ lo).
            const double* lj = &mLd[j * row + (mW - (j - lo))];
            double sum = a[q];
            for (int k = 0; k < q; ++k) sum -= t[k] * lj[k];
            t[q] = sum;
            li[q] = sum / mLd[j * row + mW];
        }
        double d = a[m];
        for (int k = 0; k < m; ++k) d -= t[k] * li[k];
        if (!(d > 0.0) || !std::isfinite(d)) return false;
        li[m] = d;
    }
    return true;
}

bool BandedLdlt::factorize(const Matrix& A) {
    mRefactored = 0;
    if (A.rows() != mN || A.cols() != mN) return false;
    std::fill(mNew.begin(), mNew.end(), 0.0);
    for (int j = 0; j < mN; ++j)
        for (Matrix::InnerIterator it(A, j); it; ++it) {
            const int i = static_cast<int>(it.row());
            if (i >= j && i - j <= mW) band(mNew, i, j) = it.value();
        }
    const size_t row = static_cast<size_t>(mW) + 1;
    for (int c = 0; c + 1 < static_cast<int>(mStart.size()); ++c) {
        const size_t from = mStart[c] * row, count = (mStart[c + 1] - mStart[c]) * row;
        if (mValid[c] && std::memcmp(&mA[from], &mNew[from], count * sizeof(double)) == 0) continue;
        std::copy(mNew.begin() + from, mNew.begin() + from + count, mA.begin() + from);
        if (!refactorComponent(c)) return false;
    }
    return true;
}

bool BandedLdlt::refactorComponent(int c) {
    ++mRefactored;
    mSolvedValid[c] = 0;
    if (!factorComponent(c)) {
        std::fill(mValid.begin(), mValid.end(), 0);
        std::fill(mSolvedValid.begin(), mSolvedValid.end(), 0);
        return false;
    }
    mValid[c] = 1;
    return true;
}

bool BandedLdlt::refactor(const std::vector<char>& changed, const std::function<void(int)>& fill) {
    mRefactored = 0;
    const size_t row = static_cast<size_t>(mW) + 1;
    for (int c = 0; c + 1 < static_cast<int>(mStart.size()); ++c) {
        if (mValid[c] && !changed[static_cast<size_t>(c)]) continue;
        std::fill(mA.begin() + mStart[c] * row, mA.begin() + mStart[c + 1] * row, 0.0);
        fill(c);
        if (!refactorComponent(c)) return false;
    }
    return true;
}

void BandedLdlt::solveComponent(int c, double* x) const {
    const int b = mStart[c], e = mStart[c + 1];
    const size_t row = static_cast<size_t>(mW) + 1;
    // L y = b, D z = y, Lᵀ x = z, within rows [b, e) (no entry couples them to another).
    for (int i = b; i < e; ++i) {
        const int m = std::min(i - b, mW);
        const double* li = &mLd[i * row + (mW - m)];
        const double* xi = x + (i - m);
        double s = x[i];
        for (int k = 0; k < m; ++k) s -= li[k] * xi[k];
        x[i] = s;
    }
    for (int i = b; i < e; ++i) x[i] /= mLd[i * row + mW];
    // Lᵀ: column i of L is spread over rows i + 1 .. i + w; scattered from each row instead.
    for (int i = e - 1; i >= b; --i) {
        const int m = std::min(i - b, mW);
        const double* li = &mLd[i * row + (mW - m)];
        double* xi = x + (i - m);
        const double v = x[i];
        for (int k = 0; k < m; ++k) xi[k] -= li[k] * v;
    }
}

void BandedLdlt::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    mSolved = 0;
    for (int c = 0; c + 1 < static_cast<int>(mStart.size()); ++c) {
        const int from = mStart[c], count = mStart[c + 1] - mStart[c];
        const size_t bytes = static_cast<size_t>(count) * sizeof(double);
        if (mSolvedValid[c] && std::memcmp(&mLastB[from], &b[from], bytes) == 0) continue;
        std::memcpy(&mLastB[from], &b[from], bytes);
        std::memcpy(&mLastX[from], &b[from], bytes);
        solveComponent(c, mLastX.data());
        mSolvedValid[c] = 1;
        ++mSolved;
    }
    x = mLastX;
}

} // namespace gale::solver
