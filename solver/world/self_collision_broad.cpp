// The self-collision pass's broad phase (self_collision.h): per-vertex regions about each
// step's path, the boxes and trees over them, the candidate pairs from two tree walks (kept from
// pass to pass, re-gathered in full or for the vertices that moved), and the flat patches that
// leave a flat stretch's pairs out.
#include "solver/world/self_collision.h"

#include "solver/world/self_collision_detail.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>

namespace gale::solver {

using contact::Box;
using namespace self_collision_detail;

void SelfCollision::refitBoxes(const std::vector<double>& lo, const std::vector<double>& hi,
                               double inflate) {
    // Boxes of vertices, triangles and edges: the union of their vertices' boxes [lo, hi],
    // inflated by `inflate` (overlapping boxes cover every pair within 2·inflate of them).
    const auto boxOf = [&](const int* v, int count) {
        Box b;
        for (int k = 0; k < count; ++k) {
            b.add(Vec3(vec3At(lo.data(), v[k])));
            b.add(Vec3(vec3At(hi.data(), v[k])));
        }
        b.inflate(inflate);
        return b;
    };
    mVertBoxes.resize(mVertexBody.size());
    mTriBoxes.resize(mTris.size());
    mEdgeBoxes.resize(mEdges.size());
    tbb::parallel_for(size_t(0), mVertBoxes.size(), [&](size_t i) {
        const int v = static_cast<int>(i);
        mVertBoxes[i] = boxOf(&v, 1);
    });
    tbb::parallel_for(size_t(0), mTris.size(),
                      [&](size_t i) { mTriBoxes[i] = boxOf(mTris[i].data(), 3); });
    tbb::parallel_for(size_t(0), mEdges.size(),
                      [&](size_t i) { mEdgeBoxes[i] = boxOf(mEdges[i].data(), 2); });
    // The trees are built once over the rest shape and refitted from then on: their nodes are
    // compact pieces of the cloth as cut (flat patches are such nodes, and a refit keeps them),
    // whatever it folds into (a rebuild over the moving boxes cut nodes across the folds, and
    // their contours were rarely star-shaped: 21.7M candidates on the cape against 13.0M).
    if (!mBuilt) {
        const auto restBox = [&](const int* v, int count) {
            Box b;
            for (int k = 0; k < count; ++k) b.add(Vec3(vec3At(mRest.data(), v[k])));
            return b;
        };
        std::vector<Box> vert(mVertBoxes.size()), tri(mTris.size()), edge(mEdges.size());
        for (size_t i = 0; i < vert.size(); ++i) {
            const int v = static_cast<int>(i);
            vert[i] = restBox(&v, 1);
        }
        for (size_t i = 0; i < tri.size(); ++i) tri[i] = restBox(mTris[i].data(), 3);
        for (size_t i = 0; i < edge.size(); ++i) edge[i] = restBox(mEdges[i].data(), 2);
        tbb::parallel_invoke([&] { mVertTree.build(vert); }, [&] { mTriTree.build(tri); },
                             [&] { mEdgeTree.build(edge); });
        mBuilt = true;
    }
    mVertTree.refit(mVertBoxes);
    mTriTree.refit(mTriBoxes);
    mEdgeTree.refit(mEdgeBoxes);
}

// Vertex–triangle pairs (v, a, b, c) and edge–edge pairs (p, q, r, s) whose boxes (refitBoxes)
// overlap, the primitives sharing no vertex and not all held; α left to the narrow phase. One
// simultaneous descent of two trees each (bvh.h), split into parts that run in parallel, each
// into its own list, concatenated in the walk's order: the pairs and their order depend only on
// the trees, not on the threads.
void SelfCollision::gatherCandidates(std::vector<Candidate>& vtOut,
                                     std::vector<Candidate>& eeOut) const {
    constexpr size_t kTasks = 64; // parts per kind (a few per thread, for balance)
    const std::vector<contact::Bvh::PairTask> vtTasks = mVertTree.pairTasks(mTriTree, kTasks);
    const std::vector<contact::Bvh::PairTask> eeTasks = mEdgeTree.pairTasks(mEdgeTree, kTasks);
    std::vector<std::vector<Candidate>> parts(vtTasks.size() + eeTasks.size());
    tbb::parallel_for(size_t(0), parts.size(), [&](size_t k) {
        std::vector<Candidate>& out = parts[k];
        if (k < vtTasks.size()) {
            mVertTree.overlappingPairs(mTriTree, vtTasks[k], [&](int vi, int t) {
                if (candidateVertexTriangle(vi, t))
                    out.push_back({vi, mTris[t][0], mTris[t][1], mTris[t][2]});
            });
            return;
        }
        mEdgeTree.overlappingPairs(mEdgeTree, eeTasks[k - vtTasks.size()], [&](int e, int f) {
            if (candidateEdgeEdge(e, f))
                out.push_back({mEdges[e][0], mEdges[e][1], mEdges[f][0], mEdges[f][1]});
        });
    });
    const auto concatenate = [&](size_t begin, size_t end, std::vector<Candidate>& all) {
        size_t total = 0;
        for (size_t k = begin; k < end; ++k) total += parts[k].size();
        all.clear();
        all.reserve(total);
        for (size_t k = begin; k < end; ++k)
            all.insert(all.end(), parts[k].begin(), parts[k].end());
    };
    concatenate(0, vtTasks.size(), vtOut);
    concatenate(vtTasks.size(), parts.size(), eeOut);
}

bool SelfCollision::candidateVertexTriangle(int vi, int t) const {
    const auto& tri = mTris[t];
    if (tri[0] == vi || tri[1] == vi || tri[2] == vi) return false;
    if (!mTangled.empty() && mTangled[vi]) return false;
    return !(mInvMass[vi] == 0.0 && mInvMass[tri[0]] == 0.0 && mInvMass[tri[1]] == 0.0 &&
             mInvMass[tri[2]] == 0.0);
}

bool SelfCollision::candidateEdgeEdge(int e, int f) const {
    const auto& ea = mEdges[e];
    const auto& eb = mEdges[f];
    if (ea[0] == eb[0] || ea[0] == eb[1] || ea[1] == eb[0] || ea[1] == eb[1]) return false;
    if (!mTangled.empty() &&
        (mTangled[ea[0]] || mTangled[ea[1]] || mTangled[eb[0]] || mTangled[eb[1]]))
        return false;
    if (mInvMass[ea[0]] == 0.0 && mInvMass[ea[1]] == 0.0 && mInvMass[eb[0]] == 0.0 &&
        mInvMass[eb[1]] == 0.0)
        return false;
    return mBodyHasTriangles[mVertexBody[ea[0]]] || mBodyHasTriangles[mVertexBody[eb[0]]];
}

void SelfCollision::setRegion(size_t i, double delta) {
    for (int j = 0; j < 3; ++j) {
        const double a = mX0[3 * i + j], b = mX1[3 * i + j];
        mRegionLo[3 * i + j] = std::min(a, b) - delta;
        mRegionHi[3 * i + j] = std::max(a, b) + delta;
    }
}

bool SelfCollision::ensureCandidates() {
    // The candidates were gathered over per-vertex regions: the box of the vertex's path
    // x₀ → x₁ then, grown by δ = ξ/2 (setRegion), each primitive's box the union of its
    // vertices' regions inflated by ξ/2. While every vertex's path x₀ → x₁ (the straight line
    // of the step) stays inside its region, so does every primitive's swept box inside its
    // gathered box, and the candidates still hold every pair within ξ at x₁ (proximity) or
    // whose path comes within ξ_c ≤ ξ (CCD): after the pass's corrections and in later passes
    // (a pile at rest keeps its candidates from substep to substep).
    const double delta = kMoveAllowance * mMaxThickness;
    const size_t n = mX1.size() / 3;
    if (mCandidatesValid) {
        std::vector<uint8_t> moved(n, 0);
        for (size_t i = 0; i < n; ++i)
            for (int j = 0; j < 3; ++j) {
                const double lo = mRegionLo[3 * i + j], hi = mRegionHi[3 * i + j];
                const double a = mX0[3 * i + j], b = mX1[3 * i + j];
                if (!(a >= lo && a <= hi && b >= lo && b <= hi)) {
                    moved[i] = 1;
                    break;
                }
            }
        // A vertex of a flat patch may stray δ from either end of the path its patch was
        // certified for. Beyond, the pairs its position vouched for are queried again: those of
        // every vertex whose fan it is in (a left-out pair rests on its vertices' fans).
        if (!mInPatch.empty()) {
            const double slack = flatSlack();
            std::vector<uint8_t> strayed(n, 0);
            bool any = false;
            for (size_t i = 0; i < n; ++i) {
                if (!mInPatch[i]) continue;
                const double d0 = (vec3At(mX0.data(), i) - vec3At(mCertX0.data(), i)).squaredNorm();
                const double d1 = (vec3At(mX1.data(), i) - vec3At(mCertX1.data(), i)).squaredNorm();
                if (moved[i] || !(d0 <= slack * slack) || !(d1 <= slack * slack)) {
                    strayed[i] = 1;
                    any = true;
                }
            }
            // The patches certified again for this path (a pile creeping, CCD moving a few
            // vertices) keep their pairs left out; the fans of the vertices of those that fail
            // (or of the strayed vertices, when many left their regions anyway) are queried
            // again.
            if (any) {
                const size_t left = static_cast<size_t>(std::count(moved.begin(), moved.end(), 1));
                std::vector<uint8_t> lost(n, 0);
                if (left * kRegatherShare <= n) {
                    mFlat.recertify(mX0, mX1, slack, mMaxThickness, lost);
                    mCertX0 = mX0;
                    mCertX1 = mX1;
                } else {
                    lost.swap(strayed);
                }
                mFlat.markFans(lost, moved);
            }
        }
        const size_t count = static_cast<size_t>(std::count(moved.begin(), moved.end(), 1));
        if (count == 0) return false;
        // A CCD correction moves the few vertices of the pairs it hit, a resting pile only its
        // few sliding vertices: re-query only those (the pairs of the others are still
        // covered). When many left their regions, gather afresh.
        if (count * kRegatherShare <= n) {
            const auto t0 = std::chrono::steady_clock::now();
            regatherMoved(moved);
            mMaybeValid = false;
            ++mStats.broadPhases;
            mStats.candidates += static_cast<long long>(mCandVt.size() + mCandEe.size());
            mStats.broadSeconds += seconds(t0);
            return true;
        }
    }
    const auto t0 = std::chrono::steady_clock::now();
    mRegionLo.resize(3 * n);
    mRegionHi.resize(3 * n);
    for (size_t i = 0; i < n; ++i) setRegion(i, delta);
    refitBoxes(mRegionLo, mRegionHi, 0.5 * mMaxThickness);
    labelFlatPatches();
    gatherCandidates(mCandVt, mCandEe);
    mCandidatesValid = true;
    mMaybeValid = false;
    ++mStats.broadPhases;
    mStats.candidates += static_cast<long long>(mCandVt.size() + mCandEe.size());
    mStats.broadSeconds += seconds(t0);
    return true;
}

double SelfCollision::flatSlack() const {
    return kFlatSlack * mMaxThickness;
}

void SelfCollision::labelFlatPatches() {
    mInPatch.clear();
    const int patches =
        mSettings.flatPatches ? mFlat.find(mTriTree, mX0, mX1, flatSlack(), mMaxThickness) : 0;
    if (patches == 0) {
        mVertTree.clearLabels();
        mTriTree.clearLabels();
        mEdgeTree.clearLabels();
        return;
    }
    const std::vector<int>& vertex = mFlat.vertexLabels();
    std::vector<int> edge(mEdges.size());
    for (size_t e = 0; e < mEdges.size(); ++e) {
        const int a = vertex[mEdges[e][0]];
        edge[e] = a == vertex[mEdges[e][1]] ? a : -1;
    }
    mVertTree.setLabels(vertex);
    mTriTree.setLabels(mFlat.triangleLabels());
    mEdgeTree.setLabels(edge);
    mInPatch = mFlat.inPatch();
    mCertX0 = mX0;
    mCertX1 = mX1;
}

void SelfCollision::regatherMoved(const std::vector<uint8_t>& moved) {
    // The moved vertices get new regions (the others keep theirs) and every primitive's box is
    // recomputed from them, exactly as at a full gathering (ensureCandidates). A pair of
    // unmoved vertices has the same boxes as when it was gathered, so it is in the old list
    // exactly when they overlap; a pair with a moved vertex is found by a query of the moved
    // primitive's new box.
    const size_t n = moved.size();
    for (size_t i = 0; i < n; ++i)
        if (moved[i]) setRegion(i, kMoveAllowance * mMaxThickness);
    refitBoxes(mRegionLo, mRegionHi, 0.5 * mMaxThickness);
    // Every pair of a moved vertex is found below: none rests on its certificate any more.
    if (!mInPatch.empty())
        for (size_t i = 0; i < n; ++i)
            if (moved[i]) mInPatch[i] = 0;
    const auto touches = [&](const Candidate& c) {
        return moved[c[0]] || moved[c[1]] || moved[c[2]] || moved[c[3]];
    };
    mCandVt.erase(std::remove_if(mCandVt.begin(), mCandVt.end(), touches), mCandVt.end());
    mCandEe.erase(std::remove_if(mCandEe.begin(), mCandEe.end(), touches), mCandEe.end());
    // Vertex–triangle: the moved vertices against every triangle, then the triangles with a
    // moved corner against the unmoved vertices (each new pair once).
    std::vector<int> movedVerts, movedTris, movedEdges;
    for (size_t i = 0; i < n; ++i)
        if (moved[i]) movedVerts.push_back(static_cast<int>(i));
    for (size_t t = 0; t < mTris.size(); ++t)
        if (moved[mTris[t][0]] || moved[mTris[t][1]] || moved[mTris[t][2]])
            movedTris.push_back(static_cast<int>(t));
    std::vector<uint8_t> edgeMoved(mEdges.size(), 0);
    for (size_t e = 0; e < mEdges.size(); ++e)
        if (moved[mEdges[e][0]] || moved[mEdges[e][1]]) {
            edgeMoved[e] = 1;
            movedEdges.push_back(static_cast<int>(e));
        }
    const auto vertexTriangle = [&](int vi, int t, std::vector<Candidate>& out) {
        if (candidateVertexTriangle(vi, t))
            out.push_back({vi, mTris[t][0], mTris[t][1], mTris[t][2]});
    };
    const size_t nv = movedVerts.size(), nt = movedTris.size();
    parallelCollect<Candidate>(
        nv + nt,
        [&](size_t k, std::vector<Candidate>& out) {
            if (k < nv) {
                const int vi = movedVerts[k];
                mTriTree.queryEach(mVertBoxes[vi], [&](int t) { vertexTriangle(vi, t, out); });
                return;
            }
            const int t = movedTris[k - nv];
            mVertTree.queryEach(mTriBoxes[t], [&](int vi) {
                if (!moved[vi]) vertexTriangle(vi, t, out);
            });
        },
        mCandVt);
    // Edge–edge: each moved edge against every edge; a pair of two moved edges from the lower.
    parallelCollect<Candidate>(
        movedEdges.size(),
        [&](size_t k, std::vector<Candidate>& out) {
            const int e = movedEdges[k];
            mEdgeTree.queryEach(mEdgeBoxes[e], [&](int f) {
                if (edgeMoved[f] && f <= e) return;
                if (candidateEdgeEdge(e, f))
                    out.push_back({mEdges[e][0], mEdges[e][1], mEdges[f][0], mEdges[f][1]});
            });
        },
        mCandEe);
}

} // namespace gale::solver
