// Certified flat patches of cloth, for the self-collision broad phase: nodes of the triangle tree
// whose triangles, wherever each vertex lies within a slack δ of its straight path over the step,
// project one-to-one onto a plane with every interior vertex at least ξ (in that projection) from
// the triangles it is not a corner of. No vertex–triangle or edge–edge pair inside a patch can
// then come within ξ, and the pair walk skips them (Volino & Magnenat-Thalmann 1994; continuous
// normal cones, Tang et al. 2009; star-shaped contours, Schvartzman, Pérez & Otaduy 2010).
#pragma once

#include "solver/contact/bvh.h"
#include "solver/linalg/types.h"

#include <array>
#include <cstdint>
#include <vector>

namespace gale::solver {

class FlatPatches {
public:
    // The mesh's connectivity, global vertex ids: a triangle may join a patch when `eligible`
    // and each of its edges is shared with at most one other triangle, traversed the other way
    // (manifold, consistently oriented); a vertex is interior when every edge round it has two
    // triangles.
    void setTopology(const std::vector<std::array<int, 3>>& tris, std::size_t vertexCount,
                     const std::vector<uint8_t>& eligible);

    // The patches of one step: the largest nodes of `triTree` (built over the triangles, by index)
    // that pass the test below for every position within `slack` (m) of each vertex's path
    // x(τ) = x0 + τ (x1 − x0), τ ∈ [0, 1] (3 doubles per vertex), at thickness ξ (m):
    //   1. a cone of half-angle θ < 90° about an axis d holds every triangle's normal (the
    //      triangle's continuous normal cone, widened by the slack);
    //   2. the patch's contour (edges with one triangle in it) is star-shaped about its centre in
    //      the projection along d, and winds once: with 1., the projection is one-to-one;
    //   3. cos θ × (the smallest altitude of its triangles) ≥ 1.01 ξ: an interior vertex is
    //      farther than ξ in projection from the contour of its triangles' fan.
    // Returns the number of patches.
    int find(const contact::Bvh& triTree, const std::vector<double>& x0,
             const std::vector<double>& x1, double slack, double thickness);

    // The same patches (the triangles of the last find()) for another step: each that passes the
    // test again keeps its labels for that step; the corners of each that does not are flagged in
    // `lost` (its pairs must be found another way) and it is dropped (not tried again until the
    // next find()). Returns how many did not pass.
    std::size_t recertify(const std::vector<double>& x0, const std::vector<double>& x1,
                          double slack, double thickness, std::vector<uint8_t>& lost);

    // Per triangle: its patch, or −1.
    const std::vector<int>& triangleLabels() const { return mTriLabel; }
    // Per vertex: the patch holding every triangle round it when it is interior, or −1. A pair
    // of two such vertices' primitives in one patch (a vertex and a triangle, or two edges, not
    // sharing a vertex) stays more than ξ apart over the step.
    const std::vector<int>& vertexLabels() const { return mVertLabel; }
    // Per vertex: a corner of some patch's triangle (its position is part of a certificate).
    const std::vector<uint8_t>& inPatch() const { return mInPatch; }
    // Marks in `marked` every corner of every triangle round a vertex flagged in `vertices`
    // (the vertices whose fans, and so whose certificates, a moved vertex is part of).
    void markFans(const std::vector<uint8_t>& vertices, std::vector<uint8_t>& marked) const;

private:
    struct Cone {
        Vec3 axis = Vec3::UnitZ();
        double angle = 0.0;  // half-angle (rad); ≥ π/2: none
        double height = 0.0; // the smallest altitude of its triangles (m), a lower bound
    };
    void merge(Cone& into, const Cone& c) const;
    // Tests 1 and 3 (the cone narrower than 90°, and cos θ × the smallest altitude ≥ 1.01 ξ), as
    // find() and recertify() both ask them before the contour's.
    static bool narrowEnough(const Cone& c, double thickness);
    // Triangle t's cone and altitude bound over the step (slack d).
    Cone triangleCone(std::size_t t, const std::vector<double>& x0, const std::vector<double>& x1,
                      double d) const;
    // Test 2 for the triangles `members` (stamped `id` in mStamp), about the mean of their
    // corners or else about the middle of the contour's kernel.
    bool starContour(const std::vector<int>& members, int id, const Vec3& d,
                     const std::vector<double>& x0, const std::vector<double>& x1,
                     double slack) const;
    // Test 2 for the contour `sides` about the centre moving c0 → c1.
    static bool starAbout(const std::vector<std::array<int, 2>>& sides, const Vec3& d,
                          const Vec3& c0, const Vec3& c1, const std::vector<double>& x0,
                          const std::vector<double>& x1, double slack);
    // The middle of the kernel of the contour `sides` at positions x in the projection along d;
    // false when the kernel is empty.
    static bool kernelMiddle(const std::vector<std::array<int, 2>>& sides, const Vec3& d,
                             const std::vector<double>& x, Vec3& centre);

    std::vector<std::array<int, 3>> mTris;
    std::vector<int> mAcross; // per triangle side k (t[k] → t[k+1]): the triangle across, or −1
    std::vector<uint8_t> mEligible;            // per triangle
    std::vector<uint8_t> mInterior;            // per vertex
    std::vector<int> mVertTriStart, mVertTris; // triangles round each vertex (CSR)
    std::vector<Cone> mTriCone, mNodeCone;
    std::vector<int> mStamp; // per triangle: the stamp of the contour being traced
    int mNextStamp = 0;
    std::vector<int> mPatchStart, mPatchTris;       // each patch's triangles (CSR)
    mutable std::vector<std::array<int, 2>> mSides; // the contour under test (scratch)
    std::vector<int> mTriLabel, mVertLabel;
    std::vector<uint8_t> mInPatch;
};

// The angle between a and b (rad, in [0, π]) bounded from above within 3.2e-5 (a polynomial
// arctangent; the cones widen by it and stay conservative).
double angleUpperBound(const Vec3& a, const Vec3& b);

} // namespace gale::solver
