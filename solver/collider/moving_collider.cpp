// The moving-mesh contact: tree refits per step, closest points at the step's ends, and the
// CCD pass. The response to a hit at time τ (the surface point q with weights w, the normal n
// from the surface towards the cloth at τ):
//   x₁ ← q(t₁) + ξ n₁   (n₁: the face normal at t₁ on the side of n; for an edge hit, the
//                         cloth edge moved by the shortfall along n, split by its weights as in
//                         Bridson, Fedkiw & Anderson 2002, §7.1),
//   u = v₁ − v_s,  u ← u − min(0, u·n₁) n₁,  |u_t| ← max(0, |u_t| − μ |min(0, u·n₁)|),
// v_s = Σ w_k (p_k(t₁) − p_k(t₀))/h the surface velocity: contact and friction in the moving
// frame of the body. Each pass re-checks the moved trajectories x₀ → x₁; a vertex still hitting
// after the last pass is left at its last projection (counted as unresolved).
// The third pair, a body vertex p (kinematic: infinite mass) against a cloth triangle
// (x_a, x_b, x_c) with weights w at the closest point met, n₁ the cloth's face normal at t₁ on
// the side of p (the direction from the cloth point to p off the face's interior): the cloth
// point c = Σ w_k x_k must end at least ξ from p along n₁, so with the shortfall
// s = ξ − (p(t₁) − c(t₁))·n₁ > 0 each movable corner moves by
//   Δx_k = −(w_k / Σ_j w_j²) s n₁     (pinned corners: w_k = 0 in both places),
// the inelastic impulse of a point against a triangle (Bridson, Fedkiw & Anderson 2002, §7.2)
// with the point's mass infinite: Σ w_k Δx_k = −s n₁, the interpolated point moves exactly s.
// The velocity change Δu of the interpolated point (u = Σ w_k v_k − ṗ, the same approach and
// friction rule as above along −n₁) is split the same way, Δv_k = (w_k / Σ w_j²) Δu.
// A pinned vertex within the thickness (a hair root on the scalp, a collar sewn closer than ξ)
// cannot be moved out, so an edge or triangle carrying it is held off by its clearance c_p (the
// least distance to the body at the step's ends) instead: ξ_e = min(ξ, c_p) in the CCD (ξ_e/2)
// and the response, and the clearance asked of the point met keeps the pinned vertices' own
// shortfalls, by weight:
//   ξ' = ξ_e − Σ_{k pinned} w_k max(0, ξ_e − g_k),   g_k the pinned vertex's clearance along n;
// with one movable vertex m the shortfall is then w_m (ξ_e − g_m) and m moves by at most ξ_e,
// not by (ξ − g)/w_m, unbounded as the point met nears the pin (a root segment thrown 6 m; at
// ξ on a root on the scalp, the next vertex pushed sideways by ξ a pass, its segments 1.45×).
#include "solver/collider/moving_collider.h"

#include "solver/collider/collider.h"
#include "solver/contact/ccd.h"
#include "solver/contact/intersect.h"
#include "solver/mesh/mesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace gale::solver {

namespace {
// A nearest-point search's bound on the squared distance still of interest, from the best so
// far: the slack covers the rounding of the distances (about 16ε of |x|², far below it), so a
// primitive at the same distance is still visited and the lowest index kept.
double withSlack(double best2) {
    return best2 * (1.0 + 1e-9) + 1e-18;
}

double seconds(std::chrono::steady_clock::time_point a) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
}
// A cull before the CCD that gives its answer without its first distance: contact::accd
// (ccd.cpp) returns "no contact" at its first safe advance when stepFraction (d − ξ)/l_p ≥ 1,
// d the start distance and l_p its bound on the relative speed (the corners' displacements
// less their mean: the largest of each primitive's, summed, rounded up by 1e-12). With
// `lower` ≤ d (the distance between the two primitives' boxes at the start, a lower bound) the
// same holds for d, so the pair is clear. `lower` is shrunk by 1e-12 of the scale first (the
// rounding of d is near 16ε of it), and l_p is taken 1e-9 larger than accd's: only pairs that
// accd certainly rejects at its first test are culled, so the hits are those of the CCD alone.
bool clearAtFirstAdvance(const Vec3 x[4], const Vec3 x1[4], int firstCount, double lower,
                         const contact::CcdOptions& opt) {
    Vec3 dx[4], mean = Vec3::Zero();
    for (int i = 0; i < 4; ++i) {
        dx[i] = x1[i] - x[i];
        mean += dx[i];
    }
    mean /= 4.0;
    double scale = 1.0, la = 0.0, lb = 0.0;
    for (int i = 0; i < 4; ++i) {
        double& l = i < firstCount ? la : lb;
        l = std::max(l, (dx[i] - mean).norm());
        scale = std::max(scale, x[i].cwiseAbs().maxCoeff());
    }
    lower -= 1e-12 * scale;
    const double xi = opt.thickness;
    if (!(lower > xi + 2e-12 * scale + opt.gapTolerance)) return false; // near: let ACCD decide
    const double lp = (la + lb) * (1.0 + 1e-9);
    return opt.stepFraction * (lower - xi) >= lp * (1.0 + 1e-9);
}

// The continuous pass's CCD for a primitive held ξ off the surface (sweep(), sweptContact()):
// motions kept ξ/2 from it, and one already within that at the start only kept from crossing.
contact::CcdOptions sweepOptions(double xi) {
    contact::CcdOptions o;
    o.thickness = 0.5 * xi;
    o.shrinkWithinThickness = true;
    return o;
}

Vec3 lerp(const Vec3& a, const Vec3& b, double t) {
    return a + t * (b - a);
}

double boxGap(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
    return std::sqrt((alo - bhi).cwiseMax(blo - ahi).cwiseMax(0.0).squaredNorm());
}

} // namespace

MovingMeshContact::MovingMeshContact(std::shared_ptr<const MeshSequence> mesh)
    : mMesh(std::move(mesh)) {
    mEdges = meshEdges(mMesh->triangles());
    // Closed: 3 T = 2 E with every edge used twice (counted per edge below).
    {
        std::vector<std::array<int, 2>> all;
        for (const auto& t : mMesh->triangles())
            for (int k = 0; k < 3; ++k)
                all.push_back({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
        std::sort(all.begin(), all.end());
        mClosed = !all.empty();
        for (size_t i = 0; i < all.size() && mClosed;) {
            size_t j = i;
            while (j < all.size() && all[j] == all[i]) ++j;
            mClosed = j - i == 2;
            i = j;
        }
    }
    std::vector<uint8_t> used(mMesh->vertexCount(), 0);
    for (const auto& t : mMesh->triangles())
        for (int v : t)
            if (v >= 0 && static_cast<size_t>(v) < used.size()) used[v] = 1;
    for (size_t v = 0; v < used.size(); ++v)
        if (used[v]) mVertices.push_back(static_cast<int>(v));
}

void MovingMeshContact::setMesh(std::shared_ptr<const MeshSequence> mesh) {
    mMesh = std::move(mesh);
    mT0 = mT1 = NAN; // no interval cached: the next prepare() reads both ends
}

Vec3 MovingMeshContact::corner(bool atEnd, int v) const {
    return vec3At((atEnd ? mP1 : mP0).data(), v);
}

Vec3 MovingMeshContact::pointVelocity(int tri, const double w[3], double h) const {
    Vec3 v = Vec3::Zero();
    if (h > 0.0)
        for (int c = 0; c < 3; ++c)
            v += w[c] *
                 (corner(true, mMesh->triangles()[tri][c]) -
                  corner(false, mMesh->triangles()[tri][c])) /
                 h;
    return v;
}

Vec3 MovingMeshContact::faceNormal(bool atEnd, int tri) const {
    const auto& t = mMesh->triangles()[tri];
    const Vec3 a = corner(atEnd, t[0]);
    const Vec3 n = (corner(atEnd, t[1]) - a).cross(corner(atEnd, t[2]) - a);
    const double l = n.norm();
    return l > 0.0 ? Vec3(n / l) : Vec3::UnitY();
}

void MovingMeshContact::prepare(double t0, double t1) {
    if (mBuilt && t0 == mT0 && t1 == mT1) return;
    const auto start = std::chrono::steady_clock::now();
    if (!(mBuilt && t0 == mT1))
        mMesh->positionsAt(t0, mP0);
    else
        mP0.swap(mP1); // consecutive steps: the last end is this start
    mMesh->positionsAt(t1, mP1);
    mT0 = t0;
    mT1 = t1;
    mEndBox = contact::Box();
    for (int v : mVertices) mEndBox.add(corner(true, v));
    // The body's mean displacement over the step: the trees' frame moves with it (mShift).
    Vec3 shift = Vec3::Zero();
    for (int v : mVertices) shift += corner(true, v) - corner(false, v);
    mShift = mVertices.empty() ? Vec3::Zero() : Vec3(shift / static_cast<double>(mVertices.size()));
    if (!mShift.allFinite()) mShift.setZero();
    if (mBuilt && treesStillHold()) {
        ++mStats.kept;
        mStats.refitSeconds += seconds(start);
        return;
    }
    // (Re)fitted in this step's frame: the corners kept for treesStillHold(), and each
    // vertex's box over the step in that frame (its corners at both ends). A primitive's box is
    // the union of its vertices' (the box of all its corners at both ends). Not inflated: every
    // query inflates its own box by its reach (a thickness, a search radius), which is enough
    // (two boxes within the reach of each other are what a pair within it needs).
    mTreeOffset.setZero();
    mTreeSlack = 0.0;
    mRef0.resize(mP0.size());
    mRef1.resize(mP1.size());
    mCornerBoxes.resize(mP0.size() / 3);
    for (int v : mVertices) {
        const Vec3 a = corner(false, v), b = corner(true, v) - mShift;
        vec3At(mRef0.data(), v) = a;
        vec3At(mRef1.data(), v) = b;
        contact::Box& box = mCornerBoxes[v];
        box.lo = a.cwiseMin(b);
        box.hi = a.cwiseMax(b);
    }
    const auto& tris = mMesh->triangles();
    const auto triangleBox = [&](int k) {
        contact::Box b = mCornerBoxes[tris[k][0]];
        b.add(mCornerBoxes[tris[k][1]]);
        b.add(mCornerBoxes[tris[k][2]]);
        return b;
    };
    // The body's edges get their own tree: an edge–edge query then meets only the edges whose
    // swept boxes reach the cloth edge's, not every edge of every triangle it reaches (each
    // three times, to be sorted and made unique).
    const auto edgeBox = [&](int e) {
        contact::Box b = mCornerBoxes[mEdges[e][0]];
        b.add(mCornerBoxes[mEdges[e][1]]);
        return b;
    };
    // And the body's vertices, for the body vertex–cloth triangle pair (queried with each cloth
    // triangle's swept box).
    const auto vertexBox = [&](int k) { return mCornerBoxes[mVertices[k]]; };
    if (!mBuilt) {
        std::vector<contact::Box> boxes(tris.size());
        for (size_t k = 0; k < tris.size(); ++k) boxes[k] = triangleBox(static_cast<int>(k));
        mBvh.build(boxes);
        boxes.resize(mEdges.size());
        for (size_t e = 0; e < mEdges.size(); ++e) boxes[e] = edgeBox(static_cast<int>(e));
        mEdgeBvh.build(boxes);
        boxes.resize(mVertices.size());
        for (size_t k = 0; k < mVertices.size(); ++k) boxes[k] = vertexBox(static_cast<int>(k));
        mVertexBvh.build(boxes);
        mBuilt = true;
        // The slack limit: a tenth of the body's mean edge length (every query reaches that
        // much farther while the trees are kept).
        double sum = 0.0;
        for (const auto& e : mEdges) sum += (corner(false, e[0]) - corner(false, e[1])).norm();
        mSlackLimit = mEdges.empty() ? 0.0 : 0.1 * sum / static_cast<double>(mEdges.size());
        if (!std::isfinite(mSlackLimit)) mSlackLimit = 0.0;
        mStats.buildSeconds += seconds(start);
        return;
    }
    mBvh.refitBy(triangleBox);
    mEdgeBvh.refitBy(edgeBox);
    mVertexBvh.refitBy(vertexBox);
    ++mStats.refits;
    mStats.refitSeconds += seconds(start);
}

// Every corner of this step in its moving frame (c at t0, and at t1 less mShift) against the
// same corner r when the trees were refitted, carried by the offset o = mean(c₀ − r₀): a box
// of the r corners inflated by max |c − o − r| holds the box of the c corners shifted by −o.
bool MovingMeshContact::treesStillHold() {
    if (!(mSlackLimit > 0.0) || mRef0.size() != mP0.size() || mVertices.empty()) return false;
    Vec3 o = Vec3::Zero();
    for (int v : mVertices) o += corner(false, v) - vec3At(mRef0.data(), v);
    o /= static_cast<double>(mVertices.size());
    if (!o.allFinite()) return false;
    double slack2 = 0.0, scale = 0.0;
    const double limit2 = mSlackLimit * mSlackLimit;
    for (int v : mVertices) {
        const Vec3 a = corner(false, v);
        const Vec3 b = corner(true, v) - mShift;
        slack2 = std::max({slack2, (a - o - vec3At(mRef0.data(), v)).squaredNorm(),
                           (b - o - vec3At(mRef1.data(), v)).squaredNorm()});
        if (!(slack2 <= limit2)) return false; // (NaN too)
        scale = std::max(scale, a.cwiseAbs().maxCoeff());
    }
    // Rounded up: the differences above and the offset's subtraction in the queries.
    mTreeSlack = std::sqrt(slack2) * (1.0 + 1e-9) + 1e-12 * std::max(scale, 1.0);
    mTreeOffset = o;
    return true;
}

bool MovingMeshContact::closest(const Vec3& x, bool atEnd, double radius, ContactPoint& out,
                                int hint) const {
    out.distance = INFINITY;
    if (!mBuilt) return false;
    // The tree's boxes hold each triangle at t0 and at t1 in the frame moving with the body:
    // a query at the end is made there too.
    const Vec3 xq = atEnd ? endQuery(x) : x;
    double best = radius * radius;
    int bestTri = -1;
    double bestW[3] = {0, 0, 0};
    const auto& tris = mMesh->triangles();
    // Triangle k against the best so far: the lowest (distance, triangle) pair is kept, so the
    // result does not depend on the order of the visits.
    const auto consider = [&](int k) {
        double w[3];
        const double d2 = contact::pointTriangleDistance2(
            x, corner(atEnd, tris[k][0]), corner(atEnd, tris[k][1]), corner(atEnd, tris[k][2]), w);
        if (d2 < best || (d2 == best && bestTri >= 0 && k < bestTri)) {
            best = d2;
            bestTri = k;
            std::copy(w, w + 3, bestW);
        }
    };
    // The hint's distance bounds the walk from the start (met again in the walk, it changes
    // nothing).
    if (hint >= 0 && static_cast<size_t>(hint) < tris.size()) consider(hint);
    // A nearest-point walk: a node or triangle whose box is farther than the best distance so
    // far cannot hold a closer point (the boxes hold the triangles at both ends of the step), so
    // it is skipped; the closer child first.
    mBvh.nearestFirst([&](const contact::Box& b) { return treeDistance2(b, xq); },
                      [&] { return withSlack(best); },
                      [&](int k, const contact::Box&) { consider(k); });
    if (bestTri < 0) return false;
    const auto& t = tris[bestTri];
    Vec3 p = Vec3::Zero();
    for (int c = 0; c < 3; ++c) p += bestW[c] * corner(atEnd, t[c]);
    const Vec3 d = x - p;
    const double dist = d.norm();
    const Vec3 fn = faceNormal(atEnd, bestTri);
    out.distance = dist;
    out.triangle = bestTri;
    out.normal = dist > 1e-12 ? Vec3(d / dist) : fn;
    out.velocity = pointVelocity(bestTri, bestW, mT1 - mT0);
    return true;
}

bool MovingMeshContact::nearestVertex(const Vec3& a, const Vec3& b, const Vec3& c, double radius,
                                      Vec3& p, double w[3], double& distance,
                                      Vec3& velocity) const {
    if (!mBuilt) return false;
    double best = radius * radius;
    int bestVertex = -1;
    // Nearest first, as closest(): the box of the triangle against the vertices' boxes bounds
    // the distance from below; the lowest (distance, vertex) pair is kept.
    contact::Box tb;
    tb.add(a);
    tb.add(b);
    tb.add(c);
    mVertexBvh.nearestFirst(
        [&](const contact::Box& box) { return treeDistance2(box, tb); },
        [&] { return withSlack(best); },
        [&](int k, const contact::Box&) {
            const int v = mVertices[k];
            double wk[3];
            const double d2 = contact::pointTriangleDistance2(corner(false, v), a, b, c, wk);
            if (d2 < best || (d2 == best && bestVertex >= 0 && v < bestVertex)) {
                best = d2;
                bestVertex = v;
                std::copy(wk, wk + 3, w);
            }
        });
    if (bestVertex < 0) return false;
    p = corner(false, bestVertex);
    distance = std::sqrt(best);
    const double h = mT1 - mT0;
    velocity = h > 0.0 ? Vec3((corner(true, bestVertex) - p) / h) : Vec3::Zero();
    return true;
}

void MovingMeshContact::vertexCandidates(const Vec3& p0, const Vec3& p1, double reach,
                                         std::vector<int>& cand) const {
    contact::Box q;
    addSwept(q, p0, p1);
    q.inflate(reach);
    cand.clear();
    mBvh.queryEach(inTrees(q), [&](int k) { cand.push_back(k); });
    std::sort(cand.begin(), cand.end()); // triangle order: a fixed tie-break
}

MovingMeshContact::VertexHit
MovingMeshContact::firstVertexHit(const Vec3& p0, const Vec3& p1, const std::vector<int>& cand,
                                  const contact::CcdOptions& opt) const {
    VertexHit hit;
    const auto& tris = mMesh->triangles();
    double first = 2.0;
    for (int k : cand) {
        const auto& t = tris[k];
        double toi;
        const Vec3 s0[4] = {p0, corner(false, t[0]), corner(false, t[1]), corner(false, t[2])};
        const Vec3 s1[4] = {p1, corner(true, t[0]), corner(true, t[1]), corner(true, t[2])};
        const Vec3 lo = s0[1].cwiseMin(s0[2]).cwiseMin(s0[3]),
                   hi = s0[1].cwiseMax(s0[2]).cwiseMax(s0[3]);
        if (clearAtFirstAdvance(s0, s1, 1, boxGap(p0, p0, lo, hi), opt)) continue;
        if (contact::vertexTriangleCcd(p0, p1, corner(false, t[0]), corner(true, t[0]),
                                       corner(false, t[1]), corner(true, t[1]), corner(false, t[2]),
                                       corner(true, t[2]), opt, toi) &&
            toi < first) {
            first = toi;
            hit.triangle = k;
        }
    }
    if (hit.triangle < 0) return hit;
    const auto& t = tris[hit.triangle];
    const Vec3 a = lerp(corner(false, t[0]), corner(true, t[0]), first),
               b = lerp(corner(false, t[1]), corner(true, t[1]), first),
               c = lerp(corner(false, t[2]), corner(true, t[2]), first);
    const Vec3 pt = lerp(p0, p1, first);
    double* w = hit.w;
    contact::pointTriangleDistance2(pt, a, b, c, w);
    const Vec3 q0 = w[0] * a + w[1] * b + w[2] * c;
    Vec3 nt = pt - q0;
    const Vec3 fnt = (b - a).cross(c - a);
    if (!(nt.norm() > 1e-12)) nt = fnt.dot(p0 - q0) >= 0.0 ? fnt : Vec3(-fnt);
    const Vec3 fn1 = faceNormal(true, hit.triangle);
    // The side the vertex is on, carried to the end of the step with the face.
    hit.normal = fn1.dot(nt) >= 0.0 ? fn1 : Vec3(-fn1);
    // Off a face's interior use the direction to the closest point's feature instead (edges and
    // corners: the normal of the face does not separate there).
    const bool interior = w[0] > 1e-9 && w[1] > 1e-9 && w[2] > 1e-9;
    if (!interior) hit.normal = nt.normalized();
    hit.point = w[0] * corner(true, t[0]) + w[1] * corner(true, t[1]) + w[2] * corner(true, t[2]);
    return hit;
}

int MovingMeshContact::endCrossings(const Vec3& a, const Vec3& b, bool first) const {
    // The segment's box at the end pose, in the trees' frame (endQuery), whose boxes hold every
    // triangle at the step's end.
    contact::Box q;
    q.add(endQuery(a));
    q.add(endQuery(b));
    const auto& tris = mMesh->triangles();
    int crossings = 0;
    mBvh.queryEach(inTrees(q), [&](int k) {
        if (first && crossings > 0) return;
        const auto& t = tris[k];
        if (contact::segmentCrossesTriangle(a, b, corner(true, t[0]), corner(true, t[1]),
                                            corner(true, t[2])))
            ++crossings;
    });
    return crossings;
}

int MovingMeshContact::movesThroughSurface(const VecX& from, const VecX& to,
                                           std::vector<int>* which) const {
    if (!mBuilt || from.size() != to.size()) return 0;
    int count = 0;
    for (Eigen::Index i = 0; 3 * i + 2 < from.size(); ++i) {
        const Vec3 a = vec3At(from.data(), i), b = vec3At(to.data(), i);
        if (a == b || !a.allFinite() || !b.allFinite()) continue;
        if (endCrossings(a, b, true) > 0) {
            ++count;
            if (which) which->push_back(static_cast<int>(i));
        }
    }
    return count;
}

double MovingMeshContact::insideDepth(const Vec3& x) const {
    if (!mBuilt || !mClosed || !x.allFinite()) return 0.0;
    // The surface's box at the end (prepare()); a point outside it is outside.
    const contact::Box& box = mEndBox;
    if ((x.array() < box.lo.array()).any() || (x.array() > box.hi.array()).any()) return 0.0;
    // A ray out through the box's nearest face (the fewest triangles on its way), along a
    // direction tilted off the axes so that no mesh is aligned with it (a crossing exactly
    // through an edge or a vertex, counted twice, is then a measure-zero event).
    int axis = 0;
    double sign = 1.0, nearest = INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (box.hi[a] - x[a] < nearest) nearest = box.hi[a] - x[a], axis = a, sign = 1.0;
        if (x[a] - box.lo[a] < nearest) nearest = x[a] - box.lo[a], axis = a, sign = -1.0;
    }
    Vec3 dir(0.0130986, 0.0217538, 0.0174322);
    dir[axis] = sign;
    const double reach = (box.hi - box.lo).norm() + 1e-3;
    if (endCrossings(x, x + reach * dir.normalized(), false) % 2 == 0) return 0.0;
    ContactPoint cp;
    return closest(x, true, INFINITY, cp) ? std::max(cp.distance, 1e-12) : 1e-12;
}

bool MovingMeshContact::sweptContact(const Vec3& p0, const Vec3& p1, double thickness,
                                     ContactPoint& out) const {
    if (!mBuilt || !p0.allFinite() || !p1.allFinite()) return false;
    const contact::CcdOptions opt = sweepOptions(thickness);
    std::vector<int> cand;
    vertexCandidates(p0, p1, opt.thickness + 2.0 * opt.gapTolerance, cand);
    const VertexHit hit = firstVertexHit(p0, p1, cand, opt);
    if (hit.triangle < 0) return false;
    out.distance = (p1 - hit.point).dot(hit.normal);
    out.normal = hit.normal;
    out.velocity = pointVelocity(hit.triangle, hit.w, mT1 - mT0);
    out.triangle = hit.triangle;
    return true;
}

bool MovingMeshContact::firstEdgeHit(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                                     const contact::CcdOptions& opt, double reach,
                                     std::vector<int>& cand, EdgeHit& hit) const {
    contact::Box q;
    addSwept(q, a0, a1);
    addSwept(q, b0, b1);
    q.inflate(reach);
    cand.clear();
    // The edges whose own swept boxes reach the cloth edge's, in edge order. The edges of the
    // triangles reached whose boxes do not are farther than the CCD's ξ/2 from the cloth edge
    // throughout the step (the query's box is inflated by `reach`), so they cannot be hit.
    mEdgeBvh.queryEach(inTrees(q), [&](int k) { cand.push_back(k); });
    std::sort(cand.begin(), cand.end());
    double first = 2.0;
    int hitEdge = -1;
    for (int k : cand) {
        const int r = mEdges[k][0], s = mEdges[k][1];
        double toi;
        const Vec3 s0[4] = {a0, b0, corner(false, r), corner(false, s)};
        const Vec3 s1[4] = {a1, b1, corner(true, r), corner(true, s)};
        if (clearAtFirstAdvance(s0, s1, 2,
                                boxGap(a0.cwiseMin(b0), a0.cwiseMax(b0), s0[2].cwiseMin(s0[3]),
                                       s0[2].cwiseMax(s0[3])),
                                opt))
            continue;
        if (contact::edgeEdgeCcd(a0, a1, b0, b1, corner(false, r), corner(true, r),
                                 corner(false, s), corner(true, s), opt, toi) &&
            toi < first) {
            first = toi;
            hitEdge = k;
        }
    }
    if (hitEdge < 0) return false;
    const int r = mEdges[hitEdge][0], s = mEdges[hitEdge][1];
    double sa, sb;
    const Vec3 pa = lerp(a0, a1, first), pb = lerp(b0, b1, first);
    const Vec3 pr = lerp(corner(false, r), corner(true, r), first),
               ps = lerp(corner(false, s), corner(true, s), first);
    contact::segmentSegmentDistance2(pa, pb, pr, ps, sa, sb);
    Vec3 nt = (pa + sa * (pb - pa)) - (pr + sb * (ps - pr));
    if (!(nt.norm() > 1e-12)) nt = (pb - pa).cross(ps - pr);
    if (!(nt.norm() > 1e-12)) nt = Vec3::UnitY();
    hit.edge = hitEdge;
    hit.toi = first;
    hit.sa = sa;
    hit.sb = sb;
    hit.normal = nt.normalized();
    // At the end: the body point at the same parameter, and its move over the step.
    const Vec3 r1 = corner(true, r), s1 = corner(true, s);
    hit.body1 = r1 + sb * (s1 - r1);
    hit.displacement = (1.0 - sb) * (r1 - corner(false, r)) + sb * (s1 - corner(false, s));
    return true;
}

contact::CcdOptions MovingMeshContact::passOptions(double xi) const {
    contact::CcdOptions o = sweepOptions(xi);
    o.thickness += mRadius;
    return o;
}

bool MovingMeshContact::edgeContact(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                                    double thickness, std::vector<int>& cand, EdgeHit& hit) const {
    if (!mBuilt || !a0.allFinite() || !a1.allFinite() || !b0.allFinite() || !b1.allFinite())
        return false;
    const contact::CcdOptions opt = passOptions(thickness);
    return firstEdgeHit(a0, a1, b0, b1, opt, opt.thickness + 2.0 * opt.gapTolerance, cand, hit);
}

bool MovingMeshContact::firstFaceHit(const Vec3 c0[3], const Vec3 c1[3],
                                     const contact::CcdOptions& opt, double reach,
                                     std::vector<int>& cand, FaceHit& hit) const {
    contact::Box q;
    for (int k = 0; k < 3; ++k) addSwept(q, c0[k], c1[k]);
    q.inflate(reach);
    cand.clear();
    mVertexBvh.queryEach(inTrees(q), [&](int k) { cand.push_back(k); });
    std::sort(cand.begin(), cand.end()); // body vertex order: a fixed tie-break
    const Vec3 lo = c0[0].cwiseMin(c0[1]).cwiseMin(c0[2]),
               hi = c0[0].cwiseMax(c0[1]).cwiseMax(c0[2]);
    double first = 2.0;
    int hitVertex = -1;
    for (int k : cand) {
        const int b = mVertices[k];
        const Vec3 p0 = corner(false, b), p1 = corner(true, b);
        const Vec3 s0[4] = {p0, c0[0], c0[1], c0[2]};
        const Vec3 s1[4] = {p1, c1[0], c1[1], c1[2]};
        if (clearAtFirstAdvance(s0, s1, 1, boxGap(p0, p0, lo, hi), opt)) continue;
        double toi;
        if (contact::vertexTriangleCcd(p0, p1, c0[0], c1[0], c0[1], c1[1], c0[2], c1[2], opt,
                                       toi) &&
            toi < first) {
            first = toi;
            hitVertex = b;
        }
    }
    if (hitVertex < 0) return false;
    const Vec3 p0 = corner(false, hitVertex), p1 = corner(true, hitVertex);
    const Vec3 pt = lerp(p0, p1, first);
    const Vec3 a = lerp(c0[0], c1[0], first), b = lerp(c0[1], c1[1], first),
               c = lerp(c0[2], c1[2], first);
    double* w = hit.w;
    contact::pointTriangleDistance2(pt, a, b, c, w);
    const Vec3 qt = w[0] * a + w[1] * b + w[2] * c;
    // From the cloth towards the body vertex, at τ; touching: the face normal on the side the
    // vertex started.
    Vec3 nt = pt - qt;
    if (!(nt.norm() > 1e-12)) {
        const Vec3 fnt = (b - a).cross(c - a);
        const Vec3 qs = w[0] * c0[0] + w[1] * c0[1] + w[2] * c0[2];
        nt = fnt.dot(p0 - qs) >= 0.0 ? fnt : Vec3(-fnt);
    }
    if (!(nt.norm() > 1e-12)) nt = Vec3::UnitY();
    nt.normalize();
    // The side carried to the end of the step with the face; off its interior the direction to
    // the feature met (the face normal does not separate there).
    Vec3 n1 = nt;
    const Vec3 fn1 = (c1[1] - c1[0]).cross(c1[2] - c1[0]);
    const bool interior = w[0] > 1e-9 && w[1] > 1e-9 && w[2] > 1e-9;
    if (interior && fn1.norm() > 1e-12) {
        n1 = fn1.normalized();
        if (n1.dot(nt) < 0.0) n1 = -n1;
    }
    hit.vertex = hitVertex;
    hit.toi = first;
    hit.p0 = p0;
    hit.p1 = p1;
    hit.normal = n1;
    return true;
}

bool MovingMeshContact::faceContact(const Vec3 c0[3], const Vec3 c1[3], double thickness,
                                    std::vector<int>& cand, FaceHit& hit) const {
    for (int k = 0; k < 3; ++k)
        if (!c0[k].allFinite() || !c1[k].allFinite()) return false;
    if (!mBuilt) return false;
    const contact::CcdOptions opt = passOptions(thickness);
    return firstFaceHit(c0, c1, opt, opt.thickness + 2.0 * opt.gapTolerance, cand, hit);
}

int MovingMeshContact::sweep(const VecX& x0, VecX& x1, VecX& v1,
                             const std::vector<uint8_t>& movable,
                             const std::vector<std::array<int, 2>>& edges,
                             const std::vector<std::array<int, 3>>& triangles, double thickness,
                             double friction, double h, int passes, std::vector<Vec3>* normals) {
    if (!mBuilt) return 0;
    const auto sweepStart = std::chrono::steady_clock::now();
    // Per-primitive clocks (broad, narrow, face) only when asked for: two clock reads for every
    // vertex, edge and triangle were 7 % of examples/10_hair_turn's time.
    const auto tick = [&] {
        return mDetailedTiming ? std::chrono::steady_clock::now()
                               : std::chrono::steady_clock::time_point{};
    };
    const auto since = [&](std::chrono::steady_clock::time_point t) {
        return mDetailedTiming ? seconds(t) : 0.0;
    };
    const size_t n = x0.size() / 3;
    // The continuous pass keeps motions from coming closer than half the thickness (a crossing
    // needs less); hits are placed at the full thickness, so that a re-check of the corrected
    // motion has half the thickness to spare (no re-hit on resting contact), and the push-out
    // after it (Body::resolveContacts) restores the full thickness everywhere else.
    // Already within the thickness at the start (resting contact): only crossing is caught
    // (shrinkWithinThickness), the push-out restores ξ, so a vertex that leaves is not held back.
    // For a primitive held off the body by ξ: the CCD's options, and the distance a hit is
    // placed at (ξ and ξ/2 as above; ξ_e below for pinned vertices within the thickness).
    // (A thin collider's centre or axis, setRadius: ξ measured from its surface, r out.)
    const auto placedAt = [&](double xi) { return xi * (1.0 + 1e-6) + 1e-9 + mRadius; };
    const contact::CcdOptions opt = passOptions(thickness);
    // The broad phase's reach: the CCD asks for at most ξ/2 (less for pinned corners), and the
    // swept boxes hold each primitive throughout the step (its points are convex combinations
    // of its corners at both ends), so a pair whose boxes are farther apart than ξ/2 stays
    // farther apart than that: it is no hit (beyond the CCD's gap tolerance, 1 µm, for which
    // the reach has room).
    const double reach = opt.thickness + 2.0 * opt.gapTolerance;
    std::vector<int> cand;
    std::vector<uint8_t> moved(n, 0);
    // Cloth triangles hit by a body vertex that no movable corner can carry (all pinned, or the
    // point met on a pinned corner): counted unresolved once and left alone.
    std::vector<uint8_t> stuck(triangles.size(), 0);
    int movedCount = 0;
    // The velocity response at vertex i against a surface point moving at vs, normal n1.
    auto respond = [&](int i, const Vec3& vs, const Vec3& n1) {
        Eigen::Map<Vec3> v(v1.data() + 3 * i);
        Vec3 u = v - vs;
        const double un = u.dot(n1);
        if (un < 0.0) {
            u -= un * n1;
            const Vec3 ut = u - n1 * u.dot(n1);
            const double ts = ut.norm();
            if (ts > 0.0) u -= std::min(1.0, friction * (-un) / ts) * ut;
        }
        v = vs + u;
        if (normals) (*normals)[static_cast<size_t>(i)] = n1;
        if (!moved[i]) {
            moved[i] = 1;
            ++movedCount;
        }
    };
    // Pinned vertices within the thickness (a hair root on the scalp, a collar sewn closer than
    // ξ): their clearance over the step, the most an edge or triangle they carry can be held off.
    std::vector<double> pinClear;
    auto clearanceOf = [&](int v) {
        if (movable[v]) return thickness;
        if (pinClear.empty()) pinClear.assign(n, -1.0);
        double& c = pinClear[v];
        if (c < 0.0) {
            c = thickness;
            ContactPoint cp;
            const double r = thickness + mRadius;
            if (closest(vec3At(x0.data(), v), false, r, cp)) c = std::min(c, cp.distance - mRadius);
            if (closest(vec3At(x1.data(), v), true, r, cp)) c = std::min(c, cp.distance - mRadius);
            c = std::max(c, 1e-3 * thickness); // on the surface: only crossing is caught
        }
        return c;
    };
    for (int pass = 0; pass < passes; ++pass) {
        int hits = 0;
        // Vertices against triangles.
        for (size_t i = 0; i < n && mVertexPairs; ++i) {
            if (!movable[i]) continue;
            const Vec3 p0 = vec3At(x0.data(), i), p1 = vec3At(x1.data(), i);
            if (!p0.allFinite() || !p1.allFinite()) continue; // left to the trouble detector
            auto tb = tick();
            vertexCandidates(p0, p1, reach, cand);
            mStats.broadSeconds += since(tb);
            mStats.candidates += static_cast<long long>(cand.size());
            auto tn = tick();
            const VertexHit hit = firstVertexHit(p0, p1, cand, opt);
            mStats.narrowSeconds += since(tn);
            if (hit.triangle < 0) continue;
            // Placed ξ off the point it met, as that point is at the step's end, on the side it
            // came from: held there, moving on with the surface. An open surface (a sagging
            // cloth under hair): ξ off the face's plane through that point, its tangential
            // displacement from it cut by Coulomb's bound on the position, at most μ × the
            // normal correction δ (μ = 0: lifted straight out, its own slide kept, so a path
            // that only dipped within ξ/2 of the deforming cloth is not dragged back along it).
            Eigen::Map<Vec3> x1i(x1.data() + 3 * i);
            if (mOpen) {
                const Vec3 off = x1i - hit.point;
                const double above = off.dot(hit.normal);
                const Vec3 slide = off - above * hit.normal;
                const double delta = std::max(0.0, placedAt(thickness) - above);
                const double length = slide.norm();
                const double keep =
                    length > 0.0 ? std::max(0.0, 1.0 - friction * delta / length) : 0.0;
                x1i = hit.point + std::max(above, placedAt(thickness)) * hit.normal + keep * slide;
            } else {
                x1i = hit.point + placedAt(thickness) * hit.normal;
            }
            respond(static_cast<int>(i), pointVelocity(hit.triangle, hit.w, h), hit.normal);
            ++hits;
            ++mStats.vertexHits;
        }
        // Cloth edges against body edges.
        for (const auto& e : edges) {
            const int i = e[0], j = e[1];
            if (!movable[i] && !movable[j]) continue;
            const double xiE = std::min(clearanceOf(i), clearanceOf(j));
            const contact::CcdOptions optE = passOptions(xiE);
            const double wantE = placedAt(xiE);
            const Vec3 a0 = vec3At(x0.data(), i), a1 = vec3At(x1.data(), i);
            const Vec3 b0 = vec3At(x0.data(), j), b1 = vec3At(x1.data(), j);
            if (!a0.allFinite() || !a1.allFinite() || !b0.allFinite() || !b1.allFinite()) continue;
            auto tb = tick();
            EdgeHit hit;
            const bool found = firstEdgeHit(a0, a1, b0, b1, optE, reach, cand, hit);
            mStats.broadSeconds += since(tb);
            mStats.candidates += static_cast<long long>(cand.size());
            auto tn = tick();
            if (found) {
                const double sa = hit.sa;
                const Vec3 nn = hit.normal, body1 = hit.body1;
                Eigen::Map<Vec3> xa(x1.data() + 3 * i), xb(x1.data() + 3 * j);
                const Vec3 cloth1 = xa + sa * (xb - xa);
                const double gap = (cloth1 - body1).dot(nn);
                // A pinned end within the thickness keeps its own shortfall (ξ' above).
                const double wantHere =
                    wantE -
                    (movable[i] ? 0.0 : (1.0 - sa) * std::max(0.0, wantE - (xa - body1).dot(nn))) -
                    (movable[j] ? 0.0 : sa * std::max(0.0, wantE - (xb - body1).dot(nn)));
                if (gap < wantHere) {
                    // Move the cloth point by (ξ' − gap) n: the edge's vertices by their
                    // weights, scaled so the interpolated point moves exactly that far.
                    const double wa = movable[i] ? 1.0 - sa : 0.0, wb = movable[j] ? sa : 0.0;
                    const double norm = wa * (1.0 - sa) + wb * sa;
                    if (norm > 1e-12) {
                        const Vec3 d = ((wantHere - gap) / norm) * nn;
                        xa += wa * d;
                        xb += wb * d;
                    }
                }
                const Vec3 vs = h > 0.0 ? Vec3(hit.displacement / h) : Vec3::Zero();
                if (movable[i]) respond(i, vs, nn);
                if (movable[j]) respond(j, vs, nn);
                ++hits;
                ++mStats.edgeHits;
            }
            mStats.narrowSeconds += since(tn);
        }
        // Body vertices against cloth triangles: a body part thinner than the cloth's edges (a
        // finger, a rod) can pass through a face with no cloth vertex inside it and no edge
        // crossing an edge; only its vertices meet the face.
        for (size_t f = 0; f < triangles.size(); ++f) {
            if (stuck[f]) continue;
            const int* tv = triangles[f].data();
            Vec3 c0[3], c1[3];
            bool finite = true;
            for (int k = 0; k < 3; ++k) {
                c0[k] = vec3At(x0.data(), tv[k]);
                c1[k] = vec3At(x1.data(), tv[k]);
                finite = finite && c0[k].allFinite() && c1[k].allFinite();
            }
            if (!finite) continue; // left to the trouble detector
            const double xiT =
                std::min({clearanceOf(tv[0]), clearanceOf(tv[1]), clearanceOf(tv[2])});
            const contact::CcdOptions optT = passOptions(xiT);
            const double wantT = placedAt(xiT);
            auto tb = tick();
            FaceHit hit;
            const bool found = firstFaceHit(c0, c1, optT, reach, cand, hit);
            const double broad = since(tb);
            mStats.broadSeconds += broad;
            mStats.candidates += static_cast<long long>(cand.size());
            mStats.faceCandidates += static_cast<long long>(cand.size());
            auto tn = tick();
            if (found) {
                const Vec3 p0 = hit.p0, p1 = hit.p1, n1 = hit.normal;
                const double* w = hit.w;
                double wm[3], norm = 0.0;
                for (int k = 0; k < 3; ++k) {
                    wm[k] = movable[tv[k]] ? w[k] : 0.0;
                    norm += wm[k] * wm[k];
                }
                if (!(norm > 1e-12)) {
                    // Nothing movable carries the point met: the body passes.
                    stuck[f] = 1;
                    ++mStats.unresolved;
                } else {
                    const Vec3 cloth1 = w[0] * c1[0] + w[1] * c1[1] + w[2] * c1[2];
                    const double gap = (p1 - cloth1).dot(n1);
                    // Pinned corners within the thickness keep their own clearance (as above).
                    double wantHere = wantT;
                    for (int k = 0; k < 3; ++k)
                        if (!movable[tv[k]])
                            wantHere -= w[k] * std::max(0.0, wantT - (p1 - c1[k]).dot(n1));
                    if (gap < wantHere) {
                        const Vec3 d = (-(wantHere - gap) / norm) * n1;
                        for (int k = 0; k < 3; ++k) vec3At(x1.data(), tv[k]) += wm[k] * d;
                    }
                    // The velocity of the cloth point relative to the body vertex's, along the
                    // normal from the body towards the cloth.
                    const Vec3 vb = h > 0.0 ? Vec3((p1 - p0) / h) : Vec3::Zero();
                    const Vec3 nc = -n1;
                    Vec3 u = -vb;
                    for (int k = 0; k < 3; ++k) u += w[k] * vec3At(v1.data(), tv[k]);
                    const double un = u.dot(nc);
                    if (un < 0.0) {
                        Vec3 du = -un * nc;
                        const Vec3 ut = u - un * nc;
                        const double ts = ut.norm();
                        if (ts > 0.0) du -= std::min(1.0, friction * (-un) / ts) * ut;
                        for (int k = 0; k < 3; ++k) vec3At(v1.data(), tv[k]) += (wm[k] / norm) * du;
                    }
                    for (int k = 0; k < 3; ++k) {
                        if (wm[k] > 0.0 && normals) (*normals)[static_cast<size_t>(tv[k])] = nc;
                        if (wm[k] > 0.0 && !moved[tv[k]]) {
                            moved[tv[k]] = 1;
                            ++movedCount;
                        }
                    }
                    ++hits;
                    ++mStats.faceHits;
                }
            }
            const double narrow = since(tn);
            mStats.narrowSeconds += narrow;
            mStats.faceSeconds += broad + narrow;
        }
        if (hits == 0) break;
        if (pass == passes - 1) mStats.unresolved += hits;
    }
    mStats.sweepSeconds += seconds(sweepStart);
    return movedCount;
}

} // namespace gale::solver
