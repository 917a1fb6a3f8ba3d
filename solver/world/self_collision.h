// Cloth against itself and against other cloth: after each base substep of every colliding body,
// a pass over their combined vertices that keeps the motion from x₀ to x₁ free of crossings —
// proximity repulsion to the thickness, continuous collision (vertex–triangle and edge–edge
// CCD with a thickness, solver/contact/ccd.h) with inelastic corrections, and rigid impact zones
// as the fail-safe (Bridson, Fedkiw & Anderson 2002; Harmon et al. 2008). docs/solver.md.
#pragma once

#include "solver/bodies/body.h"
#include "solver/contact/bvh.h"
#include "solver/world/flat_patches.h"

#include <array>
#include <utility>
#include <vector>

namespace gale::solver {

// Counts and timings of the passes (accumulated; run statistics and the benchmark).
struct SelfCollisionStats {
    long long passes = 0;         // substeps resolved
    long long proximityPairs = 0; // pairs found closer than the thickness at x₁
    long long ccdHits = 0;        // CCD hits corrected
    long long ccdRounds = 0;      // CCD detection rounds (≥ 1 per pass)
    long long broadPhases = 0;    // candidate gatherings (≥ 1 per pass)
    long long candidates = 0;     // candidate pairs they found, summed
    long long failSafeRuns = 0;   // passes that needed impact zones
    long long zoneVertices = 0;   // vertices moved rigidly by impact zones, summed
    long long frozenVertices = 0; // vertices held at x₀ by the last resort
    long long unresolved = 0;     // hits left after every stage (a guarantee breach; reported)
    // Hair vertices let through cloth (setUntangleHair), the most at one pass's start.
    long long tangledHairVertices = 0;
    long long halvings = 0;       // substeps the World halved because a pass stretched cloth
    long long retries = 0;        // intervals solved again with the pass's pairs held (World)
    // Pairs skipped because they start touching or crossing (the most in one pass).
    long long startTouching = 0;
    double broadSeconds = 0.0, proximitySeconds = 0.0, ccdSeconds = 0.0, failSafeSeconds = 0.0;
    void add(const SelfCollisionStats& o);
};

struct SelfCollisionSettings {
    // CCD runs at this fraction of the thickness: proximity keeps pairs near ξ at the end of a
    // step, CCD keeps the path between from closing to below ccdFraction·ξ.
    double ccdFraction = 0.5;
    int proximityIterations = 3; // Gauss–Seidel sweeps over the proximity pairs
    int ccdRounds = 6;           // CCD detect-and-correct rounds before the impact zones
    int zoneRounds = 64;         // impact-zone rounds before the last resort (hold at x₀)
    // The broad phase skips pairs inside certified flat patches of cloth (flat_patches.h): the
    // same pairs are corrected either way, found with less work.
    bool flatPatches = true;
    // Vertex–triangle pairs with a held side (a pinned or rigidly attached vertex) closer than
    // this × ξ at the end of a pass, not only those within ξ, hold their free side in the next
    // step's solve (contactPlanes): cloth pressed against its own pinned collar is stopped at ξ
    // there, instead of crossing into it and being pushed back by the next pass, which can move
    // only the free side and stretches the cloth round it. ≤ 1: the pairs within ξ only.
    double planeReach = 1.5;
};

// A hair's segments through a cloth's triangles at their current positions (the start shape's
// checks: the World's first-frame event and `gale check`'s warning): how many segments cross,
// and the first one's ends and midpoint. segments == 0: none.
struct HairThroughCloth {
    int segments = 0;
    int a = -1, b = -1;
    Vec3 at = Vec3::Zero();
};
HairThroughCloth hairThroughCloth(const Body& hair, const Body& cloth);

class SelfCollision {
public:
    explicit SelfCollision(SelfCollisionSettings settings = {}) : mSettings(settings) {}

    // A colliding body: its triangles (vertex indices of the body), rest positions (3 per
    // vertex: pairs closer than the thickness at rest are never repelled), thickness ξ (m).
    // A body without triangles (hair: its edges, the strands' segments) collides with the
    // others' triangles (vertex–triangle) and edges (edge–edge), never with another strand.
    void addBody(Body& body, const std::vector<std::array<int, 3>>& triangles,
                 const VecX& restPositions, double thickness);
    size_t bodyCount() const { return mBodies.size(); }
    size_t vertexCount() const { return mX0.size() / 3; }

    // Resolves the substep that took each body from `start[b]` to its current positions:
    // positions and velocities of the bodies are corrected in place. Returns this pass's counts.
    // Precondition for the guarantee: the start positions have no crossings (pairs that start
    // touching or crossing are left as they are and counted in startTouching).
    SelfCollisionStats resolve(const std::vector<VecX>& start);
    // Per body, the planes that hold its vertices against the cloth they rest on in the next
    // step's solve (Body::setClothPlanes): from the last pass's vertex–triangle proximity pairs,
    // at the positions and velocities it left. A vertex gets the plane of the triangle it is
    // closest to along the pair's normal, and each corner carrying more than 0.3 of the closest
    // point the mirrored plane through the vertex; pinned vertices none, nor pairs of a hair's
    // vertex.
    std::vector<std::vector<ClothContactPlane>> contactPlanes() const;
    // The planes of all the pass's proximity pairs and CCD hits (edge pairs too) at the pass's
    // start positions and velocities (per body): for the interval's solve done again when this pass
    // had to move cloth too far (World::advanceColliding), so that the solve holds the pairs the
    // pass found.
    std::vector<std::vector<ClothContactPlane>>
    retryPlanes(const std::vector<VecX>& startVelocities) const;

    // Intersecting triangle pairs at the bodies' current positions (contact/intersect.h): per
    // body, the pairs with at least one triangle of it.
    std::vector<int> intersectionsPerBody() const;
    // All pairs as (body, triangle) × 2.
    std::vector<std::pair<std::array<int, 2>, std::array<int, 2>>> intersections() const;
    // The smallest distance (m) between vertex–triangle and edge–edge pairs not within ξ of
    // each other at rest, searched up to `radius`; +inf when none is that close.
    double minimumSeparation(double radius) const;

    // Hair through cloth, let through (untangling): at each pass's start, the hair vertices at
    // either end of a segment that crosses a cloth triangle take no part in pairs with the
    // cloth for that pass, so the strand slides out through the cloth instead of being held
    // where it crosses (Baraff, Witkin & Kass 2003 let intersecting regions pass the same way).
    // The crossing moves along the strand and leaves it. Without crossings the pass is what it
    // is without this (the search costs a tree over the cloth's triangles a pass).
    // tangledBodies(): per body, whether a segment of it crossed at the last pass's start.
    // markTangled(): body k starts through a cloth (the World's start check), so that its solve
    // before the first pass already keeps off the cloth; each pass then finds its own.
    void setUntangleHair(bool on);
    bool untanglingHair() const { return mUntangleHair; }
    const std::vector<uint8_t>& tangledBodies() const { return mTangledBodies; }
    void markTangled(size_t body) {
        if (mUntangleHair && body < mTangledBodies.size()) mTangledBodies[body] = 1;
    }

    // A pair of primitives as four global vertices and signed weights α: the pair's relative
    // position is Σ α_k x_k (vertex − triangle point, or point on one edge − point on the other).
    struct Pair {
        std::array<int, 4> v;
        std::array<double, 4> a;
    };

private:
    // A pair to correct: proximity's (kept ξ apart) or a CCD hit's.
    struct Contact {
        Pair pair;
        Vec3 n;        // unit: the side the pair keeps (from the second part towards the first)
        double target; // the relative normal gap (m) or displacement the correction enforces
    };
    void gather();
    void scatter();
    // Boxes of the primitives over their vertices' boxes [lo, hi] (3 per vertex each),
    // inflated; the trees refitted (built over the rest shape the first time).
    void refitBoxes(const std::vector<double>& lo, const std::vector<double>& hi, double inflate);
    // Vertex i's region: the box of x₀ → x₁ grown by delta.
    void setRegion(size_t i, double delta);
    // A candidate pair's four global vertices (a Pair without its weights: a third of the
    // memory the broad phase writes and the narrow phase reads: 16 bytes, not 48).
    using Candidate = std::array<int, 4>;
    void gatherCandidates(std::vector<Candidate>& vt, std::vector<Candidate>& ee) const;
    // Vertex vi against triangle t, and edge e against edge f, as candidates when their boxes
    // overlap: false for primitives sharing a vertex, for four held vertices (nothing can move),
    // and for strand against strand (hair has no triangles: not modelled).
    // (And false for a hair vertex let through the cloth: mTangled.)
    bool candidateVertexTriangle(int vi, int t) const;
    bool candidateEdgeEdge(int e, int f) const;
    // The candidates again after the vertices marked in `moved` (and only they) moved beyond
    // the allowance: the pairs of unmoved vertices kept, those with a moved one queried anew.
    void regatherMoved(const std::vector<uint8_t>& moved);
    // After a full gathering's refit: the flat patches of the step (slack flatSlack()), as
    // labels that prune the trees' pair walks, and the positions they were certified at.
    void labelFlatPatches();
    double flatSlack() const;
    bool restClose(const Pair& p, bool vertexTriangle) const;
    bool adjacent(int a, int b) const;
    bool neighbours(const Pair& p, bool vertexTriangle) const;
    double relativeMotionBound(const Pair& p, bool vertexTriangle) const;
    // A lower bound (m) of the pair's distance at positions x: the gap between its boxes.
    double boxGap(const std::vector<double>& x, const Pair& p, bool vertexTriangle) const;
    int proximity();
    // One CCD detection over the step (and, with `apply`, the corrections); `zone`: per vertex
    // its rigid impact zone or −1 (pairs inside one zone are skipped).
    // `dirty`: per vertex whether it moved since the last round (null: test every candidate).
    int ccdRound(bool apply, std::vector<Pair>* hits, const std::vector<int>* zone = nullptr,
                 const std::vector<uint8_t>* dirty = nullptr);
    // The candidate pairs (swept boxes inflated by ξ), kept from pass to pass and gathered
    // again (in full, or for the vertices that moved) only when some vertex's path leaves its
    // region.
    bool ensureCandidates(); // true when it gathered them again
    std::vector<uint8_t> dirtySince(const std::vector<double>& before) const;
    bool rigidZone(const std::vector<int>& members) const;
    void impactZones(std::vector<Pair>& hits);
    void applyZone(const std::vector<int>& members);
    double pairThickness(const Pair& p) const;

    SelfCollisionSettings mSettings;
    struct Member {
        Body* body;
        int offset; // first global vertex
    };
    std::vector<Member> mBodies;
    std::vector<int> mVertexBody;
    std::vector<std::array<int, 3>> mTris; // global vertices
    std::vector<int> mTriBody;
    std::vector<uint8_t> mBodyHasTriangles; // per body
    std::vector<std::array<int, 2>> mEdges;
    std::vector<int> mAdjacencyStart, mAdjacency; // vertex neighbours by edges (CSR)
    std::vector<double> mRest, mX0, mX1, mV, mInvMass, mMass, mThick, mD0, mV0;
    contact::Bvh mVertTree, mTriTree, mEdgeTree;
    // The intersection count's tree over the triangles at their current positions, refitted at
    // each count (intersections(): a cache, hence mutable).
    mutable contact::Bvh mCountTree;
    std::vector<Candidate> mCandVt, mCandEe;
    // Per vertex, the region (box, 3 lo and 3 hi per vertex) the candidates cover it in.
    std::vector<double> mRegionLo, mRegionHi;
    bool mCandidatesValid = false;
    // Per candidate (vertex–triangle, edge–edge): CCD cannot rule it out from the proximity
    // pass's distances (the first CCD round tests these and pairs with moved vertices).
    std::vector<uint8_t> mMaybe[2];
    bool mMaybeValid = false;
    std::vector<Pair> mLastHits; // of the last CCD round
    std::vector<Contact> mContacts; // proximity's pairs, or a CCD round's hits (reused buffer)
    std::vector<int> bodyOffsets() const; // each body's first vertex
    // This pass's proximity pairs and CCD hits, vertex–triangle and edge–edge (retryPlanes).
    std::vector<Contact> mPassVt, mPassEe;
    // The last proximity's vertex–triangle pairs with a held side, beyond ξ but within
    // planeReach × ξ at x₁ (contactPlanes).
    std::vector<Contact> mNearVt;
    size_t mResting = 0; // mPassVt's first ones: the last proximity's pairs (contactPlanes)
    std::vector<contact::Box> mVertBoxes, mTriBoxes, mEdgeBoxes;
    // Flat patches of the last full gathering: the pairs inside them are left out of the
    // candidates while every vertex of a patch stays within δ of both ends of the path they were
    // certified for (mCertX0 → mCertX1); mInPatch marks the vertices still relied on.
    FlatPatches mFlat;
    std::vector<double> mCertX0, mCertX1;
    std::vector<uint8_t> mInPatch;
    // Untangling (setUntangleHair): on; per global vertex, let through the cloth this pass;
    // per body, a segment crossed; the hair segments (global vertices).
    bool mUntangleHair = false;
    std::vector<uint8_t> mTangled, mTangledBodies;
    std::vector<std::array<int, 2>> mHairSegments;
    void updateTangled(); // at a pass's start (mX0)
    bool mBuilt = false; // the trees (built once, over the rest shape)
    double mMaxThickness = 0.0;
    SelfCollisionStats mStats; // of the pass under way
};

} // namespace gale::solver
