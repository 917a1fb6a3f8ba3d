// Continuous collision detection with a thickness for linearly moving points, triangles and
// edges: exact closest points (point–triangle, segment–segment, with the degenerate cases), and
// additive conservative advancement (ACCD: Li, Kaufman & Jiang, "Codimensional Incremental
// Potential Contact", SIGGRAPH 2021, §4 and Alg. 1), which never reports a later time than the
// first at which the primitives come within the thickness.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gale::solver::contact {

using Vec3 = Eigen::Vector3d;

// The closest point of triangle (a, b, c) to p as barycentric weights w (q = w0 a + w1 b + w2 c),
// by Voronoi regions (Ericson, "Real-Time Collision Detection", 2005, §5.1.5); a degenerate
// triangle (a segment or a point) gives the closest point of what it is. Returns |p − q|².
double pointTriangleDistance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                              double w[3]);

// Closest points p0 + s (p1 − p0) and q0 + u (q1 − q0), s, u in [0, 1], of two segments
// (Ericson §5.1.9), including parallel and zero-length segments. Returns the squared distance.
double segmentSegmentDistance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                               double& s, double& u);

struct CcdOptions {
    double thickness = 0.0; // ξ (m): contact when the distance reaches ξ
    // Contact is reported when the gap d − ξ falls below `gapTolerance` (m); the reported time
    // is then before contact, at a gap in (0, gapTolerance).
    double gapTolerance = 1e-6;
    // Each advance covers this fraction of the distance the gap allows (< 1: the margin that
    // keeps every reached time clear of contact).
    double stepFraction = 0.9;
    int maxIterations = 500; // then report a contact at the time reached (conservative)
    // Primitives that start within the thickness: true — only keep them from crossing (ξ becomes
    // half their start distance, so a pair in resting contact that separates is no hit); false —
    // report contact at t = 0.
    bool shrinkWithinThickness = false;
};

// The motion of a primitive's corners over the step t ∈ [0, 1]: x(t) = x0 + t (x1 − x0).
// Vertex p against triangle (a, b, c). Returns true with `toi` in [0, 1] when they come within
// ξ during the step (toi: a time at which they are still at least ξ apart, or 0 when they
// start within ξ); false when they stay farther than ξ apart throughout.
bool vertexTriangleCcd(const Vec3& p0, const Vec3& p1, const Vec3& a0, const Vec3& a1,
                       const Vec3& b0, const Vec3& b1, const Vec3& c0, const Vec3& c1,
                       const CcdOptions& opt, double& toi);

// Edge (p, q) against edge (r, s), the same contract.
bool edgeEdgeCcd(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, const Vec3& r0,
                 const Vec3& r1, const Vec3& s0, const Vec3& s1, const CcdOptions& opt,
                 double& toi);

} // namespace gale::solver::contact
