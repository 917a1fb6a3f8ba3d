// Flat patches: per triangle a continuous normal cone widened by the slack and a lower bound of
// its altitudes, merged up the triangle tree; top-down, the first node on each path whose cone is
// narrow enough for its altitudes and whose contour is star-shaped becomes a patch.
#include "solver/world/flat_patches.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {
constexpr double kPi = 3.141592653589793;
constexpr double kHalfPi = 0.5 * kPi;
constexpr double kNone = 4.0;          // a half-angle meaning "no cone" (> π)
constexpr double kAngleMargin = 1e-12; // rad added at each merge (rounding of the axis)
constexpr double kClearance = 1.01;    // the altitude bound must exceed ξ by 1 %
// Triangles: a smaller node has next to no pairs inside to leave out (a leaf of 4 has at most
// a few), and its contour is the likeliest to fail the star test as it moves.
constexpr int kMinPatch = 16;

// The smallest value on [0, 1] of the quadratic with Bernstein coefficients b0, b1, b2: at an
// end, or at the vertex of the parabola when it opens upwards inside (exact, where the
// coefficients' minimum would be a loose bound when the step turns the patch).
double quadraticMinimum(double b0, double b1, double b2) {
    double lowest = std::min(b0, b2);
    const double a = b0 - 2.0 * b1 + b2, b = 2.0 * (b1 - b0); // f = b0 + bτ + aτ²
    if (a > 0.0) {
        const double t = -b / (2.0 * a);
        if (t > 0.0 && t < 1.0) lowest = std::min(lowest, b0 + t * (b + a * t));
    }
    return lowest;
}

// The arctangent's polynomial (Abramowitz & Stegun 4.4.49) is within 1.15e-5 rad of atan z on
// [0, 1] with these coefficients (measured on a 2·10⁵-point grid); the angles below add
// kAtanBound so that they bound the true angle from above, as the cones need
// (flat_patches_test.cpp checks the bound against atan2).
constexpr double kAtanBound = 2e-5;
double atanUnit(double z) {
    const double z2 = z * z;
    return z *
           (0.9998660 + z2 * (-0.3302995 + z2 * (0.1801410 + z2 * (-0.0851330 + z2 * 0.0208351))));
}
} // namespace

double angleUpperBound(const Vec3& a, const Vec3& b) {
    // atan2(|a × b|, a·b) ∈ [0, π] + kAtanBound, by octant, without libm's atan2 (about half
    // the cones' time on the cape benchmark was in it).
    const double y = a.cross(b).norm(), x = a.dot(b), ax = std::abs(x);
    if (!(std::max(y, ax) > 0.0)) return kAtanBound;
    const double base =
        y <= ax ? atanUnit(y / ax) : kHalfPi - atanUnit(ax / y); // the angle from ±a's line
    return (x >= 0.0 ? base : kPi - base) + kAtanBound;
}

void FlatPatches::setTopology(const std::vector<std::array<int, 3>>& tris, std::size_t vertexCount,
                              const std::vector<uint8_t>& eligible) {
    mTris = tris;
    const std::size_t nt = tris.size();
    mEligible.assign(nt, 0);
    for (std::size_t t = 0; t < nt; ++t) {
        const auto& v = tris[t];
        mEligible[t] = eligible[t] && v[0] != v[1] && v[1] != v[2] && v[2] != v[0];
    }
    // Each side as (lower vertex, higher vertex, triangle, side), sorted: the sides of one edge
    // are then adjacent.
    struct Side {
        int lo, hi, tri, k;
        bool forward; // the triangle runs lo → hi
    };
    std::vector<Side> sides;
    sides.reserve(3 * nt);
    for (std::size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const int p = tris[t][k], q = tris[t][(k + 1) % 3];
            sides.push_back({std::min(p, q), std::max(p, q), static_cast<int>(t), k, p < q});
        }
    std::sort(sides.begin(), sides.end(), [](const Side& a, const Side& b) {
        return a.lo < b.lo || (a.lo == b.lo && (a.hi < b.hi || (a.hi == b.hi && a.tri < b.tri)));
    });
    mAcross.assign(3 * nt, -1);
    mInterior.assign(vertexCount, 0);
    std::vector<uint8_t> open(vertexCount, 0); // a vertex on an edge without two triangles
    for (std::size_t i = 0; i < sides.size();) {
        std::size_t j = i + 1;
        while (j < sides.size() && sides[j].lo == sides[i].lo && sides[j].hi == sides[i].hi) ++j;
        if (j - i == 2 && sides[i].forward != sides[i + 1].forward) {
            mAcross[3 * sides[i].tri + sides[i].k] = sides[i + 1].tri;
            mAcross[3 * sides[i + 1].tri + sides[i + 1].k] = sides[i].tri;
        } else {
            open[sides[i].lo] = open[sides[i].hi] = 1;
            // Three or more triangles on an edge, or two running it the same way: neither a
            // manifold nor an orientation to project by.
            if (j - i >= 2)
                for (std::size_t s = i; s < j; ++s) mEligible[sides[s].tri] = 0;
        }
        i = j;
    }
    mVertTriStart.assign(vertexCount + 1, 0);
    for (const auto& v : tris)
        for (int k = 0; k < 3; ++k) ++mVertTriStart[v[k] + 1];
    for (std::size_t i = 0; i < vertexCount; ++i) mVertTriStart[i + 1] += mVertTriStart[i];
    mVertTris.assign(mVertTriStart.back(), 0);
    std::vector<int> fill(mVertTriStart.begin(), mVertTriStart.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) mVertTris[fill[tris[t][k]]++] = static_cast<int>(t);
    for (std::size_t i = 0; i < vertexCount; ++i)
        mInterior[i] = !open[i] && mVertTriStart[i + 1] > mVertTriStart[i];
}

bool FlatPatches::narrowEnough(const Cone& c, double thickness) {
    return c.angle < kHalfPi && std::cos(c.angle) * c.height >= kClearance * thickness;
}

void FlatPatches::merge(Cone& into, const Cone& c) const {
    into.height = std::min(into.height, c.height);
    if (into.angle >= kHalfPi || c.angle >= kHalfPi) {
        into.angle = kNone;
        return;
    }
    const double phi = angleUpperBound(into.axis, c.axis) + kAngleMargin;
    if (phi + c.angle <= into.angle) return;
    if (phi + into.angle <= c.angle) {
        into.axis = c.axis;
        into.angle = c.angle;
        return;
    }
    const double angle = 0.5 * (phi + into.angle + c.angle);
    if (angle >= kHalfPi) {
        into.angle = kNone;
        return;
    }
    // The axis turned from into.axis towards c.axis by angle − into.angle, in their plane.
    const Vec3 perp = (c.axis - into.axis.dot(c.axis) * into.axis).normalized();
    const double turn = angle - into.angle;
    into.axis = (std::cos(turn) * into.axis + std::sin(turn) * perp).normalized();
    // (φ bounded from above by up to kAtanBound turns the axis up to that much further: the
    // cone is widened by as much to still hold c.)
    into.angle = angle + kAngleMargin + kAtanBound;
}

FlatPatches::Cone FlatPatches::triangleCone(std::size_t t, const std::vector<double>& x0,
                                            const std::vector<double>& x1, double d) const {
    // Triangle (a, b, c), e₁ = b − a and e₂ = c − a moving linearly: the normal
    // n(τ) = e₁(τ) × e₂(τ) is a quadratic, inside the hull of its Bernstein points
    // P₀ = n(0), P₁ = (e₁(0) × e₂(1) + e₁(1) × e₂(0))/2, P₂ = n(1). Each vertex off its path by
    // ≤ δ moves e₁, e₂ by ≤ 2δ and n by ≤ R = 2δ(|e₁|max + |e₂|max) + 4δ². The cone: about the
    // mean of the P̂ᵢ, half-angle maxᵢ ∠(Pᵢ, axis) + asin(R/|Pᵢ|). The altitudes: |n| ≥
    // minᵢ Pᵢ·axis − R over an opposite side ≤ its longest length + 2δ.
    Cone c;
    c.angle = kNone;
    c.height = 0.0;
    if (!mEligible[t]) return c;
    const auto& v = mTris[t];
    const Vec3 a0 = vec3At(x0.data(), v[0]), b0 = vec3At(x0.data(), v[1]),
               c0 = vec3At(x0.data(), v[2]);
    const Vec3 a1 = vec3At(x1.data(), v[0]), b1 = vec3At(x1.data(), v[1]),
               c1 = vec3At(x1.data(), v[2]);
    const Vec3 e10 = b0 - a0, e20 = c0 - a0, e11 = b1 - a1, e21 = c1 - a1;
    const Vec3 p[3] = {e10.cross(e20), 0.5 * (e10.cross(e21) + e11.cross(e20)), e11.cross(e21)};
    const double l1 = std::max(e10.norm(), e11.norm()), l2 = std::max(e20.norm(), e21.norm());
    const double l3 = std::max((c0 - b0).norm(), (c1 - b1).norm());
    const double r = 2.0 * d * (l1 + l2) + 4.0 * d * d;
    double len[3];
    bool ok = true;
    Vec3 axis = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
        len[i] = p[i].norm();
        if (!(len[i] > r))
            ok = false;
        else
            axis += p[i] / len[i];
    }
    if (!ok || !(axis.norm() > 0.0)) return c;
    axis.normalize();
    double angle = 0.0, lowest = INFINITY;
    for (int i = 0; i < 3; ++i) {
        angle = std::max(angle, angleUpperBound(p[i], axis) + std::asin(r / len[i]));
        lowest = std::min(lowest, p[i].dot(axis));
    }
    if (!(angle < kHalfPi)) return c;
    c.axis = axis;
    c.angle = angle + kAngleMargin;
    c.height = std::max(0.0, lowest - r) / (std::max({l1, l2, l3}) + 2.0 * d);
    return c;
}

int FlatPatches::find(const contact::Bvh& triTree, const std::vector<double>& x0,
                      const std::vector<double>& x1, double slack, double thickness) {
    const std::size_t nt = mTris.size(), nv = mInterior.size();
    mTriLabel.assign(nt, -1);
    mVertLabel.assign(nv, -1);
    mInPatch.assign(nv, 0);
    if (nt == 0 || triTree.primitiveCount() != nt) return 0;
    const double d = slack;
    mTriCone.resize(nt);
    tbb::parallel_for(std::size_t(0), nt,
                      [&](std::size_t t) { mTriCone[t] = triangleCone(t, x0, x1, d); });
    // Up the tree (parents before children in node order: a reverse sweep).
    const std::size_t nn = triTree.nodeCount();
    mNodeCone.resize(nn);
    for (std::size_t k = nn; k-- > 0;) {
        const contact::Bvh::NodeView n = triTree.node(static_cast<int>(k));
        Cone& c = mNodeCone[k];
        if (n.left >= 0) {
            c = mNodeCone[static_cast<std::size_t>(n.left)];
            merge(c, mNodeCone[static_cast<std::size_t>(n.right)]);
            continue;
        }
        c = mTriCone[static_cast<std::size_t>(triTree.primitiveAt(n.begin))];
        for (int i = n.begin + 1; i < n.end; ++i)
            merge(c, mTriCone[static_cast<std::size_t>(triTree.primitiveAt(i))]);
    }
    // Down the tree: the first node on each path that passes becomes a patch.
    mStamp.assign(nt, -1);
    mNextStamp = 0;
    mPatchStart.assign(1, 0);
    mPatchTris.clear();
    int patches = 0;
    std::vector<int> stack{0}, members;
    while (!stack.empty()) {
        const int k = stack.back();
        stack.pop_back();
        const Cone& c = mNodeCone[static_cast<std::size_t>(k)];
        const contact::Bvh::NodeView n = triTree.node(k);
        if (n.end - n.begin >= kMinPatch && narrowEnough(c, thickness)) {
            members.clear();
            const int stamp = mNextStamp++;
            for (int i = n.begin; i < n.end; ++i) {
                members.push_back(triTree.primitiveAt(i));
                mStamp[static_cast<std::size_t>(members.back())] = stamp;
            }
            if (starContour(members, stamp, c.axis, x0, x1, d)) {
                for (int t : members) mTriLabel[static_cast<std::size_t>(t)] = patches;
                mPatchTris.insert(mPatchTris.end(), members.begin(), members.end());
                mPatchStart.push_back(static_cast<int>(mPatchTris.size()));
                ++patches;
                continue;
            }
        }
        if (n.left >= 0) {
            stack.push_back(n.right);
            stack.push_back(n.left);
        }
    }
    if (patches == 0) return 0;
    for (std::size_t i = 0; i < nv; ++i) {
        const int begin = mVertTriStart[i], end = mVertTriStart[i + 1];
        for (int j = begin; j < end; ++j)
            if (mTriLabel[mVertTris[j]] >= 0) mInPatch[i] = 1;
        if (!mInterior[i]) continue;
        const int label = mTriLabel[mVertTris[begin]];
        bool same = label >= 0;
        for (int j = begin + 1; j < end && same; ++j) same = mTriLabel[mVertTris[j]] == label;
        if (same) mVertLabel[i] = label;
    }
    return patches;
}

std::size_t FlatPatches::recertify(const std::vector<double>& x0, const std::vector<double>& x1,
                                   double slack, double thickness, std::vector<uint8_t>& lost) {
    std::vector<int> members, keptStart{0}, keptTris;
    std::vector<Cone> cones;
    std::size_t failed = 0;
    for (std::size_t p = 0; p + 1 < mPatchStart.size(); ++p) {
        members.assign(mPatchTris.begin() + mPatchStart[p],
                       mPatchTris.begin() + mPatchStart[p + 1]);
        // Merged pairwise, level by level (as the tree merged them: a sequential merge can
        // widen the cone far beyond the normals' spread).
        cones.clear();
        const int stamp = mNextStamp++;
        for (int t : members) {
            cones.push_back(triangleCone(static_cast<std::size_t>(t), x0, x1, slack));
            mStamp[static_cast<std::size_t>(t)] = stamp;
        }
        for (std::size_t width = 1; width < cones.size(); width *= 2)
            for (std::size_t i = 0; i + width < cones.size(); i += 2 * width)
                merge(cones[i], cones[i + width]);
        const Cone& cone = cones.front();
        if (narrowEnough(cone, thickness) &&
            starContour(members, stamp, cone.axis, x0, x1, slack)) {
            keptTris.insert(keptTris.end(), members.begin(), members.end());
            keptStart.push_back(static_cast<int>(keptTris.size()));
            continue;
        }
        // Lost for good: its pairs are found another way from now on, so it is not tried again.
        ++failed;
        for (int t : members)
            for (int v : mTris[static_cast<std::size_t>(t)]) lost[static_cast<std::size_t>(v)] = 1;
    }
    mPatchStart.swap(keptStart);
    mPatchTris.swap(keptTris);
    return failed;
}

void FlatPatches::markFans(const std::vector<uint8_t>& vertices,
                           std::vector<uint8_t>& marked) const {
    for (std::size_t i = 0; i + 1 < mVertTriStart.size(); ++i) {
        if (!vertices[i]) continue;
        for (int j = mVertTriStart[i]; j < mVertTriStart[i + 1]; ++j)
            for (int v : mTris[static_cast<std::size_t>(mVertTris[j])]) marked[v] = 1;
    }
}

bool FlatPatches::starContour(const std::vector<int>& members, int id, const Vec3& d,
                              const std::vector<double>& x0, const std::vector<double>& x1,
                              double slack) const {
    // The contour: the sides (p → q, in the triangle's order) whose triangle across is not in
    // the patch (stamped `id`). With every triangle facing d (the cone), the patch lies on the
    // left of each.
    std::vector<std::array<int, 2>>& sides = mSides;
    sides.clear();
    Vec3 c0 = Vec3::Zero(), c1 = Vec3::Zero();
    for (int t : members) {
        const auto& v = mTris[static_cast<std::size_t>(t)];
        for (int k = 0; k < 3; ++k) {
            c0 += vec3At(x0.data(), v[k]);
            c1 += vec3At(x1.data(), v[k]);
            const int across = mAcross[static_cast<std::size_t>(3 * t + k)];
            if (across < 0 || mStamp[static_cast<std::size_t>(across)] != id)
                sides.push_back({v[k], v[(k + 1) % 3]});
        }
    }
    if (sides.size() < 3) return false;
    c0 /= 3.0 * static_cast<double>(members.size());
    c1 /= 3.0 * static_cast<double>(members.size());
    // About the mean of the corners, or else about the middle of the contour's kernel (where
    // every side's line leaves it on the left) at each end of the step.
    if (starAbout(sides, d, c0, c1, x0, x1, slack)) return true;
    Vec3 k0, k1;
    return kernelMiddle(sides, d, x0, k0) && kernelMiddle(sides, d, x1, k1) &&
           starAbout(sides, d, k0, k1, x0, x1, slack);
}

bool FlatPatches::starAbout(const std::vector<std::array<int, 2>>& sides, const Vec3& d,
                            const Vec3& c0, const Vec3& c1, const std::vector<double>& x0,
                            const std::vector<double>& x1, double slack) {
    // Star-shaped about c(τ) = c0 + τ(c1 − c0): f(τ) = d·((p − c) × (q − c)) > 0 at every τ, a
    // quadratic bounded below by its Bernstein coefficients' exact minimum, less what p and q
    // off their paths by ≤ δ can take away (δ(|p − c|max + |q − c|max) + δ²). The angles the
    // sides subtend at c, summed at τ = 0, are 2π: the contour winds once (not twice, nor in
    // two loops).
    double turning = 0.0;
    for (const auto& [p, q] : sides) {
        const Vec3 u0 = Vec3(vec3At(x0.data(), p)) - c0, u1 = Vec3(vec3At(x1.data(), p)) - c1;
        const Vec3 w0 = Vec3(vec3At(x0.data(), q)) - c0, w1 = Vec3(vec3At(x1.data(), q)) - c1;
        const double f0 = d.dot(u0.cross(w0));
        const double f1 = 0.5 * d.dot(u0.cross(w1) + u1.cross(w0));
        const double f2 = d.dot(u1.cross(w1));
        const double um = std::max(u0.norm(), u1.norm()), wm = std::max(w0.norm(), w1.norm());
        const double lower =
            quadraticMinimum(f0, f1, f2) - slack * (um + wm) - slack * slack - 1e-12 * um * wm;
        if (!(lower > 0.0)) return false;
        turning += std::atan2(f0, u0.dot(w0) - d.dot(u0) * d.dot(w0));
    }
    return std::abs(turning - 2.0 * M_PI) < 1.0;
}

bool FlatPatches::kernelMiddle(const std::vector<std::array<int, 2>>& sides, const Vec3& d,
                               const std::vector<double>& x, Vec3& centre) {
    // In the plane across d (basis e₁, e₂): a square holding the contour clipped by the left
    // half-plane of each side (Sutherland–Hodgman); the centre the mean of what remains.
    const Vec3 e1 = d.unitOrthogonal(), e2 = d.cross(e1);
    const Vec3 origin = vec3At(x.data(), sides.front()[0]);
    const auto plane = [&](int v) {
        const Vec3 r = Vec3(vec3At(x.data(), v)) - origin;
        return Eigen::Vector2d(r.dot(e1), r.dot(e2));
    };
    double extent = 0.0;
    for (const auto& s : sides) extent = std::max(extent, plane(s[0]).cwiseAbs().maxCoeff());
    std::vector<Eigen::Vector2d> poly = {{-2 * extent, -2 * extent},
                                         {2 * extent, -2 * extent},
                                         {2 * extent, 2 * extent},
                                         {-2 * extent, 2 * extent}},
                                 next;
    for (const auto& [p, q] : sides) {
        const Eigen::Vector2d a = plane(p), b = plane(q), e = b - a;
        const auto side = [&](const Eigen::Vector2d& y) { // > 0: left of a → b
            return e.x() * (y.y() - a.y()) - e.y() * (y.x() - a.x());
        };
        next.clear();
        for (std::size_t i = 0; i < poly.size(); ++i) {
            const Eigen::Vector2d& y0 = poly[i];
            const Eigen::Vector2d& y1 = poly[(i + 1) % poly.size()];
            const double s0 = side(y0), s1 = side(y1);
            if (s0 >= 0.0) next.push_back(y0);
            if ((s0 >= 0.0) != (s1 >= 0.0)) next.push_back(y0 + (s0 / (s0 - s1)) * (y1 - y0));
        }
        poly.swap(next);
        if (poly.size() < 3) return false;
    }
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& y : poly) mean += y;
    mean /= static_cast<double>(poly.size());
    centre = origin + mean.x() * e1 + mean.y() * e2;
    return true;
}

} // namespace gale::solver
