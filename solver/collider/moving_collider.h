// Moving and deforming mesh colliders (a MeshSequence): per substep the triangles' corners at
// both ends of the step, their swept boxes refitted into one AABB tree (built once), closest-point
// queries at the ends (the in-solve constraints and the thickness push-out, with the surface
// velocity of the motion), the body vertex nearest a cloth triangle (the in-solve side of the
// body vertex–cloth triangle pair, Body::contactConstraints), and the continuous pass that keeps
// cloth from crossing the surface during the step: cloth vertex–body triangle, edge–edge and
// body vertex–cloth triangle CCD (solver/contact/ccd.h) with a thickness.
#pragma once

#include "solver/contact/bvh.h"
#include "solver/contact/ccd.h"
#include "solver/linalg/types.h"
#include "solver/mesh/mesh_sequence.h"

#include <array>
#include <cmath>
#include <memory>
#include <vector>

namespace gale::solver {

struct ContactPoint; // collider.h

// Timings and counts of the contact work (accumulated; bench and run statistics). The body
// vertex–cloth triangle pair's share is counted apart as well (`faceSeconds`, its broad and
// narrow phase, and `faceCandidates` are also in the totals).
// The first prepare() builds the trees (`buildSeconds`, once); every later one refits them
// (`refitSeconds` over `refits`), or keeps them where the body moved as one (`kept`: its
// vertices within a slack of the trees' boxes carried by the body's translation). `sweepSeconds`:
// the continuous passes, always; the split into broad and narrow phase and the face pair's share
// only with setDetailedTiming (a clock read per primitive).
struct MovingContactStats {
    double buildSeconds = 0.0, refitSeconds = 0.0, sweepSeconds = 0.0, broadSeconds = 0.0,
           narrowSeconds = 0.0, faceSeconds = 0.0;
    long long refits = 0, kept = 0, candidates = 0, faceCandidates = 0, vertexHits = 0,
              edgeHits = 0, faceHits = 0, unresolved = 0;
};

// The first body edge a moving cloth edge meets in the continuous pass: its index, the
// fraction of the step, the two edges' closest points' parameters then (sa on the cloth edge,
// sb on the body's), the unit normal from the body towards the cloth there, the body point at
// the step's end and its move over the step (m).
struct EdgeHit {
    int edge = -1;
    double toi = 2.0, sa = 0.0, sb = 0.0;
    Vec3 normal = Vec3::UnitY(), body1 = Vec3::Zero(), displacement = Vec3::Zero();
};

// The first body vertex a moving cloth triangle meets in the continuous pass: its index, the
// fraction of the step, the vertex at the step's two ends, the weights of the triangle's point it
// met, and the unit normal from the cloth towards it (the face's at the step's end, on the side
// the vertex came from, when the point is inside the face).
struct FaceHit {
    int vertex = -1;
    double toi = 2.0;
    double w[3] = {0.0, 0.0, 0.0};
    Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero(), normal = Vec3::UnitY();
};

class MovingMeshContact {
public:
    explicit MovingMeshContact(std::shared_ptr<const MeshSequence> mesh);

    const MeshSequence& mesh() const { return *mMesh; }
    // Another motion of the same triangles (the vertex count and triangles must match): the
    // next prepare() reads its positions anew and refits the trees (or keeps them, as ever).
    void setMesh(std::shared_ptr<const MeshSequence> mesh);
    // The step [t0, t1]: corners at both ends, the swept boxes of the triangles, edges and
    // vertices, the trees refitted (built on the first call). Cached: the same interval twice
    // is free.
    void prepare(double t0, double t1);
    double t0() const { return mT0; }
    double t1() const { return mT1; }

    // The closest surface point to x at the start (atEnd false) or end of the prepared step,
    // searched within `radius`: unsigned distance (m; +inf beyond radius), the unit normal from
    // the surface towards x (the face normal when x is on it), and the surface velocity there
    // (the mean over the step, m/s). Returns false when nothing is within radius.
    // `hint`: a triangle likely closest (an earlier answer's out.triangle), whose distance bounds
    // the search from the start; the answer is the same with or without it.
    bool closest(const Vec3& x, bool atEnd, double radius, ContactPoint& out, int hint = -1) const;

    // The body vertex nearest to triangle (a, b, c) at the start of the prepared step, searched
    // within `radius` (m): its position p, the weights w of the triangle's point closest to it,
    // their distance (m) and the vertex's velocity over the step (m/s). False when none is
    // within radius. (The in-solve side of the body vertex–cloth triangle pair.)
    bool nearestVertex(const Vec3& a, const Vec3& b, const Vec3& c, double radius, Vec3& p,
                       double w[3], double& distance, Vec3& velocity) const;

    // The continuous pass over the prepared step for one body: vertex i moves from x0 to x1
    // (where `movable[i]`), edges and triangles as given (`triangles` empty for hair). Where a
    // vertex or an edge would come within `thickness` of the moving surface, it is placed at
    // `thickness` off the surface point it met, as that point is at the step's end (an open
    // surface's vertex hit: off the face's plane through it, its slide from it cut by μ × the
    // normal correction), its approach speed removed (relative to the surface), and Coulomb
    // friction μ applied to the tangential speed; where a body vertex would come within `thickness`
    // of a cloth triangle, the triangle's movable corners are moved so that it ends `thickness` off
    // the body vertex, on the side it started, with the same velocity response at the point it met.
    // Repeated (at most `passes` times) until no motion meets the surface. Returns the vertices
    // moved. `normals` (when given, one per vertex): for each vertex moved, the unit direction
    // its last hit pushed it (from the surface towards it); left as it was for the others.
    int sweep(const VecX& x0, VecX& x1, VecX& v1, const std::vector<uint8_t>& movable,
              const std::vector<std::array<int, 2>>& edges,
              const std::vector<std::array<int, 3>>& triangles, double thickness, double friction,
              double h, int passes = 4, std::vector<Vec3>* normals = nullptr);

    // The edge test of the continuous pass alone, for the solve's contacts (Body): the cloth edge
    // a0b0 → a1b1 against the body's edges, kept `thickness` off (from the surface r out of a
    // thin collider's axis, setRadius). False when it meets none. `cand`: the caller's scratch.
    bool edgeContact(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                     double thickness, std::vector<int>& cand, EdgeHit& hit) const;

    // The body vertex–cloth triangle test of the continuous pass alone (as edgeContact): the
    // triangle with corners c0 → c1 against the body's vertices.
    bool faceContact(const Vec3 c0[3], const Vec3 c1[3], double thickness, std::vector<int>& cand,
                     FaceHit& hit) const;

    // Vertices whose straight move from[i] → to[i] (made after the step, at its end: the
    // self-collision pass) crosses the surface as it is at the end of the prepared step (a face
    // between the two points). Vertices that did not move are not tested. `which` (when given):
    // their indices appended.
    int movesThroughSurface(const VecX& from, const VecX& to,
                            std::vector<int>* which = nullptr) const;

    // The vertex test of the continuous pass for a path p0 → p1 over the prepared step, as a
    // contact plane for the solve: when the path comes within ξ/2 of the surface (a crossing
    // too), the face it met first, at the step's end — `out.normal` its normal on the side the
    // vertex came from, `out.distance` the signed distance of p1 above that plane (negative:
    // beyond it), the surface velocity there. False when the path meets nothing.
    bool sweptContact(const Vec3& p0, const Vec3& p1, double thickness, ContactPoint& out) const;

    // Whether the surface is closed (every edge shared by exactly two triangles): it has an
    // inside, and insideDepth() can tell it.
    bool closed() const { return mClosed; }
    // For a closed surface, at the end of the prepared step: how deep x is inside it (m, its
    // distance to the surface), or a value ≤ 0 when it is outside (or the surface is not
    // closed). Inside is an odd number of crossings of a ray from x to beyond the surface's box.
    double insideDepth(const Vec3& x) const;

    // An open surface (a cloth as the hair's collider, World::clothAsColliders) rather than a
    // body: the solve also tests vertex paths for crossing it (Body::updateContacts, an unsigned
    // distance cannot tell), and a vertex hit in sweep() keeps its slide along the face, cut by
    // Coulomb's bound (a body's hit holds the vertex at the point it met).
    void setOpenSurface(bool open) { mOpen = open; }
    bool openSurface() const { return mOpen; }
    // Whether sweep() tests the body's vertices' paths against the surface (on: a mesh). Off for
    // a sphere's centre or a capsule's axis as a degenerate mesh (Body::thinContact), whose
    // vertex contact the analytic collider already gives: sweep() then adds only the pairs it
    // misses, cloth edges against the axis and cloth triangles against its ends.
    void setVertexPairs(bool on) { mVertexPairs = on; }
    // The radius (m) of such a centre or axis: sweep() keeps primitives its thickness off the
    // surface r out from it.
    void setRadius(double r) { mRadius = r; }

    const MovingContactStats& stats() const { return mStats; }
    // Clock the broad and narrow phase of every primitive (MovingContactStats; benchmarks).
    void setDetailedTiming(bool on) { mDetailedTiming = on; }

private:
    Vec3 corner(bool atEnd, int v) const;
    // The continuous pass's CCD options for a primitive held ξ off the surface (r out of a thin
    // collider's axis, setRadius).
    contact::CcdOptions passOptions(double xi) const;
    // The face test for CCD options `opt`, candidates from the tree within `reach` (into cand).
    bool firstFaceHit(const Vec3 c0[3], const Vec3 c1[3], const contact::CcdOptions& opt,
                      double reach, std::vector<int>& cand, FaceHit& hit) const;
    // The edge test for CCD options `opt`, candidates from the tree within `reach` (into cand).
    bool firstEdgeHit(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                      const contact::CcdOptions& opt, double reach, std::vector<int>& cand,
                      EdgeHit& hit) const;
    // A point's box over the step in the step's moving frame: p0 at the start, p1 at the end
    // (world positions).
    void addSwept(contact::Box& b, const Vec3& p0, const Vec3& p1) const {
        b.add(p0);
        b.add(p1 - mShift);
    }
    // A point at the step's end (world) in the step's moving frame.
    Vec3 endQuery(const Vec3& x) const { return x - mShift; }
    // A query box of the step's moving frame in the trees' (mTreeOffset, mTreeSlack).
    contact::Box inTrees(contact::Box q) const {
        q.lo -= mTreeOffset;
        q.hi -= mTreeOffset;
        q.inflate(mTreeSlack);
        return q;
    }
    // A lower bound on the squared distance from a point (or box) of the step's moving frame to
    // whatever a tree box `b` holds.
    double treeDistance2(const contact::Box& b, const Vec3& p) const {
        return lessSlack(b.distance2(Vec3(p - mTreeOffset)));
    }
    double treeDistance2(const contact::Box& b, contact::Box q) const {
        q.lo -= mTreeOffset;
        q.hi -= mTreeOffset;
        return lessSlack(b.distance2(q));
    }
    double lessSlack(double d2) const {
        if (mTreeSlack == 0.0) return d2;
        const double d = std::sqrt(d2) - mTreeSlack;
        return d > 0.0 ? d * d : 0.0;
    }
    // Whether the trees' boxes, carried by the body's translation since their last refit, still
    // hold every primitive of this step within the slack limit (then mTreeOffset, mTreeSlack).
    bool treesStillHold();
    // The faces the segment a → b crosses at the end of the prepared step (`first`: stop at
    // the first, so 0 or 1).
    int endCrossings(const Vec3& a, const Vec3& b, bool first) const;
    Vec3 faceNormal(bool atEnd, int tri) const;
    // The surface velocity (m/s) of triangle tri's point with weights w over a step of h s.
    Vec3 pointVelocity(int tri, const double w[3], double h) const;
    // The continuous pass's vertex test, broad phase: the triangles whose swept boxes come
    // within `reach` of the path p0 → p1's, in triangle order (a fixed tie-break).
    void vertexCandidates(const Vec3& p0, const Vec3& p1, double reach,
                          std::vector<int>& cand) const;
    // And its narrow phase: the first of `cand` the path meets within opt.thickness over the
    // prepared step (ties: the lower index), with the point's weights w at that time, the
    // face's normal at the step's end on the side the vertex came from (the direction to the
    // feature off a face's interior), and that point at the step's end; triangle −1: none.
    struct VertexHit {
        int triangle = -1;
        double w[3] = {0.0, 0.0, 0.0};
        Vec3 normal = Vec3::UnitY(), point = Vec3::Zero();
    };
    VertexHit firstVertexHit(const Vec3& p0, const Vec3& p1, const std::vector<int>& cand,
                             const contact::CcdOptions& opt) const;

    std::shared_ptr<const MeshSequence> mMesh;
    bool mOpen = false;                     // setOpenSurface
    bool mVertexPairs = true;               // setVertexPairs
    double mRadius = 0.0;                   // setRadius (m)
    std::vector<std::array<int, 2>> mEdges; // unique body edges
    bool mClosed = false;                   // every edge in exactly two triangles
    contact::Box mEndBox;                   // the corners at t1 (prepare; insideDepth)
    std::vector<int> mVertices;             // body vertices in some triangle
    std::vector<double> mP0, mP1;           // corners at t0 and t1
    // The body's mean displacement over the step (m). The trees hold every primitive swept in
    // the frame that moves with it (corners at t0, and at t1 less mShift) and queries are made
    // in that frame too (swept(), endQuery()): a common motion linear in time changes no
    // distance between two linearly moving points, so the boxes stay conservative, and a cloth
    // riding on a body that travels d per step sweeps a box of its relative motion, not of d.
    Vec3 mShift = Vec3::Zero();
    // The trees as last refitted: their step's corners in its moving frame (at t0, and at t1
    // less that step's mShift), per vertex. A body that since moved as one (a rigid prop, a
    // ball in flight: every vertex by the same displacement) has every primitive of this step
    // within mTreeSlack (m) of its box there, carried by mTreeOffset (the mean displacement of
    // the t0 corners since): the refit is skipped and every query made in the trees' frame
    // (inTrees, treeDistance2), which gives the same candidates and results a refit would have
    // (every box still conservative; the narrow phase reads the true corners). Refitted when the
    // slack would pass mSlackLimit (a tenth of the body's mean edge length).
    std::vector<double> mRef0, mRef1;
    Vec3 mTreeOffset = Vec3::Zero();
    double mTreeSlack = 0.0, mSlackLimit = 0.0;
    std::vector<contact::Box> mCornerBoxes; // per mesh vertex, swept over the step (refit scratch)
    contact::Bvh mBvh, mEdgeBvh, mVertexBvh;
    bool mBuilt = false;
    bool mDetailedTiming = false;
    double mT0 = NAN, mT1 = NAN;
    MovingContactStats mStats;
};

} // namespace gale::solver
