// Aggregation AMG preconditioner for the filtered cloth system and its BSR matrix (see
// multigrid.h). References: Vaněk, Mandel, Brezina, "Algebraic multigrid by smoothed
// aggregation", Computing 56 (1996); Tamstorf, Jones, McCormick, "Smoothed aggregation
// multigrid for cloth simulation", SIGGRAPH Asia 2015.
#include "solver/linalg/multigrid.h"

#include "solver/linalg/bsr_kernels.h"
#include "solver/linalg/linear.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <utility>

namespace gale::solver {

namespace {

// Blocks are stored column-major, 9 values each (bsr_kernels.h).
using BlockMap = Eigen::Map<Mat3>;
using ConstBlockMap = Eigen::Map<const Mat3>;

// A single-precision block (column-major, 9 floats) as a double 3×3 matrix, and back.
inline Mat3 blockAt(const float* p) {
    return Eigen::Map<const Eigen::Matrix3f>(p).cast<double>();
}
inline void storeBlock(float* p, const Mat3& m) {
    Eigen::Map<Eigen::Matrix3f> out(p);
    out = m.cast<float>();
}

// The multicolour ordering of a level (types.h, ColouredBlocks): its rows, in natural order, cut
// into blocks of `rowBlock`; two blocks neighbour when a row of one shares a matrix block
// with a row of the other. Without `multicolour`: the natural order, one block.
ColouredBlocks colourRows(bool multicolour, int rowBlock, int n, const int* start,
                          const int* cols) {
    if (!multicolour || rowBlock <= 0 || n <= rowBlock) return naturalBlocks(n);
    std::vector<std::vector<int>> near((n + rowBlock - 1) / rowBlock);
    for (int i = 0; i < n; ++i) {
        std::vector<int>& nb = near[i / rowBlock];
        for (int k = start[i]; k < start[i + 1]; ++k)
            if (cols[k] / rowBlock != i / rowBlock) nb.push_back(cols[k] / rowBlock);
    }
    for (std::vector<int>& nb : near) {
        std::sort(nb.begin(), nb.end());
        nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    }
    return colourBlocks(n, rowBlock, near);
}

int slotIn(const BsrMatrix& m, int i, int j) {
    auto b = m.cols.begin() + m.start[i], e = m.cols.begin() + m.start[i + 1];
    return static_cast<int>(std::lower_bound(b, e, j) - m.cols.begin());
}

// diag of a pattern with sorted columns, symmetric, the diagonal present.
void finishPattern(BsrMatrix& m) {
    m.diag.resize(m.n);
    for (int i = 0; i < m.n; ++i) m.diag[i] = slotIn(m, i, i);
}

} // namespace

// ---------------------------------------------------------------------------------------------
// BsrMatrix

void BsrMatrix::multiply(const double* x, double* y) const {
    const BsrPattern p = pattern();
    parallelChunks(static_cast<size_t>(n), 512,
                   [&](size_t i0, size_t i1) { bsrMultiplyRows(p, val.data(), x, y, i0, i1); });
}

double BsrMatrix::multiplyDot(const double* x, double* y, std::vector<double>& partial,
                              const double* dval) const {
    const size_t n3 = 3 * static_cast<size_t>(n);
    const size_t chunks = (n3 + kReduceChunk - 1) / kReduceChunk;
    const size_t rowsPerChunk = kReduceChunk / 3;
    const BsrPattern p = pattern();
    partial.assign(chunks, 0.0);
    parallelChunks(chunks, 1, [&](size_t c0, size_t c1) {
        for (size_t ch = c0; ch < c1; ++ch) {
            const size_t i1 = std::min(static_cast<size_t>(n), (ch + 1) * rowsPerChunk);
            const size_t i0 = ch * rowsPerChunk;
            if (dval)
                bsrMultiplyRows(p, dval, x, y, i0, i1);
            else bsrMultiplyRows(p, val.data(), x, y, i0, i1);
            double s = 0.0;
            for (size_t k = 3 * i0; k < 3 * i1; ++k) s += x[k] * y[k]; // in entry order, as deterministicDot
            partial[ch] = s;
        }
    });
    double s = 0.0;
    for (double p : partial) s += p;
    return s;
}

// ---------------------------------------------------------------------------------------------
// BlockMultigrid: set-up

BlockMultigrid::Settings& BlockMultigrid::defaults() {
    static Settings settings;
    return settings;
}

// Level 0: A's pattern renumbered in colour order (row p of level 0 is A's row order()[p]; its
// slot k holds A's slot mSrcSlot[k]).
void BlockMultigrid::buildHierarchy(const BlockMatrix& A) {
    mLevels.assign(1, Level());
    Level& L = mLevels[0];
    BsrMatrix& a = L.a;
    const int n = A.size();
    const std::vector<int>& start = A.blockRowStart();
    const std::vector<int>& cols = A.blockCols();
    L.colouring =
        colourRows(mSettings.multicolour, mSettings.rowBlock, n, start.data(), cols.data());
    L.visit.resize(n);
    for (int p = 0; p < n; ++p) L.visit[order()[p]] = p;
    a.n = n;
    a.start.assign(n + 1, 0);
    a.cols.clear();
    mSrcSlot.clear();
    std::vector<std::pair<int, int>> row; // (level-0 column, A's slot)
    for (int p = 0; p < n; ++p) {
        const int i = order()[p];
        row.clear();
        for (int k = start[i]; k < start[i + 1]; ++k) row.push_back({L.visit[cols[k]], k});
        std::sort(row.begin(), row.end());
        for (const auto& e : row) {
            a.cols.push_back(e.first);
            mSrcSlot.push_back(e.second);
        }
        a.start[p + 1] = static_cast<int>(a.cols.size());
    }
    a.cols.shrink_to_fit();
    mSrcSlot.shrink_to_fit();
    finishPattern(a);
    a.val.assign(9 * a.cols.size() + kBsrPad, 0.0f);
    mPatternRows = A.size();
    mPatternSlots = A.slotCount();
}

// The pattern of level l + 1 from level l's: nodes (agg.d rows each) aggregated on the node
// graph in natural order (fine.visit), P's pattern and the Galerkin pattern in the aggregates'
// natural numbering, which is then coloured; everything is renumbered in the coarse colour
// order. Block boundaries of the colouring are multiples of the rows per node, so a coarse
// node's rows stay consecutive there.
bool BlockMultigrid::buildCoarse(int l) {
    Level& f = mLevels[l];
    const BsrMatrix& a = f.a;
    const int d = f.agg.d, dc = mModes / 3;
    const int nodes = a.n / d;
    std::vector<int> row, nodeVisit(nodes);
    if (l == 0) { // level 0's node graph: A's pattern
        f.graphStart.assign(a.start.begin(), a.start.end());
        f.graphCols.assign(a.cols.begin(), a.cols.end());
    }
    const std::vector<int>& nStart = f.graphStart;
    const std::vector<int>& nCols = f.graphCols;
    for (int s = 0; s < nodes; ++s) nodeVisit[s] = f.visit[s * d] / d;
    std::vector<int> joined;
    const int count = aggregateNodes(nodes, nStart.data(), nCols.data(), nodeVisit, joined);
    if (5 * static_cast<long>(count) * dc > 4 * static_cast<long>(a.n)) return false; // stalls
    Aggregates& g = f.agg;
    g.nodeAgg = joined;
    g.memberStart.assign(count + 1, 0); // (natural numbering: only the count matters here)
    BlockProlongator& P = f.P;
    prolongatorPattern(a, g, dc, mSettings.smoothed, P);
    P.buildTranspose();
    std::vector<int> natStart, natCols;
    galerkinPattern(a, P, natStart, natCols);
    const int nc = dc * count;
    Level c;
    const int block = (std::max(mSettings.rowBlock, 1) + dc - 1) / dc * dc;
    c.colouring = colourRows(mSettings.multicolour, block, nc, natStart.data(), natCols.data());
    const std::vector<int>& order = c.colouring.order;
    c.visit.resize(nc);
    for (int p = 0; p < nc; ++p) c.visit[order[p]] = p;
    c.agg.d = dc;
    // Renumber: nodes, P's columns (rows re-sorted), members, the coarse pattern.
    for (int u = 0; u < nodes; ++u) g.nodeAgg[u] = c.visit[joined[u] * dc] / dc;
    for (int r = 0; r < a.n; ++r) {
        for (int k = P.start[r]; k < P.start[r + 1]; ++k) P.cols[k] = c.visit[P.cols[k]];
        std::sort(P.cols.begin() + P.start[r], P.cols.begin() + P.start[r + 1]);
    }
    P.buildTranspose();
    g.memberStart.assign(count + 1, 0);
    for (int u = 0; u < nodes; ++u) ++g.memberStart[g.nodeAgg[u] + 1];
    for (int J = 0; J < count; ++J) g.memberStart[J + 1] += g.memberStart[J];
    g.members.resize(nodes);
    {
        std::vector<int> fill(g.memberStart.begin(), g.memberStart.end() - 1);
        for (int u = 0; u < nodes; ++u) g.members[fill[g.nodeAgg[u]]++] = u;
    }
    BsrMatrix& cm = c.a;
    cm.n = nc;
    cm.start.assign(nc + 1, 0);
    cm.cols.clear();
    for (int p = 0; p < nc; ++p) {
        row.clear();
        for (int k = natStart[order[p]]; k < natStart[order[p] + 1]; ++k) row.push_back(c.visit[natCols[k]]);
        std::sort(row.begin(), row.end());
        cm.cols.insert(cm.cols.end(), row.begin(), row.end());
        cm.start[p + 1] = static_cast<int>(cm.cols.size());
    }
    cm.cols.shrink_to_fit();
    finishPattern(cm);
    cm.val.assign(9 * cm.cols.size() + kBsrPad, 0.0f);
    // The coarse node graph the next aggregation reads: aggregates neighbour when two of their
    // nodes do (the tentative prolongator's pattern, not the smoothed one's wider stencil: that
    // would grow the aggregates about threefold per level and coarsen too fast).
    c.graphStart.assign(count + 1, 0);
    c.graphCols.clear();
    for (int J = 0; J < count; ++J) {
        row.clear();
        for (int t = g.memberStart[J]; t < g.memberStart[J + 1]; ++t) {
            const int u = g.members[t];
            for (int k = nStart[u]; k < nStart[u + 1]; ++k) row.push_back(g.nodeAgg[nCols[k]]);
        }
        std::sort(row.begin(), row.end());
        row.erase(std::unique(row.begin(), row.end()), row.end());
        c.graphCols.insert(c.graphCols.end(), row.begin(), row.end());
        c.graphStart[J + 1] = static_cast<int>(c.graphCols.size());
    }
    // This level's node graph is not read again (the next level has its own).
    std::vector<int>().swap(f.graphStart);
    std::vector<int>().swap(f.graphCols);
    mLevels.push_back(std::move(c));
    return true;
}

// ---------------------------------------------------------------------------------------------
// Plain aggregation (main's path before issue 26, kept bit for bit for small meshes, where the
// smoothed set-up costs more than its iterations save: bench/README.md): P₀ = S P_tent with
// P_tent(i, I) = I₃, Galerkin products as sums of blocks.

// Vaněk–Mandel–Brezina aggregation on the graph of the pattern of `fine` (values are not
// read: a resumed run, which sees other first values, builds the same hierarchy bit for bit),
// rows visited in their natural order (fine.visit); builds the pattern of `coarse` — its rows
// (the aggregates, numbered in the order they were found) coloured and renumbered in colour
// order — and the slot maps.
void BlockMultigrid::aggregatePlain(Level& fine, Level& coarse) {
    const BsrMatrix& a = fine.a;
    const int n = a.n;
    std::vector<int> agg(n, -1), size;
    // 1. Roots: a vertex whose neighbours are all unaggregated starts an aggregate with them.
    for (int s = 0; s < n; ++s) {
        const int i = fine.visit[s];
        if (agg[i] >= 0) continue;
        bool free = true;
        for (int k = a.start[i]; k < a.start[i + 1] && free; ++k)
            if (agg[a.cols[k]] >= 0) free = false;
        if (!free) continue;
        for (int k = a.start[i]; k < a.start[i + 1]; ++k) agg[a.cols[k]] = static_cast<int>(size.size());
        size.push_back(a.start[i + 1] - a.start[i]);
    }
    // 2. The rest join the smallest neighbouring aggregate (ties: the lower index), decided
    // from the phase-1 labels only, so the order of the rows does not matter.
    std::vector<int> joined = agg;
    for (int i = 0; i < n; ++i) {
        if (agg[i] >= 0) continue;
        for (int k = a.start[i]; k < a.start[i + 1]; ++k) {
            const int J = agg[a.cols[k]];
            if (J >= 0 && (joined[i] < 0 || size[J] < size[joined[i]] || (size[J] == size[joined[i]] && J < joined[i])))
                joined[i] = J;
        }
    }
    // 3. Left-overs (no aggregated neighbour) form aggregates with their unaggregated neighbours.
    int count = static_cast<int>(size.size());
    for (int s = 0; s < n; ++s) {
        const int i = fine.visit[s];
        if (joined[i] >= 0) continue;
        joined[i] = count;
        for (int k = a.start[i]; k < a.start[i + 1]; ++k)
            if (joined[a.cols[k]] < 0) joined[a.cols[k]] = count;
        ++count;
    }
    // The coarse graph in the aggregates' natural numbering, coloured in that order; coarse
    // row P is aggregate order[P].
    std::vector<std::vector<int>> rows(count);
    for (int i = 0; i < n; ++i)
        for (int k = a.start[i]; k < a.start[i + 1]; ++k)
            rows[joined[i]].push_back(joined[a.cols[k]]);
    std::vector<int> natStart(count + 1, 0), natCols;
    for (int I = 0; I < count; ++I) {
        std::sort(rows[I].begin(), rows[I].end());
        rows[I].erase(std::unique(rows[I].begin(), rows[I].end()), rows[I].end());
        natCols.insert(natCols.end(), rows[I].begin(), rows[I].end());
        natStart[I + 1] = static_cast<int>(natCols.size());
    }
    coarse.colouring = colourRows(mSettings.multicolour, mSettings.rowBlock, count, natStart.data(),
                                  natCols.data());
    const std::vector<int>& order = coarse.colouring.order;
    coarse.visit.resize(count);
    for (int P = 0; P < count; ++P) coarse.visit[order[P]] = P;
    fine.plainAgg.resize(n);
    for (int i = 0; i < n; ++i) fine.plainAgg[i] = coarse.visit[joined[i]];
    fine.plainStart.assign(count + 1, 0);
    for (int i = 0; i < n; ++i) ++fine.plainStart[fine.plainAgg[i] + 1];
    for (int I = 0; I < count; ++I) fine.plainStart[I + 1] += fine.plainStart[I];
    fine.plainMembers.resize(n);
    {
        std::vector<int> fill(fine.plainStart.begin(), fine.plainStart.end() - 1);
        for (int i = 0; i < n; ++i) fine.plainMembers[fill[fine.plainAgg[i]]++] = i;
    }
    // Coarse pattern: (agg i, agg j) for every fine block (i, j), in the coarse numbering.
    BsrMatrix& c = coarse.a;
    c.n = count;
    c.start.assign(count + 1, 0);
    c.cols.clear();
    std::vector<int> row;
    for (int P = 0; P < count; ++P) {
        row.clear();
        for (int k = natStart[order[P]]; k < natStart[order[P] + 1]; ++k)
            row.push_back(coarse.visit[natCols[k]]);
        std::sort(row.begin(), row.end());
        c.cols.insert(c.cols.end(), row.begin(), row.end());
        c.start[P + 1] = static_cast<int>(c.cols.size());
    }
    c.cols.shrink_to_fit();
    finishPattern(c);
    c.val.assign(9 * c.cols.size() + kBsrPad, 0.0f);
    coarse.dval.assign(c.val.size(), 0.0);
    fine.coarseSlot.resize(a.cols.size());
    for (int i = 0; i < n; ++i)
        for (int k = a.start[i]; k < a.start[i + 1]; ++k)
            fine.coarseSlot[k] = slotIn(c, fine.plainAgg[i], fine.plainAgg[a.cols[k]]);
    // The same map inverted, for the coarsening's gather: the fine slots of each coarse slot in
    // increasing order.
    fine.gatherStart.assign(c.cols.size() + 1, 0);
    for (int K : fine.coarseSlot) ++fine.gatherStart[K + 1];
    for (size_t K = 0; K < c.cols.size(); ++K) fine.gatherStart[K + 1] += fine.gatherStart[K];
    fine.gather.resize(a.cols.size());
    std::vector<int> fill(fine.gatherStart.begin(), fine.gatherStart.end() - 1);
    for (int k = 0; k < a.blocks(); ++k) fine.gather[fill[fine.coarseSlot[k]]++] = k;
}

// A_{l+1} = P_lᵀ A_l P_l: a sum of blocks; at level 0 the constrained diagonals lose their
// I − S part and aggregates with a direction no member can move in get an identity there.
void BlockMultigrid::coarsenPlain(int l) {
    Level& f = mLevels[l];
    Level& C = mLevels[l + 1];
    BsrMatrix& c = C.a;
    const BsrMatrix& a = f.a;
    // Each coarse block the sum of its fine blocks in slot order, gathered (rows in parallel),
    // in double (finishLevel rounds each level for the smoother).
    parallelChunks(static_cast<size_t>(c.n), 64, [&](size_t I0, size_t I1) {
        for (int K = c.start[I0]; K < c.start[I1]; ++K) {
            double sum[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
            for (int m = f.gatherStart[K]; m < f.gatherStart[K + 1]; ++m) {
                const double* __restrict src = f.dval.data() + 9 * static_cast<size_t>(f.gather[m]);
                for (int q = 0; q < 9; ++q) sum[q] += src[q];
            }
            std::copy(sum, sum + 9, C.dval.data() + 9 * static_cast<size_t>(K));
        }
    });
    if (l != 0 || mKind.empty()) return;
    for (int i = 0; i < a.n; ++i) {
        if (!mKind[i]) continue;
        // Â_ii = S A_ii S + (I − S); the Galerkin block keeps S A_ii S only.
        BlockMap(C.dval.data() + 9 * static_cast<size_t>(c.diag[f.plainAgg[i]])) -=
            Mat3::Identity() - Constraints::filterOf(mKind[i], normalOf(i));
    }
    for (int I = 0; I < c.n; ++I) {
        bool any = false;
        for (int m = f.plainStart[I]; m < f.plainStart[I + 1]; ++m) any = any || mKind[f.plainMembers[m]];
        if (!any) continue;
        Mat3 B = Mat3::Zero();
        for (int m = f.plainStart[I]; m < f.plainStart[I + 1]; ++m) {
            const int i = f.plainMembers[m];
            B += Constraints::filterOf(mKind[i], normalOf(i));
        }
        Eigen::SelfAdjointEigenSolver<Mat3> es(B);
        BlockMap d(C.dval.data() + 9 * static_cast<size_t>(c.diag[I]));
        const double scale = d.trace() > 0.0 ? d.trace() / 3.0 : 1.0;
        for (int e = 0; e < 3; ++e)
            if (es.eigenvalues()[e] < 1e-8) {
                const Vec3 v = es.eigenvectors().col(e);
                d += scale * v * v.transpose();
            }
    }
}

// Level 0's near-null space from the positions and filters (multigrid.h): per aggregate its
// centroid and radius, per row S_i [I | −[x_i − c]× / ρ].
void BlockMultigrid::levelZeroNullSpace(std::vector<double>& nullB) const {
    const Level& L = mLevels[0];
    const Aggregates& g = L.agg;
    const int m = mModes;
    const size_t stride = 3 * static_cast<size_t>(m);
    nullB.assign(stride * L.a.n, 0.0);
    const int count = static_cast<int>(g.memberStart.size()) - 1;
    parallelChunks(static_cast<size_t>(count), 64, [&](size_t J0, size_t J1) {
        for (size_t J = J0; J < J1; ++J) {
            Vec3 c = Vec3::Zero();
            double radius = 0.0;
            if (m == 6) {
                for (int t = g.memberStart[J]; t < g.memberStart[J + 1]; ++t)
                    c += vec3At(mPositions.data(), order()[g.members[t]]);
                c /= std::max(1, g.memberStart[J + 1] - g.memberStart[J]);
                for (int t = g.memberStart[J]; t < g.memberStart[J + 1]; ++t)
                    radius = std::max(
                        radius, (vec3At(mPositions.data(), order()[g.members[t]]) - c).norm());
            }
            const double inv = radius > 0.0 ? 1.0 / radius : 1.0;
            for (int t = g.memberStart[J]; t < g.memberStart[J + 1]; ++t) {
                const int i = g.members[t];
                const Mat3 S =
                    mKind.empty() ? Mat3::Identity() : Constraints::filterOf(mKind[i], normalOf(i));
                double* B = nullB.data() + stride * i;
                BlockMap translations(B);
                translations = S;
                if (m == 6) {
                    const Vec3 p = inv * (vec3At(mPositions.data(), order()[i]) - c);
                    Mat3 cross;
                    cross << 0.0, -p.z(), p.y(), p.z(), 0.0, -p.x(), -p.y(), p.x(), 0.0;
                    BlockMap(B + 9) = -S * cross;
                }
            }
        }
    });
}

// A_{l+1} = P_lᵀ A_l P_l with P_l the smoothed tentative prolongator of B_l (multigrid.h);
// coarse unknowns no mode reaches get a unit diagonal (their rows and columns are zero).
// fineB: B_l on entry (built here at level 0); coarseB receives B_{l+1}; Q is scratch for the
// tentative prolongator (set-up scratch, not kept: refresh frees them).
void BlockMultigrid::coarsenValues(int l, std::vector<double>& fineB, std::vector<double>& coarseB,
                                   std::vector<double>& Q) {
    Level& f = mLevels[l];
    Level& c = mLevels[l + 1];
    if (l == 0) levelZeroNullSpace(fineB);
    double omega = 0.0;
    if (mSettings.smoothed) {
        const double rho = spectralRadiusDinvA(f.a, f.dinv.data(), mSettings.powerIterations);
        omega = mSettings.prolongatorDamping / rho;
    }
    tentativeProlongator(f.agg, mModes, fineB, Q, coarseB, c.dead);
    smoothProlongator(f.a, f.agg, mModes / 3, omega, Q, f.P);
    galerkinValues(f.a, f.P, c.a);
    mPeakBytes =
        std::max(mPeakBytes,
                 bytes() + sizeof(double) * (fineB.capacity() + coarseB.capacity() + Q.capacity()));
    for (int J = 0; J < c.a.n; ++J) {
        const uint8_t* dead = c.dead.data() + 3 * static_cast<size_t>(J);
        if (!(dead[0] | dead[1] | dead[2])) continue;
        float* Df = c.a.val.data() + 9 * static_cast<size_t>(c.a.diag[J]);
        Mat3 D = blockAt(Df);
        double live = 0.0;
        int nLive = 0;
        for (int q = 0; q < 3; ++q)
            if (!dead[q]) {
                live += D(q, q);
                ++nLive;
            }
        const double scale = nLive > 0 && live > 0.0 ? live / nLive : 1.0;
        for (int q = 0; q < 3; ++q)
            if (dead[q]) D(q, q) = scale;
        storeBlock(Df, D);
    }
}

// A level's diagonal inverses and work vectors (level 0 reads and writes apply's vectors: it
// needs only t).
void BlockMultigrid::finishLevel(int l) {
    Level& L = mLevels[l];
    if (l != 0 && !L.dval.empty()) { // plain aggregation: the smoother's copy of the sums
        parallelChunks(L.a.val.size(), 8192, [&](size_t k0, size_t k1) {
            for (size_t k = k0; k < k1; ++k) L.a.val[k] = static_cast<float>(L.dval[k]);
        });
    }
    L.dinv.resize(9 * static_cast<size_t>(L.a.n) + kBsrPad);
    std::fill(L.dinv.end() - kBsrPad, L.dinv.end(), 0.0);
    // The inverse of the single-precision diagonal, so that every sweep reads one matrix
    // (the forward and backward sweeps stay exact adjoints: the V-cycle stays symmetric).
    parallelChunks(static_cast<size_t>(L.a.n), 512, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i)
            BlockMap(L.dinv.data() + 9 * i) =
                invertBlockOrScale(blockAt(L.a.val.data() + 9 * static_cast<size_t>(L.a.diag[i])));
    });
    const size_t n3 = 3 * static_cast<size_t>(L.a.n);
    if (l != 0) {
        L.r.resize(n3);
        L.x.resize(n3);
    }
    L.rp = L.r.data();
    L.xp = L.x.data();
    L.t.resize(n3);
}

size_t BlockMultigrid::bytes() const {
    size_t b = 0;
    auto v = [&](const auto& vec) { b += vec.capacity() * sizeof(vec[0]); };
    for (const Level& L : mLevels) {
        v(L.a.start), v(L.a.cols), v(L.a.diag), v(L.a.val), v(L.dval), v(L.dinv);
        v(L.colouring.order), v(L.colouring.blockStart), v(L.colouring.colourStart), v(L.visit);
        v(L.dead), v(L.graphStart), v(L.graphCols), v(L.agg.nodeAgg), v(L.agg.memberStart),
            v(L.agg.members);
        v(L.P.start), v(L.P.cols), v(L.P.val), v(L.P.tStart), v(L.P.tRow), v(L.P.tSlot);
        v(L.plainAgg), v(L.plainStart), v(L.plainMembers), v(L.coarseSlot), v(L.gatherStart), v(L.gather);
        v(L.r), v(L.x), v(L.t), v(L.kr), v(L.kc), v(L.kv), v(L.kw);
    }
    v(mPartial), v(mSrcSlot), v(mConstrainedRows), v(mKind), v(mNormal), v(mPositions);
    b += static_cast<size_t>(mCoarseDense.size()) * 2 * sizeof(double); // and its factor
    return b;
}

bool BlockMultigrid::refresh(const BlockMatrix& A, const Constraints& cons, const std::vector<int>& constrained,
                             bool keepCoarse) {
    const bool plain = !mSettings.smoothed || A.size() < mSettings.smoothedMinRows;
    const int modes =
        !plain && mSettings.rotations && mPositions.size() == 3 * static_cast<size_t>(A.size()) ? 6 : 3;
    const bool fresh = mLevels.empty() || mPatternRows != A.size() ||
                       mPatternSlots != A.slotCount() || modes != mModes || plain != mPlain;
    mModes = modes;
    mPlain = plain;
    if (plain) keepCoarse = false; // its set-up is cheap: always the matrix's own hierarchy
    std::vector<uint8_t> kindsBefore;
    if (keepCoarse && !fresh) kindsBefore = mKind;
    if (fresh) {
        buildHierarchy(A);
        while (!plain && mLevels.back().a.n > mSettings.coarsest &&
               buildCoarse(static_cast<int>(mLevels.size()) - 1)) {
        }
        for (Level& L : mLevels) { // the node graphs were for the patterns only
            std::vector<int>().swap(L.graphStart);
            std::vector<int>().swap(L.graphCols);
        }
    }
    mSource = &A;
    // Level 0: Â = S A S + I − S, in single precision (the smoother's, the set-up's and the
    // single-precision CG products' copy). One pass over A, rows in parallel, with the
    // finiteness check.
    BsrMatrix& a = mLevels[0].a;
    const int n = a.n;
    std::vector<float>& low = a.val;
    std::fill(low.end() - kBsrPad, low.end(), 0.0f);
    std::vector<double>& dval = mLevels[0].dval;
    if (plain)
        dval.resize(a.val.size(), 0.0);
    else
        std::vector<double>().swap(dval);
    std::atomic<uint32_t> anyBad{0};
    parallelChunks(static_cast<size_t>(n), 256, [&](size_t i0, size_t i1) {
        const double* __restrict src = A.values();
        float* __restrict lo = low.data();
        const int k0 = a.start[i0], k1 = a.start[i1];
        for (int k = k0; k < k1; ++k) {
            const double* s = src + 9 * static_cast<size_t>(mSrcSlot[k]);
            for (int q = 0; q < 9; ++q)
                lo[9 * static_cast<size_t>(k) + q] = static_cast<float>(s[q]);
            if (plain)
                for (int q = 0; q < 9; ++q) dval[9 * static_cast<size_t>(k) + q] = s[q];
        }
        // Finite, checked on the single-precision copy (an all-ones exponent: inf or NaN — or
        // a value beyond float range, which the smoother could not use either); integer bit
        // tests vectorise where isfinite on doubles does not.
        uint32_t bad = 0;
        for (size_t q = 9 * static_cast<size_t>(k0); q < 9 * static_cast<size_t>(k1); ++q) {
            uint32_t bits;
            std::memcpy(&bits, lo + q, sizeof bits);
            bad |= static_cast<uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
        }
        if (bad) anyBad.fetch_or(1u, std::memory_order_relaxed);
    });
    if (anyBad.load()) return false;
    mKind.clear();
    mConstrainedRows.clear();
    mNormal.clear();
    if (!constrained.empty()) {
        mKind.assign(n, 0);
        for (int v : constrained) { // A's row v is level-0 row visit[v]
            const int i = mLevels[0].visit[v];
            mKind[i] = cons.kind[v];
            if (mKind[i]) mConstrainedRows.push_back(i);
        }
        std::sort(mConstrainedRows.begin(), mConstrainedRows.end());
        mConstrainedRows.erase(std::unique(mConstrainedRows.begin(), mConstrainedRows.end()),
                               mConstrainedRows.end());
        mNormal.assign(3 * mConstrainedRows.size(), 0.0); // the normals of those rows only
        for (size_t c = 0; c < mConstrainedRows.size(); ++c) {
            const int v = mLevels[0].colouring.order[mConstrainedRows[c]];
            for (int q = 0; q < 3; ++q)
                mNormal[3 * c + q] = cons.normal[3 * static_cast<size_t>(v) + q];
        }
        // Plain aggregation: the double copy filtered in place, row then column, each block
        // then rounded (the path before issue 26).
        auto lower = [&](int k) {
            for (size_t q = 9 * static_cast<size_t>(k); q < 9 * static_cast<size_t>(k) + 9; ++q)
                low[q] = static_cast<float>(dval[q]);
        };
        for (int v : constrained) {
            if (!plain) break;
            const int i = mLevels[0].visit[v];
            const Mat3 S = Constraints::filterOf(mKind[i], normalOf(i));
            for (int k = a.start[i]; k < a.start[i + 1]; ++k) {
                const int kt = slotIn(a, a.cols[k], i);
                BlockMap row(dval.data() + 9 * static_cast<size_t>(k));
                row = (S * row).eval();
                BlockMap col(dval.data() + 9 * static_cast<size_t>(kt));
                col = (col * S).eval();
                lower(k);
                lower(kt);
            }
            BlockMap(dval.data() + 9 * static_cast<size_t>(a.diag[i])) += Mat3::Identity() - S;
            lower(a.diag[i]);
        }
        // Smoothed: S_i A_ij S_j (+ I − S_i on the diagonal) from A's double values, rounded
        // once; the transposed block written as its transpose.
        for (int v : constrained) {
            if (plain) break;
            const int i = mLevels[0].visit[v];
            for (int k = a.start[i]; k < a.start[i + 1]; ++k) {
                const Mat3 b = levelZeroBlock(i, k);
                storeBlock(a.val.data() + 9 * static_cast<size_t>(k), b);
                if (a.cols[k] != i)
                    storeBlock(a.val.data() + 9 * static_cast<size_t>(slotIn(a, a.cols[k], i)),
                               b.transpose());
            }
        }
    }
    // Coarse levels: each finished (diagonal inverses), then the next one's values from it;
    // the near-null spaces and tentative prolongators are scratch, freed on return.
    const bool reuse = keepCoarse && !fresh && kindsBefore == mKind && mHaveCoarse;
    mPeakBytes = 0;
    if (plain) {
        // Plain aggregation: aggregate on first sight of the pattern, then sum.
        for (int l = 0;; ++l) {
            if (fresh) {
                if (mLevels[l].a.n <= mSettings.coarsest) break;
                Level next;
                aggregatePlain(mLevels[l], next);
                if (5 * next.a.n > 4 * mLevels[l].a.n) { // coarsening stalls: stop here
                    mLevels[l].plainAgg.clear();
                    break;
                }
                mLevels.push_back(std::move(next));
            } else if (l + 1 >= static_cast<int>(mLevels.size())) {
                break;
            }
            coarsenPlain(l);
        }
        for (int l = 0; l < static_cast<int>(mLevels.size()); ++l) finishLevel(l);
    } else {
        std::vector<double> fineB, coarseB, Q;
        for (int l = 0; l < static_cast<int>(mLevels.size()); ++l) {
            finishLevel(l);
            if (reuse) return true; // the coarse levels and the coarsest factorisation as they were
            if (l + 1 < static_cast<int>(mLevels.size())) {
                coarsenValues(l, fineB, coarseB, Q);
                fineB.swap(coarseB);
            }
        }
    }
    mHaveCoarse = true;
    mPeakBytes = std::max(mPeakBytes, bytes());
    // The coarsest level: a dense Cholesky factorisation when it is small (it may not be when
    // coarsening stalled, e.g. on uncoupled vertices: then symmetric Gauss–Seidel).
    const BsrMatrix& c = mLevels.back().a;
    mCoarseOk = false;
    if (c.n > 2 * std::max(mSettings.coarsest, 1)) return true;
    mCoarseDense.setZero(3 * c.n, 3 * c.n);
    for (int I = 0; I < c.n; ++I)
        for (int k = c.start[I]; k < c.start[I + 1]; ++k)
            mCoarseDense.block<3, 3>(3 * I, 3 * c.cols[k]) =
                mPlain ? ConstBlockMap(mLevels.back().dval.data() + 9 * static_cast<size_t>(k))
                : mLevels.size() == 1 ? levelZeroBlock(I, k)
                                      : blockAt(c.val.data() + 9 * static_cast<size_t>(k));
    mCoarseLlt.compute(mCoarseDense);
    mCoarseOk = mCoarseLlt.info() == Eigen::Success;
    return true;
}

// ---------------------------------------------------------------------------------------------
// BlockMultigrid: the V-cycle

bool BlockMultigrid::smooth(int l, bool forward, bool fromZero, bool residual) {
    Level& L = mLevels[l];
    const BsrMatrix& a = L.a;
    const int n = a.n;
    double* x = L.xp;
    const double* r = L.rp;
    if (mSettings.gaussSeidel) {
        GaussSeidelSweep g;
        g.pattern = a.pattern();
        g.val = a.val.data();
        g.dinv = L.dinv.data();
        g.r = r;
        g.x = x;
        g.t = nullptr; // t is pulled afterwards (cycle, cyclePlainCoarse)
        g.forward = forward;
        g.fromZero = fromZero && forward;
        const bool parallel =
            n >= mSettings.parallelRows && L.colouring.colours() >= 2 && arenaConcurrency() >= 2;
        // Colour by colour (reversed for the backward sweep), each colour's blocks of rows in
        // parallel; sequentially, one sweep over all rows in the same order. The residual t is
        // pulled afterwards, row by row: the same sums in the same order as a push would make.
        forEachColour(L.colouring, !forward, parallel, [&](size_t i0, size_t i1) {
            GaussSeidelSweep part = g;
            part.begin = static_cast<int>(i0);
            part.end = static_cast<int>(i1);
            gaussSeidelSweep(part);
        });
        return residual && g.fromZero; // t still to pull (the restriction does)
    }
    // Damped block Jacobi: x += ω D⁻¹ (r − A x).
    const double w = mSettings.jacobiWeight;
    if (!fromZero) a.multiply(x, L.t.data());
    parallelChunks(static_cast<size_t>(n), 512, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i) {
            double y[3];
            for (int q = 0; q < 3; ++q) y[q] = r[3 * i + q] - (fromZero ? 0.0 : L.t[3 * i + q]);
            const double* d = L.dinv.data() + 9 * i;
            for (int q = 0; q < 3; ++q) {
                const double v = w * (d[3 * q] * y[0] + d[3 * q + 1] * y[1] + d[3 * q + 2] * y[2]);
                x[3 * i + q] = fromZero ? v : x[3 * i + q] + v;
            }
        }
    });
    return false;
}

// Plain aggregation's coarse correction: r_c = P₀ᵀ t, the coarse cycle, x += α P₀ e (P₀ = S P_tent
// at level 0, P_tent below).
void BlockMultigrid::cyclePlainCoarse(int l, bool pull) {
    // Restriction: r_c(I) = Σ_{i∈I} S_i t_i (with t pulled here after the sweep).
    Level& L = mLevels[l];
    Level& C = mLevels[l + 1];
    const BsrMatrix& a = L.a;
    const BsrPattern p = a.pattern();
    const bool filtered = l == 0 && !mKind.empty();
    parallelChunks(static_cast<size_t>(C.a.n), 64, [&](size_t I0, size_t I1) {
        for (size_t I = I0; I < I1; ++I) {
            Vec3 s = Vec3::Zero();
            for (int m = L.plainStart[I]; m < L.plainStart[I + 1]; ++m) {
                const int i = L.plainMembers[m];
                if (pull) bsrUpperResidualRows(p, a.val.data(), L.xp, L.t.data(), i, i + 1);
                Vec3 t(L.t[3 * i], L.t[3 * i + 1], L.t[3 * i + 2]);
                if (filtered && mKind[i]) t = Constraints::filterOf(mKind[i], normalOf(i)) * t;
                s += t;
            }
            for (int q = 0; q < 3; ++q) C.r[3 * I + q] = s[q];
        }
    });
    coarseCycle(l + 1);
    // x += α S P_tent e.
    const double alpha = mSettings.coarseWeight;
    parallelChunks(static_cast<size_t>(L.a.n), 512, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i) {
            const int I = L.plainAgg[i];
            Vec3 e(C.x[3 * I], C.x[3 * I + 1], C.x[3 * I + 2]);
            if (filtered && mKind[i]) e = Constraints::filterOf(mKind[i], normalOf(i)) * e;
            for (int q = 0; q < 3; ++q) L.xp[3 * i + q] += alpha * e[q];
        }
    });
}

void BlockMultigrid::cycle(int l) {
    Level& L = mLevels[l];
    const size_t n3 = 3 * static_cast<size_t>(L.a.n);
    if (l + 1 == static_cast<int>(mLevels.size())) {
        if (mCoarseOk) {
            Eigen::Map<VecX>(L.xp, n3) = mCoarseLlt.solve(Eigen::Map<const VecX>(L.rp, n3));
        } else { // a symmetric pair of sweeps, the first from zero
            smooth(l, true, true);
            smooth(l, false, false);
        }
        return;
    }
    // x = 0 on entry: the first sweep starts from zero and writes every row without reading
    // its old value, so no fill is needed (only without sweeps).
    if (mSettings.sweeps < 1) std::fill(L.xp, L.xp + n3, 0.0);
    // t = r − A x. After one forward Gauss–Seidel sweep from zero, rows up to i already
    // satisfy their equation: t_i = −Σ_{j>i} A_ij x_j, which that sweep accumulates itself.
    const BsrMatrix& a = L.a;
    const bool fused = mSettings.gaussSeidel && mSettings.sweeps == 1;
    bool pull = false; // t_i = −Σ_{j>i} A_ij x_j still to be pulled, row by row
    for (int s = 0; s < mSettings.sweeps; ++s) pull = smooth(l, true, s == 0, fused);
    if (!fused) {
        a.multiply(L.xp, L.t.data());
        for (size_t k = 0; k < n3; ++k) L.t[k] = L.rp[k] - L.t[k];
    }
    Level& C = mLevels[l + 1];
    if (mPlain) {
        cyclePlainCoarse(l, pull);
        for (int s = 0; s < mSettings.sweeps; ++s) smooth(l, false, false);
        return;
    }
    // Restriction r_c = Pᵀ t (t pulled first after the sweep); P's rows lie in range(S).
    if (pull) {
        const BsrPattern p = a.pattern();
        parallelChunks(static_cast<size_t>(L.a.n), 512, [&](size_t i0, size_t i1) {
            bsrUpperResidualRows(p, a.val.data(), L.xp, L.t.data(), i0, i1);
        });
    }
    L.P.restrictTo(L.t.data(), C.r.data());
    coarseCycle(l + 1);
    // x += α P e.
    L.P.prolongAdd(C.x.data(), mSettings.coarseWeight, L.xp);
    for (int s = 0; s < mSettings.sweeps; ++s) smooth(l, false, false);
}

// The coarse correction of level c (c ≥ 1) for its r, into its x. With Settings::kCycle and a
// level below c, Notay & Vassilevski's K-cycle (2008, Algorithm 2.1 with two inner steps): two
// steps of flexible CG on A_c x = r, each preconditioned by one cycle of level c,
//   c₁ = B r, v₁ = A c₁, ρ₁ = c₁ᵀv₁, α₁ = c₁ᵀr, r̃ = r − (α₁/ρ₁) v₁;
//   if ‖r̃‖ ≤ t‖r‖ (t = 0.25): x = (α₁/ρ₁) c₁; else
//   c₂ = B r̃, v₂ = A c₂, γ = c₂ᵀv₁, β = c₂ᵀv₂, α₂ = c₂ᵀr̃, ρ₂ = β − γ²/ρ₁,
//   x = (α₁/ρ₁ − γα₂/(ρ₁ρ₂)) c₁ + (α₂/ρ₂) c₂.
// Dot products in deterministicDot's order: the same bits for any thread count.
void BlockMultigrid::coarseCycle(int c) {
    if (!mSettings.kCycle || c + 1 >= static_cast<int>(mLevels.size())) {
        cycle(c);
        return;
    }
    Level& C = mLevels[c];
    const size_t n3 = 3 * static_cast<size_t>(C.a.n);
    C.kr.assign(C.r.begin(), C.r.end());
    C.kc.resize(n3);
    C.kv.resize(n3);
    C.kw.resize(n3);
    cycle(c);
    std::copy(C.x.begin(), C.x.end(), C.kc.begin());
    C.a.multiply(C.kc.data(), C.kv.data());
    const double rho1 = deterministicDot(C.kc.data(), C.kv.data(), n3);
    const double a1 = deterministicDot(C.kc.data(), C.kr.data(), n3);
    if (!(rho1 > 0.0) || !std::isfinite(rho1)) return; // x = c₁ (one cycle)
    const double s1 = a1 / rho1;
    for (size_t k = 0; k < n3; ++k) C.r[k] = C.kr[k] - s1 * C.kv[k];
    const double r0 = deterministicDot(C.kr.data(), C.kr.data(), n3);
    const double rt = deterministicDot(C.r.data(), C.r.data(), n3);
    if (rt <= 0.0625 * r0) {
        for (size_t k = 0; k < n3; ++k) C.x[k] = s1 * C.kc[k];
        return;
    }
    cycle(c); // c₂ = B r̃
    C.a.multiply(C.x.data(), C.kw.data());
    const double gamma = deterministicDot(C.x.data(), C.kv.data(), n3);
    const double beta = deterministicDot(C.x.data(), C.kw.data(), n3);
    const double a2 = deterministicDot(C.x.data(), C.r.data(), n3);
    const double rho2 = beta - gamma * gamma / rho1;
    if (!(rho2 > 0.0) || !std::isfinite(rho2)) {
        for (size_t k = 0; k < n3; ++k) C.x[k] = s1 * C.kc[k];
        return;
    }
    const double w1 = s1 - gamma * a2 / (rho1 * rho2), w2 = a2 / rho2;
    for (size_t k = 0; k < n3; ++k) C.x[k] = w1 * C.kc[k] + w2 * C.x[k];
}

const double* BlockMultigrid::normalOf(int i) const {
    static const double none[3] = {0.0, 0.0, 0.0}; // (the filters of kinds 0 and 1 read none)
    if (mKind[i] != 2) return none;
    const size_t c =
        static_cast<size_t>(std::lower_bound(mConstrainedRows.begin(), mConstrainedRows.end(), i) -
                            mConstrainedRows.begin());
    return mNormal.data() + 3 * c;
}

// Block k of level-0 row i of Â = S A S + I − S in double, from A's values (a one-level
// hierarchy factors Â itself: an exact solve).
Mat3 BlockMultigrid::levelZeroBlock(int i, int k) const {
    const BsrMatrix& a = mLevels[0].a;
    const int j = a.cols[k];
    Mat3 b = ConstBlockMap(mSource->values() + 9 * static_cast<size_t>(mSrcSlot[k]));
    if (mKind.empty() || !(mKind[i] | mKind[j])) return b;
    const Mat3 Si = mKind[i] ? Constraints::filterOf(mKind[i], normalOf(i)) : Mat3::Identity();
    const Mat3 Sj = mKind[j] ? Constraints::filterOf(mKind[j], normalOf(j)) : Mat3::Identity();
    b = (Si * b * Sj).eval();
    if (i == j) b += Mat3::Identity() - Si;
    return b;
}

// Â x = S A S x + (I − S) x in double from A's values: row p of level 0 is A's row order()[p],
// its slot k A's slot mSrcSlot[k]; y = A x row by row in level-0 column order, then for each
// constrained row j (in level order) the columns' part A_ij (S_j − I) x_j added to its
// neighbours i, then the constrained rows' S_i y_i + (I − S_i) x_i (sequential: few rows).
void BlockMultigrid::multiply(const double* x, double* y) const {
    const BsrMatrix& a = mLevels[0].a;
    if (mPlain) { // the double copy (plain aggregation keeps one)
        const BsrPattern p = a.pattern();
        const double* dval = mLevels[0].dval.data();
        parallelChunks(static_cast<size_t>(a.n), 512,
                       [&](size_t i0, size_t i1) { bsrMultiplyRows(p, dval, x, y, i0, i1); });
        return;
    }
    const double* __restrict src = mSource->values();
    parallelChunks(static_cast<size_t>(a.n), 512, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i) {
            double s0 = 0.0, s1 = 0.0, s2 = 0.0;
            for (int k = a.start[i]; k < a.start[i + 1]; ++k) {
                const double* b = src + 9 * static_cast<size_t>(mSrcSlot[k]);
                const double* xj = x + 3 * static_cast<size_t>(a.cols[k]);
                s0 += b[0] * xj[0] + b[3] * xj[1] + b[6] * xj[2];
                s1 += b[1] * xj[0] + b[4] * xj[1] + b[7] * xj[2];
                s2 += b[2] * xj[0] + b[5] * xj[1] + b[8] * xj[2];
            }
            y[3 * i] = s0;
            y[3 * i + 1] = s1;
            y[3 * i + 2] = s2;
        }
    });
    if (mConstrainedRows.empty()) return;
    const std::vector<int>& start = mSource->blockRowStart();
    const std::vector<int>& cols = mSource->blockCols();
    const std::vector<int>& order = mLevels[0].colouring.order;
    const std::vector<int>& visit = mLevels[0].visit;
    for (int j : mConstrainedRows) {
        const Mat3 S = Constraints::filterOf(mKind[j], normalOf(j));
        const Vec3 d = (S - Mat3::Identity()) * vec3At(x, j);
        const int v = order[j];
        for (int k = start[v]; k < start[v + 1]; ++k) // A_uv = (A_vu)ᵀ, the block of row u
            vec3At(y, visit[cols[k]]) +=
                ConstBlockMap(mSource->values() + 9 * static_cast<size_t>(mSource->mirrorSlot(k))) *
                d;
    }
    for (int i : mConstrainedRows) {
        const Mat3 S = Constraints::filterOf(mKind[i], normalOf(i));
        vec3At(y, i) = (S * vec3At(y, i) + (Mat3::Identity() - S) * vec3At(x, i)).eval();
    }
}

double BlockMultigrid::multiplyDot(const double* x, double* y, bool single) {
    if (single) return mLevels[0].a.multiplyDot(x, y, mPartial);
    if (mPlain) return mLevels[0].a.multiplyDot(x, y, mPartial, mLevels[0].dval.data());
    multiply(x, y);
    return deterministicDot(x, y, 3 * static_cast<size_t>(mLevels[0].a.n));
}

void BlockMultigrid::toLevelOrder(const double* natural, double* level) const {
    parallelChunks(order().size(), 2048, [&](size_t p0, size_t p1) {
        for (size_t p = p0; p < p1; ++p)
            for (int q = 0; q < 3; ++q)
                level[3 * p + q] = natural[3 * static_cast<size_t>(order()[p]) + q];
    });
}

void BlockMultigrid::fromLevelOrder(const double* level, double* natural) const {
    parallelChunks(order().size(), 2048, [&](size_t p0, size_t p1) {
        for (size_t p = p0; p < p1; ++p)
            for (int q = 0; q < 3; ++q)
                natural[3 * static_cast<size_t>(order()[p]) + q] = level[3 * p + q];
    });
}

double BlockMultigrid::apply(const double* r, double* z) {
    // Level 0 reads r and writes x = z in place: no copies in or out.
    Level& L = mLevels[0];
    L.rp = r;
    L.xp = z;
    cycle(0);
    L.rp = L.r.data();
    L.xp = L.x.data();
    return deterministicDot(r, z, 3 * static_cast<size_t>(L.a.n));
}

} // namespace gale::solver
