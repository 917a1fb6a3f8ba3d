// Triangle–triangle intersection by segment-against-triangle orientation tests, and the
// intersecting pairs of a mesh with a box tree as the broad phase.
#include "solver/contact/intersect.h"

#include "solver/contact/bvh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace gale::solver::contact {

namespace {
template <class T>
T det3(T ax, T ay, T az, T bx, T by, T bz, T cx, T cy, T cz, T& permanent) {
    const T m1 = by * cz - bz * cy, m2 = bz * cx - bx * cz, m3 = bx * cy - by * cx;
    permanent = std::fabs(ax) * (std::fabs(by * cz) + std::fabs(bz * cy)) +
                std::fabs(ay) * (std::fabs(bz * cx) + std::fabs(bx * cz)) +
                std::fabs(az) * (std::fabs(bx * cy) + std::fabs(by * cx));
    return ax * m1 + ay * m2 + az * m3;
}
} // namespace

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    // det [a − d; b − d; c − d]: positive when d is below the plane of (a, b, c) seen with
    // a, b, c counter-clockwise (Shewchuk's convention).
    double perm = 0.0;
    const double det =
        det3(a.x() - d.x(), a.y() - d.y(), a.z() - d.z(), b.x() - d.x(), b.y() - d.y(),
             b.z() - d.z(), c.x() - d.x(), c.y() - d.y(), c.z() - d.z(), perm);
    const double bound = 7.7715611723761e-16 * perm;
    if (det > bound) return 1;
    if (det < -bound) return -1;
    if (perm == 0.0) return 0;
    using L = long double;
    L lperm = 0.0L;
    const L ldet = det3<L>(L(a.x()) - L(d.x()), L(a.y()) - L(d.y()), L(a.z()) - L(d.z()),
                           L(b.x()) - L(d.x()), L(b.y()) - L(d.y()), L(b.z()) - L(d.z()),
                           L(c.x()) - L(d.x()), L(c.y()) - L(d.y()), L(c.z()) - L(d.z()), lperm);
    // The differences are exact in long double only when the inputs are close; bound the error
    // of the whole evaluation by 8 ulps of long double per term of the permanent.
    const L lbound = 8.0L * LDBL_EPSILON * lperm;
    if (ldet > lbound) return 1;
    if (ldet < -lbound) return -1;
    return 0;
}

namespace {
// Whether the line through p and q passes through the closed triangle abc: the triangle's edges
// wind the same way round it (a segment whose ends lie on different sides of the plane then
// crosses the triangle).
bool lineThroughTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                         const Vec3& c) {
    const int o1 = orient3d(p, q, a, b), o2 = orient3d(p, q, b, c), o3 = orient3d(p, q, c, a);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}
} // namespace

bool segmentCrossesTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                            const Vec3& c) {
    const int sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
    if (sp == sq) return false; // same side, or both in the plane (coplanar: not counted)
    return lineThroughTriangle(p, q, a, b, c);
}

bool trianglesIntersect(const Vec3 t[3], const Vec3 u[3]) {
    // Each corner's side of the other's plane, once (segmentCrossesTriangle would take each
    // twice). A triangle strictly on one side of the other's plane touches neither it nor, then,
    // the other triangle (Möller's rejection); coplanar ones count as not intersecting.
    int st[3], su[3];
    for (int k = 0; k < 3; ++k) st[k] = orient3d(u[0], u[1], u[2], t[k]);
    if (st[0] == st[1] && st[1] == st[2]) return false;
    for (int k = 0; k < 3; ++k) su[k] = orient3d(t[0], t[1], t[2], u[k]);
    if (su[0] == su[1] && su[1] == su[2]) return false;
    // Then, as segmentCrossesTriangle, each edge whose ends are on different sides.
    for (int e = 0; e < 3; ++e) {
        const int f = (e + 1) % 3;
        if (st[e] != st[f] && lineThroughTriangle(t[e], t[f], u[0], u[1], u[2])) return true;
        if (su[e] != su[f] && lineThroughTriangle(u[e], u[f], t[0], t[1], t[2])) return true;
    }
    return false;
}

bool trianglesSharingVertexIntersect(const Vec3 t[3], int sharedT, const Vec3 u[3], int sharedU) {
    // Both triangles contain the shared corner; any further common point makes the intersection
    // a segment from it, which ends on the edge opposite the shared corner of one of them.
    const Vec3& t1 = t[(sharedT + 1) % 3];
    const Vec3& t2 = t[(sharedT + 2) % 3];
    const Vec3& u1 = u[(sharedU + 1) % 3];
    const Vec3& u2 = u[(sharedU + 2) % 3];
    return segmentCrossesTriangle(t1, t2, u[0], u[1], u[2]) ||
           segmentCrossesTriangle(u1, u2, t[0], t[1], t[2]);
}

std::vector<std::pair<int, int>> intersectingPairs(const std::vector<double>& x,
                                                   const std::vector<std::array<int, 3>>& triangles,
                                                   size_t limit) {
    Bvh tree;
    return intersectingPairs(x, triangles, tree, limit);
}

std::vector<std::pair<int, int>> intersectingPairs(const std::vector<double>& x,
                                                   const std::vector<std::array<int, 3>>& triangles,
                                                   Bvh& tree, size_t limit) {
    std::vector<std::pair<int, int>> pairs;
    if (triangles.size() < 2) return pairs;
    const auto at = [&](int v) { return Vec3(x[3 * v], x[3 * v + 1], x[3 * v + 2]); };
    std::vector<Box> boxes(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i)
        for (int k = 0; k < 3; ++k) boxes[i].add(at(triangles[i][k]));
    if (tree.primitiveCount() == triangles.size())
        tree.refit(boxes);
    else
        tree.build(boxes);
    // The pairs whose boxes overlap, by one walk of the tree against itself (cheaper than a
    // query per triangle), split into parts that run in parallel and are joined in the walk's
    // order: the same list for any number of threads. Each part stops at `limit`, enough for
    // the first `limit` of the whole.
    constexpr size_t kTasks = 64; // a few per thread, for balance
    const std::vector<Bvh::PairTask> tasks = tree.pairTasks(tree, kTasks);
    std::vector<std::vector<std::pair<int, int>>> parts(tasks.size());
    tbb::parallel_for(size_t(0), tasks.size(), [&](size_t k) {
        std::vector<std::pair<int, int>>& out = parts[k];
        tree.overlappingPairs(tree, tasks[k], [&](int a, int b) {
            if (limit > 0 && out.size() >= limit) return;
            const int i = std::min(a, b), j = std::max(a, b);
            const auto& ti = triangles[i];
            const auto& tj = triangles[j];
            int shared = 0, sT = -1, sU = -1;
            for (int p = 0; p < 3; ++p)
                for (int q = 0; q < 3; ++q)
                    if (ti[p] == tj[q]) {
                        ++shared;
                        sT = p;
                        sU = q;
                    }
            if (shared >= 2) return;
            const Vec3 t[3] = {at(ti[0]), at(ti[1]), at(ti[2])};
            const Vec3 u[3] = {at(tj[0]), at(tj[1]), at(tj[2])};
            const bool hit = shared == 1 ? trianglesSharingVertexIntersect(t, sT, u, sU)
                                         : trianglesIntersect(t, u);
            if (hit) out.emplace_back(i, j);
        });
    });
    for (const auto& part : parts) pairs.insert(pairs.end(), part.begin(), part.end());
    if (limit > 0 && pairs.size() > limit) pairs.resize(limit);
    return pairs;
}

std::vector<std::pair<int, int>> crossingSegments(const std::vector<double>& x,
                                                  const std::vector<std::array<int, 2>>& segments,
                                                  const std::vector<double>& y,
                                                  const std::vector<std::array<int, 3>>& triangles,
                                                  size_t limit) {
    std::vector<std::pair<int, int>> pairs;
    if (segments.empty() || triangles.empty()) return pairs;
    const auto at = [](const std::vector<double>& p, int v) {
        return Vec3(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    };
    std::vector<Box> boxes(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i)
        for (int k = 0; k < 3; ++k) boxes[i].add(at(y, triangles[i][k]));
    Bvh tree;
    tree.build(boxes);
    for (size_t s = 0; s < segments.size(); ++s) {
        const Vec3 p = at(x, segments[s][0]), q = at(x, segments[s][1]);
        Box box;
        box.add(p);
        box.add(q);
        tree.query(box, [&](int t) {
            if (limit > 0 && pairs.size() >= limit) return;
            const auto& tri = triangles[static_cast<size_t>(t)];
            if (segmentCrossesTriangle(p, q, at(y, tri[0]), at(y, tri[1]), at(y, tri[2])))
                pairs.emplace_back(static_cast<int>(s), t);
        });
        if (limit > 0 && pairs.size() >= limit) break;
    }
    return pairs;
}

} // namespace gale::solver::contact
