// Exact-sign triangle–triangle intersection tests and the count of intersecting triangle pairs of
// a mesh (the check that self-collision keeps cloth intersection-free): orientation predicates
// of segments against triangles, with an AABB tree (bvh.h) as the broad phase.
#pragma once

#include "solver/contact/bvh.h"
#include "solver/contact/ccd.h"

#include <array>
#include <utility>
#include <vector>

namespace gale::solver::contact {

// Sign of the volume of (a, b, c, d): +1, −1 or 0. The determinant of the differences in double,
// trusted when it exceeds Shewchuk's forward error bound for orient3d (7.78e-16 × the permanent,
// "Adaptive Precision Floating-Point Arithmetic", 1997); otherwise recomputed in long double
// with the bound scaled to its epsilon, and 0 (touching) when still below it.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Whether the closed segment pq crosses the triangle abc (a proper crossing or a touch); a
// segment in the triangle's plane counts as no crossing (the coplanar case: see below).
bool segmentCrossesTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                            const Vec3& c);

// Whether triangles t = (a0, a1, a2) and u = (b0, b1, b2), which share no vertex, intersect: an
// edge of one crosses the other (Möller's interval test reduces to this when the triangles are
// not coplanar). Coplanar overlapping triangles count as not intersecting: cloth meets itself
// there only as a measure-zero event, and a test of counts is about crossings.
bool trianglesIntersect(const Vec3 t[3], const Vec3 u[3]);

// Triangles that share exactly one vertex intersect when the edge opposite the shared corner in
// either crosses the other (the fold of a fan through itself). `shared` is the shared corner's
// index in t and in u.
bool trianglesSharingVertexIntersect(const Vec3 t[3], int sharedT, const Vec3 u[3], int sharedU);

// The intersecting pairs (i < j) among `triangles` over vertex positions `x` (3 per vertex):
// pairs sharing no vertex by trianglesIntersect, pairs sharing one by the fan test; pairs
// sharing an edge are never counted. In the tree walk's order (deterministic); `limit` > 0
// stops after that many pairs.
std::vector<std::pair<int, int>> intersectingPairs(const std::vector<double>& x,
                                                   const std::vector<std::array<int, 3>>& triangles,
                                                   size_t limit = 0);
// The same with the caller's tree kept from call to call: built over the first call's positions
// (or when the triangle count changed), refitted after (a mesh checked every frame pays a refit,
// not a build; the pairs are the same, their order the kept tree's walk's).
std::vector<std::pair<int, int>> intersectingPairs(const std::vector<double>& x,
                                                   const std::vector<std::array<int, 3>>& triangles,
                                                   Bvh& tree, size_t limit = 0);

// The segments (x's edges, e.g. a hair's) that cross a triangle of another mesh (positions y,
// `triangles`), as (segment, triangle) pairs by segmentCrossesTriangle, in segment order (each
// segment's triangles in the tree's order); `limit` > 0 stops after that many pairs.
std::vector<std::pair<int, int>> crossingSegments(const std::vector<double>& x,
                                                  const std::vector<std::array<int, 2>>& segments,
                                                  const std::vector<double>& y,
                                                  const std::vector<std::array<int, 3>>& triangles,
                                                  size_t limit = 0);

} // namespace gale::solver::contact
