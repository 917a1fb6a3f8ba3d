// Block-sparse matrix, Baraff–Witkin constraint filter, PCG and LDLᵀ solves (see linear.h).
#include "solver/linalg/linear.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace gale::solver {

// ---------------------------------------------------------------------------------------------
// BlockMatrix

void BlockMatrix::build(int n, const std::vector<std::pair<int, int>>& pairs) {
    mN = n;
    std::vector<std::vector<int>> rows(n);
    for (int i = 0; i < n; ++i) rows[i].push_back(i);
    for (const auto& p : pairs) {
        if (p.first == p.second) continue;
        rows[p.first].push_back(p.second);
        rows[p.second].push_back(p.first);
    }
    mBlockRowStart.assign(n + 1, 0);
    mBlockCols.clear();
    for (int i = 0; i < n; ++i) {
        std::sort(rows[i].begin(), rows[i].end());
        rows[i].erase(std::unique(rows[i].begin(), rows[i].end()), rows[i].end());
        mBlockRowStart[i + 1] = mBlockRowStart[i] + static_cast<int>(rows[i].size());
        mBlockCols.insert(mBlockCols.end(), rows[i].begin(), rows[i].end());
    }
    mVal.assign(9 * mBlockCols.size() + kBsrPad, 0.0);
    mDiagSlot.assign(n, -1);
    mMirror.resize(mBlockCols.size());
    for (int i = 0; i < n; ++i)
        for (int k = mBlockRowStart[i]; k < mBlockRowStart[i + 1]; ++k) {
            if (mBlockCols[k] == i) mDiagSlot[i] = k;
            mMirror[k] = slot(mBlockCols[k], i);
        }
}

int BlockMatrix::slot(int i, int j) const {
    auto b = mBlockCols.begin() + mBlockRowStart[i], e = mBlockCols.begin() + mBlockRowStart[i + 1];
    auto it = std::lower_bound(b, e, j);
    return (it != e && *it == j) ? static_cast<int>(it - mBlockCols.begin()) : -1;
}

// In parallel pieces of 32768 values (256 KB): a 64×64 cloth's matrix is ~4 MB, zeroed every
// substep, memory-bound, and was the largest serial loop of a 2-thread step (bench/README.md).
// Zeros are the same bits whoever writes them.
void BlockMatrix::setZero() {
    parallelChunks(mVal.size(), 32768, [&](size_t b, size_t e) {
        std::memset(mVal.data() + b, 0, (e - b) * sizeof(double));
    });
}

void BlockMatrix::multiply(const double* x, double* y) const {
    const BsrPattern p = pattern();
    parallelChunks(static_cast<size_t>(mN), 512,
                   [&](size_t i0, size_t i1) { bsrMultiplyRows(p, mVal.data(), x, y, i0, i1); });
}

void BlockMatrix::toScalar(ScalarMatrix& out) const {
    // Column 3j+a lists, for each block (i, j) of block column j — the blocks of block row j,
    // the pattern being symmetric — the rows 3i .. 3i+2: entry (3i+r, 3j+a) is
    // values[9·slot(i, j) + 3a + r].
    const long nnz = 9 * static_cast<long>(mBlockCols.size());
    if (out.rows() != 3 * mN || out.cols() != 3 * mN || out.nonZeros() != nnz) {
        out = ScalarMatrix(3 * mN, 3 * mN);
        out.resizeNonZeros(nnz);
        int* outer = out.outerIndexPtr();
        int* inner = out.innerIndexPtr();
        int pos = 0;
        for (int j = 0; j < mN; ++j)
            for (int a = 0; a < 3; ++a) {
                outer[3 * j + a] = pos;
                for (int k = mBlockRowStart[j]; k < mBlockRowStart[j + 1]; ++k)
                    for (int r = 0; r < 3; ++r) inner[pos++] = 3 * mBlockCols[k] + r;
            }
        outer[3 * mN] = pos;
    }
    double* v = out.valuePtr();
    for (int j = 0; j < mN; ++j)
        for (int a = 0; a < 3; ++a)
            for (int k = mBlockRowStart[j]; k < mBlockRowStart[j + 1]; ++k) {
                const double* b = mVal.data() + 9 * static_cast<size_t>(mMirror[k]) + 3 * a;
                *v++ = b[0];
                *v++ = b[1];
                *v++ = b[2];
            }
}

// ---------------------------------------------------------------------------------------------
// Constraints

bool Constraints::any() const {
    for (uint8_t k : kind)
        if (k) return true;
    return false;
}

Mat3 Constraints::filterOf(uint8_t kind, const double* normal) {
    switch (kind) {
    case 1:
        return Mat3::Zero();
    case 2: {
        const Vec3 n(normal[0], normal[1], normal[2]);
        return Mat3::Identity() - n * n.transpose();
    }
    default:
        return Mat3::Identity();
    }
}

void Constraints::apply(double* x) const {
    for (size_t i = 0; i < kind.size(); ++i) {
        if (kind[i] == 1) {
            x[3 * i] = x[3 * i + 1] = x[3 * i + 2] = 0.0;
        } else if (kind[i] == 2) {
            const Vec3 n = vec3At(normal.data(), i);
            Eigen::Map<Vec3> xi(x + 3 * i);
            xi -= n.dot(xi) * n;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// FilteredSolver

namespace {
// A right-hand side that needs no iterations: non-finite (failed) or zero (y = 0, converged).
bool trivialRhs(double rhsNorm, VecX& y, SolveStatus& st) {
    if (!std::isfinite(rhsNorm)) {
        st.failed = true;
        return true;
    }
    if (rhsNorm == 0.0) {
        y.setZero();
        st.converged = true;
        return true;
    }
    return false;
}
} // namespace

void FilteredSolver::applyFiltered(const BlockMatrix& A, const Constraints& c, const VecX& x,
                                   VecX& out) {
    // Â x = S A S x + (I − S) x; S = I except at the constrained vertices (mConstrained).
    if (mConstrained.empty()) {
        A.multiply(x.data(), out.data());
        return;
    }
    mTmp2 = x;
    for (int i : mConstrained) {
        Eigen::Map<Vec3> t(mTmp2.data() + 3 * i);
        if (c.kind[i] == 1) t.setZero();
        else {
            const Vec3 n = vec3At(c.normal.data(), i);
            t -= n.dot(t) * n;
        }
    }
    A.multiply(mTmp2.data(), out.data());
    for (int i : mConstrained) {
        Eigen::Map<Vec3> o(out.data() + 3 * i);
        const Eigen::Map<const Vec3> xi(x.data() + 3 * i);
        if (c.kind[i] == 1) o = xi;
        else {
            const Vec3 n = vec3At(c.normal.data(), i);
            o -= n.dot(o) * n;
            o += n.dot(xi) * n;
        }
    }
}

SolveStatus FilteredSolver::solve(const BlockMatrix& A, const Constraints& c, const VecX& b, VecX& dv,
                                  LinearSolverKind kind, double tolerance, int maxIterations) {
    const int n3 = 3 * A.size();
    if (dv.size() != n3) dv = VecX::Zero(n3);
    mConstrained.clear();
    for (size_t i = 0; i < c.kind.size(); ++i)
        if (c.kind[i]) mConstrained.push_back(static_cast<int>(i));
    // rhs = S (b − A z); initial y = S dv. z is zero but at the constrained vertices, so A z
    // is a sum over their block columns (A_ij = (A_ji)ᵀ: the mirror of row j's blocks).
    VecX z = VecX::Zero(n3);
    if (!c.z.empty()) z = Eigen::Map<const VecX>(c.z.data(), n3);
    VecX rhs = b;
    for (int j : mConstrained) {
        const Vec3 zj = z.segment<3>(3 * j);
        if (zj.isZero(0.0)) continue;
        for (int k = A.blockRowStart()[j]; k < A.blockRowStart()[j + 1]; ++k)
            rhs.segment<3>(3 * A.blockCols()[k]) -= A.block(A.mirrorSlot(k)) * zj;
    }
    c.apply(rhs.data());
    VecX y = dv;
    c.apply(y.data());
    SolveStatus st = kind == LinearSolverKind::Direct ? solveDirect(A, c, rhs, y)
                     : mPreconditioner == Preconditioner::Multigrid
                         ? solvePcgMultigrid(A, c, rhs, y, tolerance, maxIterations)
                         : solvePcg(A, c, rhs, y, tolerance, maxIterations);
    c.apply(y.data());
    dv = y + z;
    if (!dv.allFinite()) {
        st.failed = true;
        st.converged = false;
    }
    return st;
}

void FilteredSolver::squaredWeights(size_t n3) {
    mW2.resize(mWeights.empty() ? 0 : static_cast<long>(n3));
    for (long k = 0; k < mW2.size(); ++k) mW2[k] = mWeights[k / 3] * mWeights[k / 3];
}

double FilteredSolver::residualNorm(const VecX& r) {
    const size_t n3 = static_cast<size_t>(r.size());
    if (mW2.size() == 0) return std::sqrt(deterministicDot(r.data(), r.data(), n3));
    mWr = mW2.cwiseProduct(r); // rᵀ(w² r)
    return std::sqrt(deterministicDot(mWr.data(), r.data(), n3));
}

SolveStatus FilteredSolver::solvePcg(const BlockMatrix& A, const Constraints& c, const VecX& rhs,
                                     VecX& y, double tolerance, int maxIterations) {
    SolveStatus st;
    const int n = A.size();
    const size_t n3 = 3 * static_cast<size_t>(n);
    // 3×3 block-Jacobi preconditioner of Â: (S_i A_ii S_i + I − S_i)⁻¹.
    mPrecond.resize(n);
    for (int i = 0; i < n; ++i) {
        Mat3 d = A.block(A.diagonalSlot(i));
        if (!c.kind.empty() && c.kind[i]) {
            const Mat3 S = c.filter(i);
            d = S * d * S + (Mat3::Identity() - S);
        }
        mPrecond[i] = invertBlockOrScale(d);
    }
    auto precondition = [&](const VecX& r, VecX& out) {
        parallelChunks(static_cast<size_t>(n), 512, [&](size_t i0, size_t i1) {
            for (size_t i = i0; i < i1; ++i)
                out.segment<3>(3 * i).noalias() = mPrecond[i] * r.segment<3>(3 * i);
        });
    };
    squaredWeights(n3);
    const double rhsNorm = residualNorm(rhs);
    if (trivialRhs(rhsNorm, y, st)) return st;
    mR.resize(n3);
    mZ.resize(n3);
    mP.resize(n3);
    mQ.resize(n3);
    applyFiltered(A, c, y, mQ);
    mR = rhs - mQ;
    double rNorm = residualNorm(mR);
    const double target = std::max(tolerance * rhsNorm, mResidualFloor);
    if (rNorm <= target) {
        st.converged = true;
        st.residual = rNorm / rhsNorm;
        return st;
    }
    precondition(mR, mZ);
    mP = mZ;
    double rz = deterministicDot(mR.data(), mZ.data(), n3);
    // Fused vector updates, each reduction summed in fixed chunks (thread-count independent).
    const size_t chunks = (n3 + kReduceChunk - 1) / kReduceChunk;
    mPartial.assign(2 * chunks, 0.0);
    int it = 0;
    while (it < maxIterations) {
        applyFiltered(A, c, mP, mQ);
        const double pq = deterministicDot(mP.data(), mQ.data(), n3);
        if (!(pq > 0.0) || !std::isfinite(pq)) {
            st.failed = !std::isfinite(pq);
            break;
        }
        const double alpha = rz / pq;
        // y += α p; r −= α q; z = P⁻¹ r; partial sums of r·r and r·z.
        parallelChunks(chunks, 1, [&](size_t c0, size_t c1) {
            for (size_t ch = c0; ch < c1; ++ch) {
                const size_t b = ch * kReduceChunk, e = std::min(n3, b + kReduceChunk);
                double rr = 0.0, rzp = 0.0;
                for (size_t k = b; k < e; ++k) {
                    y[k] += alpha * mP[k];
                    mR[k] -= alpha * mQ[k];
                }
                for (size_t k = b; k < e; k += 3) {
                    const Mat3& P = mPrecond[k / 3];
                    const double r0 = mR[k], r1 = mR[k + 1], r2 = mR[k + 2];
                    const double z0 = P(0, 0) * r0 + P(0, 1) * r1 + P(0, 2) * r2;
                    const double z1 = P(1, 0) * r0 + P(1, 1) * r1 + P(1, 2) * r2;
                    const double z2 = P(2, 0) * r0 + P(2, 1) * r1 + P(2, 2) * r2;
                    mZ[k] = z0;
                    mZ[k + 1] = z1;
                    mZ[k + 2] = z2;
                    rr += mW2.size() == 0
                              ? r0 * r0 + r1 * r1 + r2 * r2
                              : mW2[k] * r0 * r0 + mW2[k + 1] * r1 * r1 + mW2[k + 2] * r2 * r2;
                    rzp += r0 * z0 + r1 * z1 + r2 * z2;
                }
                mPartial[2 * ch] = rr;
                mPartial[2 * ch + 1] = rzp;
            }
        });
        double rr = 0.0, rzNew = 0.0;
        for (size_t ch = 0; ch < chunks; ++ch) {
            rr += mPartial[2 * ch];
            rzNew += mPartial[2 * ch + 1];
        }
        ++it;
        rNorm = std::sqrt(rr);
        if (rNorm <= target || !std::isfinite(rNorm)) break;
        const double beta = rzNew / rz;
        rz = rzNew;
        parallelChunks(n3, kReduceChunk, [&](size_t b, size_t e) {
            for (size_t k = b; k < e; ++k) mP[k] = mZ[k] + beta * mP[k];
        });
    }
    st.iterations = it;
    st.residual = rNorm / rhsNorm;
    st.converged = rNorm <= target;
    if (!std::isfinite(rNorm)) st.failed = true;
    return st;
}

// Multigrid-preconditioned CG iterations on Â y = rhs from the residual in mR (‖mR‖ = rNorm)
// until ‖r‖ ≤ target or `it` reaches maxIterations; returns ‖r‖ (of the products used).
double FilteredSolver::multigridCg(VecX& y, double rNorm, double target, bool single, int maxIterations, int& it,
                                   SolveStatus& st) {
    if (rNorm <= target || !std::isfinite(rNorm)) return rNorm;
    const size_t n3 = static_cast<size_t>(y.size());
    const size_t chunks = (n3 + kReduceChunk - 1) / kReduceChunk;
    mPartial.assign(chunks, 0.0);
    const bool flexible = mMultigrid.settings().kCycle;
    double rz = mMultigrid.apply(mR.data(), mZ.data());
    mP = mZ;
    while (it < maxIterations) {
        const double pq = mMultigrid.multiplyDot(mP.data(), mQ.data(), single); // q = Â p, pᵀq
        if (!(pq > 0.0) || !std::isfinite(pq)) {
            st.failed = !std::isfinite(pq);
            break;
        }
        const double alpha = rz / pq;
        // y += α p; r −= α q; partial sums of r·r.
        parallelChunks(chunks, 1, [&](size_t c0, size_t c1) {
            for (size_t ch = c0; ch < c1; ++ch) {
                const size_t b = ch * kReduceChunk, e = std::min(n3, b + kReduceChunk);
                double rr = 0.0;
                if (mW2.size() == 0) {
                    for (size_t k = b; k < e; ++k) {
                        y[k] += alpha * mP[k];
                        mR[k] -= alpha * mQ[k];
                        rr += mR[k] * mR[k];
                    }
                } else {
                    for (size_t k = b; k < e; ++k) {
                        y[k] += alpha * mP[k];
                        mR[k] -= alpha * mQ[k];
                        rr += mW2[k] * mR[k] * mR[k];
                    }
                }
                mPartial[ch] = rr;
            }
        });
        double rr = 0.0;
        for (size_t ch = 0; ch < chunks; ++ch) rr += mPartial[ch];
        ++it;
        rNorm = std::sqrt(rr);
        if (rNorm <= target || !std::isfinite(rNorm)) break;
        // Flexible CG (Polak–Ribière, β = r_newᵀ(z_new − z_old) / r_oldᵀz_old) when the K-cycle
        // makes the preconditioner depend on r; else Fletcher–Reeves, β = r_newᵀz_new /
        // r_oldᵀz_old.
        const double rzOld = flexible ? deterministicDot(mR.data(), mZ.data(), n3) : 0.0;
        const double rzNew = mMultigrid.apply(mR.data(), mZ.data()); // z = B r, rᵀz
        const double beta = (rzNew - rzOld) / rz;
        rz = rzNew;
        parallelChunks(n3, kReduceChunk, [&](size_t b, size_t e) {
            for (size_t k = b; k < e; ++k) mP[k] = mZ[k] + beta * mP[k];
        });
    }
    return rNorm;
}

// PCG on Â (its BSR copy in the multigrid's level 0) with one symmetric V-cycle as the
// preconditioner; reductions in fixed chunks as above.
//
// Mixed precision: for tolerances ≥ kSinglePrecisionTolerance the products q = Â p read the
// single-precision copy of Â, whose entries differ from Â's by a relative 6e-8 — far below
// the tolerance, as the forward error of stopping at it is cond(Â)·tol. The solution is then
// checked against Â in double (r = rhs − Â y); should that residual miss the tolerance, CG
// restarts from y with double-precision products (residual replacement). The reported
// residual is always the double-precision one.
SolveStatus FilteredSolver::solvePcgMultigrid(const BlockMatrix& A, const Constraints& c,
                                              const VecX& rhsNatural, VecX& yNatural,
                                              double tolerance, int maxIterations) {
    SolveStatus st;
    const size_t n3 = 3 * static_cast<size_t>(A.size());
    squaredWeights(n3);
    const double rhsNorm = residualNorm(rhsNatural);
    if (trivialRhs(rhsNorm, yNatural, st)) return st;
    if (!mMultigrid.refresh(A, c, mConstrained, mKeepCoarse)) {
        st.failed = true;
        return st;
    }
    if (mW2.size() != 0) { // the weights in level order, as CG runs
        VecX natural = mW2;
        mMultigrid.toLevelOrder(natural.data(), mW2.data());
    }
    mR.resize(n3);
    mZ.resize(n3);
    mP.resize(n3);
    mQ.resize(n3);
    // CG runs in the multigrid's level-0 (colour) order: rhs and y permuted in, y out.
    mRhsLevel.resize(n3);
    mYLevel.resize(n3);
    mMultigrid.toLevelOrder(rhsNatural.data(), mRhsLevel.data());
    mMultigrid.toLevelOrder(yNatural.data(), mYLevel.data());
    const VecX& rhs = mRhsLevel;
    VecX& y = mYLevel;
    const double target = std::max(tolerance * rhsNorm, mResidualFloor);
    // r = rhs − Â y (the products in double unless `single`); returns ‖r‖.
    auto residual = [&](bool single) {
        if (single) mMultigrid.multiplyDot(y.data(), mQ.data(), true);
        else mMultigrid.multiply(y.data(), mQ.data());
        mR = rhs - mQ;
        return residualNorm(mR);
    };
    const bool single = tolerance >= kSinglePrecisionTolerance;
    double rNorm = residual(single);
    int it = 0;
    rNorm = multigridCg(y, rNorm, target, single, maxIterations, it, st);
    if (single && !st.failed && std::isfinite(rNorm)) {
        rNorm = residual(false); // the check in double; a miss continues in double
        if (!(rNorm <= target) && it < maxIterations)
            rNorm = multigridCg(y, rNorm, target, false, maxIterations, it, st);
    }
    mMultigrid.fromLevelOrder(y.data(), yNatural.data());
    st.iterations = it;
    st.residual = rNorm / rhsNorm;
    st.converged = rNorm <= target;
    if (!std::isfinite(rNorm)) st.failed = true;
    return st;
}

namespace {
// Block (i, j) of the filtered matrix S A S + I − S: S_i B S_j, plus I − S_j on the diagonal.
Mat3 filteredBlock(const Mat3& B, const Constraints& c, int i, int j) {
    Mat3 F = c.filter(static_cast<size_t>(i)) * B * c.filter(static_cast<size_t>(j));
    if (i == j) F += Mat3::Identity() - c.filter(static_cast<size_t>(j));
    return F;
}
} // namespace

bool FilteredSolver::factorBanded(const BlockMatrix& A, const Constraints& c) {
    // The components (strands) whose block rows changed since the last factorisation: a block's
    // values, or the filter of the row's vertex (a block (i, j) couples i's component only to
    // itself, so j's filter changing marks j's component, which is i's). Their bands are
    // written straight from the blocks, filtered; the others keep their factor.
    const int n = A.size();
    const size_t slots = static_cast<size_t>(A.slotCount());
    const double* val = A.values();
    const std::vector<int>& start = A.blockRowStart();
    const std::vector<int>& cols = A.blockCols();
    const bool constrained = !c.kind.empty() && c.any();
    const auto kindOf = [&](int i) { return constrained ? c.kind[static_cast<size_t>(i)] : 0; };
    const bool fresh =
        mBandValues.size() != 9 * slots || mBandKind.size() != static_cast<size_t>(n);
    mBandChanged.assign(static_cast<size_t>(mLdltBanded->components()), fresh ? 1 : 0);
    mBandValues.resize(9 * slots);
    mBandKind.resize(static_cast<size_t>(n));
    mBandNormal.resize(3 * static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const uint8_t kind = kindOf(i);
        const double* normal = constrained ? c.normal.data() + 3 * i : nullptr;
        const size_t from = 9 * static_cast<size_t>(start[i]);
        const size_t count = 9 * static_cast<size_t>(start[i + 1] - start[i]);
        bool changed = fresh || kind != mBandKind[static_cast<size_t>(i)] ||
                       std::memcmp(val + from, mBandValues.data() + from, count * sizeof(double));
        if (!changed && kind == 2)
            changed = std::memcmp(normal, mBandNormal.data() + 3 * i, 3 * sizeof(double)) != 0;
        if (!changed) continue;
        mBandChanged[static_cast<size_t>(mLdltBanded->componentOf(3 * i))] = 1;
        std::memcpy(mBandValues.data() + from, val + from, count * sizeof(double));
        mBandKind[static_cast<size_t>(i)] = kind;
        if (kind == 2) std::memcpy(mBandNormal.data() + 3 * i, normal, 3 * sizeof(double));
    }
    BandedLdlt& ldlt = *mLdltBanded;
    return ldlt.refactor(mBandChanged, [&](int comp) {
        for (int i = ldlt.firstRow(comp) / 3; i < ldlt.endRow(comp) / 3; ++i)
            for (int k = start[i]; k < start[i + 1] && cols[k] <= i; ++k) {
                const int j = cols[k];
                const Mat3 B = Eigen::Map<const Mat3>(val + 9 * static_cast<size_t>(k));
                const Mat3 F = kindOf(i) || kindOf(j) ? filteredBlock(B, c, i, j) : B;
                for (int r = 0; r < 3; ++r)
                    for (int a = 0; a < 3 && 3 * j + a <= 3 * i + r; ++a)
                        ldlt.set(3 * i + r, 3 * j + a, F(r, a));
            }
    });
}

SolveStatus FilteredSolver::solveDirect(const BlockMatrix& A, const Constraints& c, const VecX& rhs,
                                        VecX& y) {
    SolveStatus st;
    if (mFilteredA.rows() != 3 * A.size() || mFilteredA.nonZeros() != 9L * A.slotCount()) {
        mLdlt.reset();
        mLdltBanded.reset();
        mBandValues.clear();
    }
    // The first solve of a pattern: the scalar matrix (its pattern is what the analyses read),
    // and the factorisation's kind.
    const bool analyse = !mLdlt && !mLdltBanded;
    if (analyse) {
        A.toScalar(mFilteredA);
        // Natural order when the block pattern is a band at most kBandedOrder blocks wide.
        constexpr int kBandedOrder = 4;
        int band = 0;
        for (int i = 0; i < A.size(); ++i)
            for (int k = A.blockRowStart()[i]; k < A.blockRowStart()[i + 1]; ++k)
                band = std::max(band, std::abs(A.blockCols()[k] - i));
        if (band <= kBandedOrder) {
            mLdltBanded = std::make_unique<BandedLdlt>();
            mLdltBanded->analyze(mFilteredA);
        } else {
            mLdlt = std::make_unique<Eigen::SimplicialLDLT<ColMatrix>>();
            mLdlt->analyzePattern(mFilteredA);
        }
    }
    bool ok;
    if (mLdltBanded) {
        // A band (hair): written from the blocks and refactored by the strands that changed.
        ok = factorBanded(A, c);
        if (ok) mLdltBanded->solve(rhs, y);
    } else {
        // The scalar matrix's values, then the constrained block rows and columns filtered.
        if (!analyse) A.toScalar(mFilteredA);
        if (!c.kind.empty() && c.any()) {
            // Column-major over a symmetric pattern: column 3j+a lists rows; entry (r, col).
            const int* outer = mFilteredA.outerIndexPtr();
            const int* inner = mFilteredA.innerIndexPtr();
            double* val = mFilteredA.valuePtr();
            const int n = A.size();
            for (int j = 0; j < n; ++j) {
                // Block column j: for each block row i present, B ← S_i B S_j (+ I − S_j on the
                // diagonal).
                for (int p = outer[3 * j]; p < outer[3 * j + 1]; p += 3) {
                    const int i = inner[p] / 3;
                    if (!c.kind[i] && !c.kind[j]) continue;
                    const int stride = outer[3 * j + 1] - outer[3 * j];
                    Mat3 B;
                    for (int a = 0; a < 3; ++a)     // column offset
                        for (int r = 0; r < 3; ++r) // row offset
                            B(r, a) = val[p + a * stride + r];
                    const Mat3 F = filteredBlock(B, c, i, j);
                    for (int a = 0; a < 3; ++a)
                        for (int r = 0; r < 3; ++r) val[p + a * stride + r] = F(r, a);
                }
            }
        }
        mLdlt->factorize(mFilteredA);
        ok = mLdlt->info() == Eigen::Success;
        if (ok) y = mLdlt->solve(rhs);
    }
    if (!ok) {
        st.failed = true;
        return st;
    }
    st.iterations = 1;
    mQ.resize(rhs.size());
    applyFiltered(A, c, y, mQ);
    const double rn = std::sqrt(deterministicDot(rhs.data(), rhs.data(), rhs.size()));
    const VecX res = mQ - rhs;
    st.residual = rn > 0.0 ? std::sqrt(deterministicDot(res.data(), res.data(), res.size())) / rn : 0.0;
    st.converged = std::isfinite(st.residual);
    st.failed = !st.converged;
    return st;
}

} // namespace gale::solver
