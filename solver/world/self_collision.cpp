// Self- and cloth–cloth collision (self_collision.h): the three stages of Bridson, Fedkiw &
// Anderson 2002 ("Robust treatment of collisions, contact and friction for cloth animation")
// applied to the substep's end positions x₁ and velocities v, with the step's path taken as the
// straight line x(t) = x₀ + t (x₁ − x₀), t ∈ [0, 1]:
//   1. proximity: pairs closer than ξ at x₁ are pushed apart to ξ along the side they were on at
//      x₀ (a position correction; the approaching part of v is removed, nothing is added),
//      measured at x₁ where they end on that side;
//   2. CCD rounds: pairs whose path comes within ξ_c = ccdFraction·ξ get an inelastic correction
//      of their relative normal displacement (contact/ccd.h, conservative advancement);
//   3. fail-safe: vertices of pairs still hitting are merged into impact zones moved rigidly
//      (Provot 1997; Harmon et al. 2008): x₁ = x₀ + D + ω × (x₀ − c). That map is affine with
//      linear part I + t[ω]× at every t, whose singular values are ≥ 1, so no distance inside a
//      zone shrinks during the step: a zone never hits itself, and zones only grow (union-find)
//      until nothing hits. A zone with pins or attachments keeps their motion and gives its free
//      vertices the rigid motion fitted to theirs; where they do not move together (a collar on
//      a turning body) only its pairs with a held vertex can still meet. Last resort: hold the
//      zones' free vertices at x₀ (the start state, which had no crossings).
// A pair's weights α (Σ α = 0) give its relative position r = Σ α_k x_k; a correction of r by
// Δ n moves vertex k by λ α_k w_k n, w = 1/m (0 for pins and attachments), λ = Δ / Σ α_k² w_k:
// the impulse that conserves momentum.
#include "solver/world/self_collision.h"

#include "solver/world/self_collision_detail.h"

#include "solver/contact/ccd.h"
#include "solver/contact/intersect.h"

#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

namespace gale::solver {

using contact::Box;
using namespace self_collision_detail;

void SelfCollisionStats::add(const SelfCollisionStats& o) {
    passes += o.passes;
    proximityPairs += o.proximityPairs;
    ccdHits += o.ccdHits;
    ccdRounds += o.ccdRounds;
    broadPhases += o.broadPhases;
    halvings += o.halvings;
    retries += o.retries;
    candidates += o.candidates;
    failSafeRuns += o.failSafeRuns;
    zoneVertices += o.zoneVertices;
    frozenVertices += o.frozenVertices;
    unresolved += o.unresolved;
    startTouching = std::max(startTouching, o.startTouching);
    tangledHairVertices = std::max(tangledHairVertices, o.tangledHairVertices);
    broadSeconds += o.broadSeconds;
    proximitySeconds += o.proximitySeconds;
    ccdSeconds += o.ccdSeconds;
    failSafeSeconds += o.failSafeSeconds;
}

void SelfCollision::addBody(Body& body, const std::vector<std::array<int, 3>>& triangles,
                            const VecX& restPositions, double thickness) {
    const int offset = static_cast<int>(mVertexBody.size());
    const int b = static_cast<int>(mBodies.size());
    mBodies.push_back({&body, offset});
    const size_t n = body.vertexCount();
    mVertexBody.insert(mVertexBody.end(), n, b);
    mRest.insert(mRest.end(), restPositions.data(), restPositions.data() + 3 * n);
    mThick.insert(mThick.end(), n, thickness);
    mMaxThickness = std::max(mMaxThickness, thickness);
    for (const auto& t : triangles) {
        mTris.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
        mTriBody.push_back(b);
    }
    mBodyHasTriangles.push_back(!triangles.empty());
    for (const auto& e : body.edges()) mEdges.push_back({e[0] + offset, e[1] + offset});
    // Vertex neighbours by edges, CSR with sorted rows (neighbours()).
    std::vector<std::vector<int>> rows(mVertexBody.size());
    for (const auto& e : mEdges) {
        rows[e[0]].push_back(e[1]);
        rows[e[1]].push_back(e[0]);
    }
    mAdjacencyStart.assign(1, 0);
    mAdjacency.clear();
    for (auto& r : rows) {
        std::sort(r.begin(), r.end());
        mAdjacency.insert(mAdjacency.end(), r.begin(), r.end());
        mAdjacencyStart.push_back(static_cast<int>(mAdjacency.size()));
    }
    mFlat.setTopology(mTris, mVertexBody.size(), std::vector<uint8_t>(mTris.size(), 1));
    mBuilt = false;
    mCandidatesValid = false;
}

void SelfCollision::gather() {
    const size_t n = mVertexBody.size();
    mX1.resize(3 * n);
    mV.resize(3 * n);
    mInvMass.assign(n, 0.0);
    mMass.assign(n, 0.0);
    for (const Member& m : mBodies) {
        const Body& b = *m.body;
        std::copy(b.positions().data(), b.positions().data() + b.positions().size(),
                  mX1.begin() + 3 * m.offset);
        std::copy(b.velocities().data(), b.velocities().data() + b.velocities().size(),
                  mV.begin() + 3 * m.offset);
        // A vertex with no mass of its own (only degenerate triangles) still moves with the
        // solve: it gets a small one (10⁻³ of the mean) rather than counting as held.
        const double floor = 1e-3 * b.masses().sum() / std::max<double>(1.0, b.vertexCount());
        for (size_t i = 0; i < b.vertexCount(); ++i) {
            mMass[m.offset + i] = std::max(b.masses()[static_cast<long>(i)], floor);
            mInvMass[m.offset + i] = mMass[m.offset + i] > 0.0 ? 1.0 / mMass[m.offset + i] : 0.0;
        }
        for (int p : b.pinnedVertices()) mInvMass[m.offset + p] = 0.0;
        // A vertex a collider holds (the ground under a pile) counts as 100× heavier: the pass
        // then moves the cloth above it rather than pushing it into the collider, which would
        // push it back out next substep — a fight that ratchets a resting pile's strain up.
        const std::vector<uint8_t>& touching = b.colliderContacts();
        for (size_t i = 0; i < touching.size(); ++i)
            if (touching[i]) mInvMass[m.offset + i] *= kHeldByCollider;
    }
}

void SelfCollision::scatter() {
    for (const Member& m : mBodies) {
        Body& b = *m.body;
        const long n3 = static_cast<long>(3 * b.vertexCount());
        b.setPositions(Eigen::Map<const VecX>(mX1.data() + 3 * m.offset, n3));
        b.setVelocities(Eigen::Map<const VecX>(mV.data() + 3 * m.offset, n3));
    }
}

double SelfCollision::pairThickness(const Pair& p) const {
    return std::max({mThick[p.v[0]], mThick[p.v[1]], mThick[p.v[2]], mThick[p.v[3]]});
}

double SelfCollision::relativeMotionBound(const Pair& p, bool vertexTriangle) const {
    // l = max over the first primitive's corners of |Δx − m| + the same over the second's, m the
    // mean displacement: a bound on how much the distance can change over the step (ACCD, §4).
    Vec3 d[4], mean = Vec3::Zero();
    for (int k = 0; k < 4; ++k) {
        d[k] = Vec3(vec3At(mX1.data(), p.v[k])) - Vec3(vec3At(mX0.data(), p.v[k]));
        mean += d[k];
    }
    mean /= 4.0;
    // The largest squared norm per side, then one square root each (√ is monotonic and
    // correctly rounded: the same value as the largest of the norms).
    double la = 0.0, lb = 0.0;
    for (int k = 0; k < 4; ++k) {
        double& side = (vertexTriangle ? k < 1 : k < 2) ? la : lb;
        side = std::max(side, (d[k] - mean).squaredNorm());
    }
    return (std::sqrt(la) + std::sqrt(lb)) * (1.0 + 1e-12);
}

double SelfCollision::boxGap(const std::vector<double>& x, const Pair& p,
                             bool vertexTriangle) const {
    // The two primitives' boxes at x and the distance between them: the closest points lie in
    // the boxes, so no pair of points is closer.
    const int first = vertexTriangle ? 1 : 2;
    Vec3 loA = vec3At(x.data(), p.v[0]), hiA = loA;
    Vec3 loB = vec3At(x.data(), p.v[first]), hiB = loB;
    for (int k = 1; k < first; ++k) {
        const Vec3 y = vec3At(x.data(), p.v[k]);
        loA = loA.cwiseMin(y);
        hiA = hiA.cwiseMax(y);
    }
    for (int k = first + 1; k < 4; ++k) {
        const Vec3 y = vec3At(x.data(), p.v[k]);
        loB = loB.cwiseMin(y);
        hiB = hiB.cwiseMax(y);
    }
    return (loA - hiB).cwiseMax(loB - hiA).cwiseMax(0.0).norm();
}

bool SelfCollision::adjacent(int a, int b) const {
    const auto begin = mAdjacency.begin() + mAdjacencyStart[a];
    const auto end = mAdjacency.begin() + mAdjacencyStart[a + 1];
    return std::binary_search(begin, end, b);
}

bool SelfCollision::neighbours(const Pair& p, bool vertexTriangle) const {
    // One edge apart: a vertex and a triangle with a corner next to it, or edges whose ends are
    // joined by an edge. Such a pair comes within ξ only where the cloth creases over an edge;
    // repelling it would fight the crease (bending), stretch the cloth and, in a resting pile,
    // ratchet strain up substep after substep. CCD still keeps it from crossing.
    if (vertexTriangle)
        return adjacent(p.v[0], p.v[1]) || adjacent(p.v[0], p.v[2]) || adjacent(p.v[0], p.v[3]);
    return adjacent(p.v[0], p.v[2]) || adjacent(p.v[0], p.v[3]) || adjacent(p.v[1], p.v[2]) ||
           adjacent(p.v[1], p.v[3]);
}

bool SelfCollision::restClose(const Pair& p, bool vertexTriangle) const {
    if (mVertexBody[p.v[0]] != mVertexBody[p.v[3]]) return false;
    const double xi = pairThickness(p);
    const auto r = [&](int k) { return Vec3(vec3At(mRest.data(), p.v[k])); };
    if (vertexTriangle) {
        double w[3];
        return contact::pointTriangleDistance2(r(0), r(1), r(2), r(3), w) < xi * xi;
    }
    double s, u;
    return contact::segmentSegmentDistance2(r(0), r(1), r(2), r(3), s, u) < xi * xi;
}

namespace {
// The closest points of a candidate at positions x: α and the relative vector Σ α x.
Vec3 closestPair(const std::vector<double>& x, SelfCollision::Pair& p, bool vertexTriangle,
                 double& dist) {
    const auto at = [&](int k) { return Vec3(vec3At(x.data(), p.v[k])); };
    if (vertexTriangle) {
        double w[3];
        dist = std::sqrt(contact::pointTriangleDistance2(at(0), at(1), at(2), at(3), w));
        p.a = {1.0, -w[0], -w[1], -w[2]};
    } else {
        double s, u;
        dist = std::sqrt(contact::segmentSegmentDistance2(at(0), at(1), at(2), at(3), s, u));
        p.a = {1.0 - s, s, -(1.0 - u), -u};
    }
    Vec3 r = Vec3::Zero();
    for (int k = 0; k < 4; ++k) r += p.a[k] * at(k);
    return r;
}

Vec3 relative(const std::vector<double>& x, const SelfCollision::Pair& p) {
    Vec3 r = Vec3::Zero();
    for (int k = 0; k < 4; ++k) r += p.a[k] * Vec3(vec3At(x.data(), p.v[k]));
    return r;
}

// The direction a pair is kept apart along, from its closest-point vector r (length d) at
// positions x: the plane normal of the triangle (vertex–triangle) or e₁ × e₂ (edge–edge) signed
// like r when r is within 45° of it — a vertex over a face, edges crossing — else r / d (a
// vertex beside an edge, edges side by side). Closest points alone tilt the normal of a near
// hit far from the face and push cloth sideways, stretching it.
Vec3 contactNormal(const std::vector<double>& x, const SelfCollision::Pair& p, bool vertexTriangle,
                   const Vec3& r, double d) {
    const auto at = [&](int k) { return Vec3(vec3At(x.data(), p.v[k])); };
    const Vec3 c = vertexTriangle ? Vec3((at(2) - at(1)).cross(at(3) - at(1)))
                                  : Vec3((at(1) - at(0)).cross(at(3) - at(2)));
    const double cn = c.norm();
    const Vec3 rn = r / d;
    if (cn > 0.0) {
        const double cosine = c.dot(rn) / cn;
        if (std::abs(cosine) > 0.7071) return (cosine > 0.0 ? 1.0 : -1.0) * c / cn;
    }
    return rn;
}

// Moves the pair's relative position by Δ along n, momentum-conserving (file comment).
void correct(std::vector<double>& x, const std::vector<double>& invMass,
             const SelfCollision::Pair& p, const Vec3& n, double delta) {
    double denom = 0.0;
    for (int k = 0; k < 4; ++k) denom += p.a[k] * p.a[k] * invMass[p.v[k]];
    if (!(denom > 0.0)) return;
    const double lambda = delta / denom;
    for (int k = 0; k < 4; ++k) vec3At(x.data(), p.v[k]) += (lambda * p.a[k] * invMass[p.v[k]]) * n;
}

// Removes the approaching part of the pair's relative velocity along n (inelastic).
void stopApproach(std::vector<double>& v, const std::vector<double>& invMass,
                  const SelfCollision::Pair& p, const Vec3& n) {
    const double vn = n.dot(relative(v, p));
    if (vn < 0.0) correct(v, invMass, p, n, -vn);
}
} // namespace

int SelfCollision::proximity() {
    ensureCandidates();
    std::vector<Contact>& contacts = mContacts;
    contacts.clear();
    size_t vtCount = 0; // the vertex–triangle pairs come first
    for (int kind = 0; kind < 2; ++kind) {
        const bool vt = kind == 0;
        const std::vector<Candidate>& cands = vt ? mCandVt : mCandEe;
        // Also which pairs CCD must test (the first round adds those proximity moves): the
        // distance is Lipschitz in t with the relative displacement bound l, so d(t) ≥ d₁ − l
        // and a pair with d₁ − l > ξ_c cannot come within ξ_c during the step.
        std::vector<uint8_t>& maybe = mMaybe[kind];
        maybe.assign(cands.size(), 0);
        parallelCollect<Contact>(
            cands.size(),
            [&](size_t c, std::vector<Contact>& out) {
                Pair p{cands[c], {}};
                const double xi = pairThickness(p);
                const double l = relativeMotionBound(p, vt);
                // Early out: the boxes' distance g ≤ d₁, so g − l > ξ (with a margin far above
                // the rounding of either distance) means d₁ − l > ξ > ξ_c: no contact and
                // nothing for CCD — what the exact distance below would decide.
                // A vertex–triangle pair with a held side (a pinned or rigidly attached vertex)
                // is looked at out to planeReach × ξ as well (the near pairs below).
                bool heldSide = false;
                for (int k = 0; k < 4 && vt; ++k) heldSide = heldSide || mInvMass[p.v[k]] == 0.0;
                const double reach = heldSide ? std::max(xi, mSettings.planeReach * xi) : xi;
                const double gap = boxGap(mX1, p, vt);
                if (gap - l > xi * (1.0 + kBoundMargin) && gap > reach * (1.0 + kBoundMargin))
                    return;
                double d1 = 0.0, d0 = 0.0;
                const Vec3 r1 = closestPair(mX1, p, vt, d1);
                if (!(d1 - l > mSettings.ccdFraction * xi)) maybe[c] = 1;
                // Near a held side, not within ξ: the next step's solve gets its plane as well
                // (contactPlanes; marked here by a negative target). The pass can move only the
                // free side of such a pair, so the push it would need once the free side has
                // crossed into ξ lands on a few vertices and stretches the cloth round them.
                if (d1 >= xi && d1 < reach && d1 > kTouching && !restClose(p, vt) &&
                    !neighbours(p, vt))
                    out.push_back({p, contactNormal(mX1, p, vt, r1, d1), -1.0});
                // Within ξ at the end, or at the start (d₀ ≥ d₁ − l): a pair in resting contact
                // keeps its side and normal from x₀ even when the step would take it through.
                if (!(d1 < xi) && !(d1 - l < xi)) return;
                Pair p0 = p;
                const Vec3 r0 = closestPair(mX0, p0, vt, d0);
                if (!(d1 < xi) && !(d0 < xi)) return;
                if (restClose(p, vt) || neighbours(p, vt)) return;
                Vec3 n;
                if (d0 > kTouching) {
                    n = contactNormal(mX0, p0, vt, r0, d0);
                    const Vec3 n1 =
                        d1 > kTouching ? contactNormal(mX1, p, vt, r1, d1) : Vec3(Vec3::Zero());
                    if (n.dot(n1) > 0.0) {
                        // Ending on the side it started (the end's own normal agrees with the
                        // start's): measured in the end's frame, its closest points and normal
                        // (the path between is CCD's), so a pair ξ or more apart is left alone.
                        // The start's frame would measure a pair that slid along a curved
                        // surface short and push it: hair its solve held at ξ off a cloth lost
                        // up to 10 % of its length to such pushes.
                        if (!(d1 < xi)) return;
                        n = n1;
                    } else if (d0 < xi) {
                        p = p0; // the start's closest points: it keeps the side it started on
                    }
                } else if (d1 > kTouching) {
                    n = contactNormal(mX1, p, vt, r1, d1);
                } else {
                    return;
                }
                // A pair already closer than ξ at the start (resting contact, a pile) is kept from
                // closing further and eased a quarter of the way back to ξ per substep: pushing
                // it the whole way every substep fights gravity and the cloth's own elasticity
                // and ratchets strain up in a resting pile.
                const double g0 = n.dot(relative(mX0, p));
                const double target =
                    g0 < xi ? std::max(0.0, g0) + kEase * (xi - std::max(0.0, g0)) : xi;
                out.push_back({p, n, target});
            },
            contacts);
        if (vt) vtCount = contacts.size();
    }
    mMaybeValid = true;
    // The near pairs (vertex–triangle only) apart: planes for the next step, not corrected.
    mNearVt.clear();
    const auto near = std::stable_partition(contacts.begin(), contacts.begin() + vtCount,
                                            [](const Contact& c) { return c.target >= 0.0; });
    mNearVt.assign(near, contacts.begin() + static_cast<std::ptrdiff_t>(vtCount));
    contacts.erase(near, contacts.begin() + static_cast<std::ptrdiff_t>(vtCount));
    vtCount -= mNearVt.size();
    mResting = vtCount; // proximity runs first in a pass: mPassVt is empty before it
    mPassVt.insert(mPassVt.end(), contacts.begin(),
                   contacts.begin() + static_cast<std::ptrdiff_t>(vtCount));
    mPassEe.insert(mPassEe.end(), contacts.begin() + static_cast<std::ptrdiff_t>(vtCount),
                   contacts.end());
    for (int it = 0; it < mSettings.proximityIterations; ++it)
        for (const Contact& c : contacts) {
            const double g = c.n.dot(relative(mX1, c.pair));
            if (g < c.target) correct(mX1, mInvMass, c.pair, c.n, c.target - g);
        }
    for (const Contact& c : contacts) stopApproach(mV, mInvMass, c.pair, c.n);
    return static_cast<int>(contacts.size());
}

int SelfCollision::ccdRound(bool apply, std::vector<Pair>* hits, const std::vector<int>* zone,
                            const std::vector<uint8_t>* dirty) {
    if (ensureCandidates()) dirty = nullptr; // new candidates: no earlier round covered them
    const auto t0 = std::chrono::steady_clock::now();
    ++mStats.ccdRounds;
    std::vector<Contact>& found = mContacts;
    found.clear();
    size_t vtCount = 0; // the vertex–triangle hits come first
    std::atomic<long long> touching{0};
    for (int kind = 0; kind < 2; ++kind) {
        const bool vt = kind == 0;
        const std::vector<Candidate>& cands = vt ? mCandVt : mCandEe;
        const std::vector<uint8_t>* maybe = dirty && mMaybeValid ? &mMaybe[vt ? 0 : 1] : nullptr;
        parallelCollect<Contact>(
            cands.size(),
            [&](size_t c, std::vector<Contact>& hitsOut) {
                Pair p{cands[c], {}};
                // A pair none of whose vertices moved since a round that found it clear, and that
                // was not hit then, has the same path: still clear.
                if (dirty && !(maybe && (*maybe)[c]) && !(*dirty)[p.v[0]] && !(*dirty)[p.v[1]] &&
                    !(*dirty)[p.v[2]] && !(*dirty)[p.v[3]])
                    return;
                // Inside one impact zone the motion is affine with no distance shrinking (file
                // comment): such a pair cannot come closer, so it is not tested.
                if (zone && (*zone)[p.v[0]] >= 0 && (*zone)[p.v[0]] == (*zone)[p.v[1]] &&
                    (*zone)[p.v[0]] == (*zone)[p.v[2]] && (*zone)[p.v[0]] == (*zone)[p.v[3]])
                    return;
                const auto x0 = [&](int k) { return Vec3(vec3At(mX0.data(), p.v[k])); };
                const auto x1 = [&](int k) { return Vec3(vec3At(mX1.data(), p.v[k])); };
                const double xiC = mSettings.ccdFraction * pairThickness(p);
                // Early out as in proximity: the boxes' distance at x₀ bounds d₀ from below, so
                // this is the cheap rejection below (not touching, d₀ − l > ξ_c) decided sooner.
                const double l = relativeMotionBound(p, vt);
                if (boxGap(mX0, p, vt) - l > xiC * (1.0 + kBoundMargin)) return;
                double d0 = 0.0;
                closestPair(mX0, p, vt, d0);
                if (!(d0 > kTouching)) {
                    ++touching;
                    return;
                }
                // Cheap rejection: the distance at x₀ less the largest relative displacement stays
                // above the CCD thickness (the bound conservative advancement starts from).
                if (d0 - l > xiC) return;
                contact::CcdOptions opt;
                opt.thickness = xiC;
                opt.shrinkWithinThickness = true;
                const double xiUsed = d0 <= opt.thickness ? 0.5 * d0 : opt.thickness;
                opt.gapTolerance = std::min(1e-6, 0.05 * xiUsed);
                double toi = 0.0;
                const bool hit = vt ? contact::vertexTriangleCcd(x0(0), x1(0), x0(1), x1(1), x0(2),
                                                                 x1(2), x0(3), x1(3), opt, toi)
                                    : contact::edgeEdgeCcd(x0(0), x1(0), x0(1), x1(1), x0(2), x1(2),
                                                           x0(3), x1(3), opt, toi);
                if (!hit) return;
                // The pair at the time of contact: its closest points and normal.
                std::vector<double> xt(12);
                Pair local = p;
                for (int k = 0; k < 4; ++k) {
                    local.v[k] = k;
                    const Vec3 y = x0(k) + toi * (x1(k) - x0(k));
                    for (int j = 0; j < 3; ++j) xt[3 * k + j] = y[j];
                }
                double dt = 0.0;
                const Vec3 rt = closestPair(xt, local, vt, dt);
                Vec3 n;
                if (dt > kTouching) {
                    n = contactNormal(xt, local, vt, rt, dt);
                } else {
                    Pair q = p;
                    double dd = 0.0;
                    const Vec3 r0 = closestPair(mX0, q, vt, dd);
                    n = contactNormal(mX0, q, vt, r0, dd);
                }
                p.a = local.a;
                // Inelastic: the pair ends where it met, just outside the CCD thickness (a 10 %
                // margin, so the next round finds it clear), its approach along n removed.
                hitsOut.push_back({p, n, std::max(dt, 1.1 * xiUsed)});
            },
            found);
        if (vt) vtCount = found.size();
    }
    mStats.startTouching = std::max(mStats.startTouching, touching.load());
    if (apply) {
        mPassVt.insert(mPassVt.end(), found.begin(),
                       found.begin() + static_cast<std::ptrdiff_t>(vtCount));
        mPassEe.insert(mPassEe.end(), found.begin() + static_cast<std::ptrdiff_t>(vtCount),
                       found.end());
        for (const Contact& c : found) {
            const double g1 = c.n.dot(relative(mX1, c.pair));
            if (g1 < c.target) correct(mX1, mInvMass, c.pair, c.n, c.target - g1);
            stopApproach(mV, mInvMass, c.pair, c.n);
        }
        mStats.ccdHits += static_cast<long long>(found.size());
    }
    mLastHits.clear();
    for (const Contact& c : found) mLastHits.push_back(c.pair);
    if (hits) *hits = mLastHits;
    mStats.ccdSeconds += seconds(t0);
    return static_cast<int>(found.size());
}

std::vector<uint8_t> SelfCollision::dirtySince(const std::vector<double>& before) const {
    // Moved since `before`, or in a pair the last round hit (a hit it did not move stays one).
    std::vector<uint8_t> d(before.size() / 3, 0);
    for (size_t k = 0; k < before.size(); ++k)
        if (before[k] != mX1[k]) d[k / 3] = 1;
    for (const Pair& p : mLastHits)
        for (int v : p.v) d[v] = 1;
    return d;
}

bool SelfCollision::rigidZone(const std::vector<int>& members) const {
    // Rigid when its held vertices (if any) all share one displacement.
    const int* first = nullptr;
    for (const int& i : members) {
        if (mInvMass[i] != 0.0) continue;
        if (!first) first = &i;
        const Vec3 d = vec3At(mD0.data(), *first);
        if ((Vec3(vec3At(mD0.data(), i)) - d).norm() > 1e-12 * (1.0 + d.norm())) return false;
    }
    return true;
}

namespace {

// The motion x₁ = x₀ + D + ω_d × (x₀ − c), v = V + ω_v × (x₀ − c) with the linear and angular
// momentum of `members`' displacements and velocities (weights `weight(i)`): D = Σ w d / Σ w,
// ω = I⁻¹ Σ w r × (d − D), r = x₀ − c, I = Σ w (|r|² I − r rᵀ). Its linear part I + t[ω_d]× has
// singular values ≥ 1 at every t of the step, so no distance it carries shrinks on the way.
struct ZoneMotion {
    Vec3 c = Vec3::Zero(), D = Vec3::Zero(), V = Vec3::Zero(), wd = Vec3::Zero(), wv = Vec3::Zero();
    template <class Weight>
    ZoneMotion(const std::vector<int>& members, const std::vector<double>& x0,
               const std::vector<double>& d0, const std::vector<double>& v0, Weight weight) {
        double mass = 0.0;
        for (int i : members) {
            const double w = weight(i);
            mass += w;
            c += w * Vec3(vec3At(x0.data(), i));
            D += w * Vec3(vec3At(d0.data(), i));
            V += w * Vec3(vec3At(v0.data(), i));
        }
        c /= mass;
        D /= mass;
        V /= mass;
        Mat3 inertia = Mat3::Zero();
        Vec3 Ld = Vec3::Zero(), Lv = Vec3::Zero();
        for (int i : members) {
            const double w = weight(i);
            const Vec3 r = Vec3(vec3At(x0.data(), i)) - c;
            inertia += w * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
            Ld += w * r.cross(Vec3(vec3At(d0.data(), i)) - D);
            Lv += w * r.cross(Vec3(vec3At(v0.data(), i)) - V);
        }
        // A zone on a line (or a point) has no inertia about it: regularise so ω stays finite.
        inertia += (1e-12 * inertia.trace() + 1e-300) * Mat3::Identity();
        const Eigen::LDLT<Mat3> ldlt(inertia);
        wd = ldlt.solve(Ld);
        wv = ldlt.solve(Lv);
    }
    void apply(int i, const std::vector<double>& x0, std::vector<double>& x1,
               std::vector<double>& v) const {
        const Vec3 r = Vec3(vec3At(x0.data(), i)) - c;
        vec3At(x1.data(), i) = Vec3(vec3At(x0.data(), i)) + D + wd.cross(r);
        vec3At(v.data(), i) = V + wv.cross(r);
    }
};

} // namespace

void SelfCollision::applyZone(const std::vector<int>& members) {
    // Pins and attachments in the zone (their own motion kept): the free vertices take the
    // rigid motion fitted to theirs — their common displacement when they share one (static
    // pins, or a translation: the zone is then rigid), else the momentum fit of their
    // displacements (a collar sewn to a turning body: the zone turns with it; no longer rigid,
    // its pairs are tested whole). Without them, the zone's own linear and angular momentum.
    std::vector<int> fixed;
    for (int i : members)
        if (mInvMass[i] == 0.0) fixed.push_back(i);
    const ZoneMotion motion =
        fixed.empty() ? ZoneMotion(members, mX0, mD0, mV0, [&](int i) { return mMass[i]; })
                      : ZoneMotion(fixed, mX0, mD0, mV0, [](int) { return 1.0; });
    for (int i : members)
        if (mInvMass[i] != 0.0) motion.apply(i, mX0, mX1, mV);
}

void SelfCollision::impactZones(std::vector<Pair>& hits) {
    const auto start = std::chrono::steady_clock::now();
    ++mStats.failSafeRuns;
    const size_t n = mVertexBody.size();
    mD0.resize(3 * n);
    for (size_t k = 0; k < 3 * n; ++k) mD0[k] = mX1[k] - mX0[k];
    mV0 = mV;
    DisjointSets sets(n);
    std::vector<uint8_t> inZone(n, 0);
    int round = 0;
    for (; round < mSettings.zoneRounds && !hits.empty(); ++round) {
        for (const Pair& p : hits) {
            for (int k = 0; k < 4; ++k) inZone[p.v[k]] = 1;
            for (int k = 1; k < 4; ++k) sets.join(p.v[0], p.v[k]);
        }
        std::vector<std::vector<int>> zones(n);
        for (size_t i = 0; i < n; ++i)
            if (inZone[i]) zones[sets.find(static_cast<int>(i))].push_back(static_cast<int>(i));
        std::vector<int> zoneOf(n, -1);
        const std::vector<double> before = mX1;
        for (const auto& z : zones)
            if (!z.empty()) {
                applyZone(z);
                // Its free vertices move by one affine map whose distances do not shrink: their
                // pairs are skipped. So are the held ones' when they move together (the zone is
                // rigid); otherwise each pair with a held vertex is tested.
                const bool rigid = rigidZone(z);
                for (int i : z)
                    if (rigid || mInvMass[i] != 0.0) zoneOf[i] = z.front();
            }
        const std::vector<uint8_t> dirty = dirtySince(before);
        ccdRound(false, &hits, &zoneOf, &dirty);
    }
    long long zoneCount = 0;
    for (uint8_t z : inZone) zoneCount += z;
    mStats.zoneVertices += zoneCount;
    // Last resort: free vertices of the zones and of the pairs still hitting stay at x₀.
    for (int r = 0; r < 16 && !hits.empty(); ++r) {
        for (const Pair& p : hits)
            for (int k = 0; k < 4; ++k) inZone[p.v[k]] = 1;
        for (size_t i = 0; i < n; ++i) {
            if (!inZone[i] || mInvMass[i] == 0.0) continue;
            vec3At(mX1.data(), i) = vec3At(mX0.data(), i);
            vec3At(mV.data(), i) = Vec3::Zero();
            ++mStats.frozenVertices;
        }
        ccdRound(false, &hits);
    }
    mStats.unresolved += static_cast<long long>(hits.size());
    mStats.failSafeSeconds += seconds(start);
}

HairThroughCloth hairThroughCloth(const Body& hair, const Body& cloth) {
    HairThroughCloth out;
    if (!cloth.collisionTriangles()) return out;
    const VecX& xh = hair.positions();
    const VecX& xc = cloth.positions();
    const auto through = contact::crossingSegments(
        std::vector<double>(xh.data(), xh.data() + xh.size()), hair.edges(),
        std::vector<double>(xc.data(), xc.data() + xc.size()), *cloth.collisionTriangles());
    if (through.empty()) return out;
    std::vector<uint8_t> seen(hair.edges().size(), 0);
    for (const auto& [seg, tri] : through) out.segments += !seen[static_cast<size_t>(seg)]++;
    const auto [a, b] = hair.edges()[static_cast<size_t>(through[0].first)];
    out.a = a;
    out.b = b;
    out.at = 0.5 * (vec3At(xh.data(), static_cast<size_t>(a)) +
                    vec3At(xh.data(), static_cast<size_t>(b)));
    return out;
}

void SelfCollision::setUntangleHair(bool on) {
    mUntangleHair = on;
    if (!on && !mTangled.empty()) {
        mTangled.clear();
        mCandidatesValid = false;
    }
    mTangledBodies.assign(mBodies.size(), 0);
}

void SelfCollision::updateTangled() {
    if (mHairSegments.empty())
        for (const auto& e : mEdges)
            if (!mBodyHasTriangles[mVertexBody[e[0]]]) mHairSegments.push_back(e);
    // Hair segments through cloth triangles at the pass's start (mTris are the cloth's: hair
    // has none).
    const auto through = contact::crossingSegments(mX0, mHairSegments, mX0, mTris);
    std::vector<uint8_t> tangled;
    mTangledBodies.assign(mBodies.size(), 0);
    if (!through.empty()) {
        tangled.assign(mVertexBody.size(), 0);
        for (const auto& [seg, tri] : through)
            for (int v : mHairSegments[static_cast<size_t>(seg)]) {
                tangled[static_cast<size_t>(v)] = 1;
                mTangledBodies[static_cast<size_t>(mVertexBody[v])] = 1;
            }
    }
    if (tangled != mTangled) mCandidatesValid = false; // the candidates' filter changed
    mTangled = std::move(tangled);
    mStats.tangledHairVertices = 0;
    for (uint8_t t : mTangled) mStats.tangledHairVertices += t;
}

SelfCollisionStats SelfCollision::resolve(const std::vector<VecX>& start) {
    mStats = SelfCollisionStats();
    mX0.resize(3 * mVertexBody.size());
    for (size_t b = 0; b < mBodies.size(); ++b)
        std::copy(start[b].data(), start[b].data() + start[b].size(),
                  mX0.begin() + 3 * mBodies[b].offset);
    if (mUntangleHair) updateTangled();
    gather();
    mLastHits.clear();
    mPassVt.clear();
    mPassEe.clear();
    auto t0 = std::chrono::steady_clock::now();
    std::vector<double> before = mX1;
    mStats.proximityPairs += proximity();
    mStats.proximitySeconds += seconds(t0);
    std::vector<Pair> hits;
    bool clear = false;
    // The first round: the pairs proximity could not rule out, and those it moved.
    std::vector<uint8_t> dirty = dirtySince(before);
    for (int r = 0; r < mSettings.ccdRounds; ++r) {
        before = mX1;
        if (ccdRound(true, nullptr, nullptr, &dirty) == 0) {
            clear = true;
            break;
        }
        dirty = dirtySince(before);
    }
    if (!clear && ccdRound(false, &hits, nullptr, &dirty) > 0) impactZones(hits);
    mStats.passes = 1;
    scatter();
    return mStats;
}

std::vector<std::pair<std::array<int, 2>, std::array<int, 2>>>
SelfCollision::intersections() const {
    std::vector<double> x(3 * mVertexBody.size());
    for (const Member& m : mBodies)
        std::copy(m.body->positions().data(),
                  m.body->positions().data() + m.body->positions().size(),
                  x.begin() + 3 * m.offset);
    const auto pairs = contact::intersectingPairs(x, mTris, mCountTree);
    std::vector<int> firstTri(mBodies.size() + 1, static_cast<int>(mTris.size()));
    for (int t = static_cast<int>(mTris.size()) - 1; t >= 0; --t) firstTri[mTriBody[t]] = t;
    std::vector<std::pair<std::array<int, 2>, std::array<int, 2>>> out;
    for (const auto& [a, b] : pairs)
        out.push_back(
            {{mTriBody[a], a - firstTri[mTriBody[a]]}, {mTriBody[b], b - firstTri[mTriBody[b]]}});
    return out;
}

std::vector<int> SelfCollision::intersectionsPerBody() const {
    std::vector<int> count(mBodies.size(), 0);
    for (const auto& [a, b] : intersections()) {
        ++count[a[0]];
        if (b[0] != a[0]) ++count[b[0]];
    }
    return count;
}

double SelfCollision::minimumSeparation(double radius) const {
    // A copy that can refit its own trees (the query is const for callers).
    SelfCollision probe = *this;
    probe.gather();
    probe.mX0 = probe.mX1;
    probe.mBuilt = false;
    probe.mStats = SelfCollisionStats();
    probe.refitBoxes(probe.mX1, probe.mX1, 0.5 * radius);
    probe.mCandidatesValid = false;
    double best = INFINITY;
    std::vector<Candidate> cands[2];
    probe.gatherCandidates(cands[0], cands[1]);
    for (int kind = 0; kind < 2; ++kind)
        for (const Candidate& c : cands[kind]) {
            Pair p{c, {}};
            double d = 0.0;
            closestPair(probe.mX1, p, kind == 0, d);
            if (d < best && !probe.restClose(p, kind == 0)) best = d;
        }
    return best;
}

} // namespace gale::solver
