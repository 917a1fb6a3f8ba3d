// Moving mesh colliders at one substep per frame: a ball flying at 5 m/s into a free sheet
// carries it in front (no vertex inside the ball, none behind its centre within its silhouette),
// and so does a 2 cm paddle at 5 m/s moving ten times its thickness per frame (the tunnelling
// case), face-first and edge-first; closest points at the step's ends carry the surface velocity.
#include "geometry/geometry.h"
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/collider/moving_collider.h"
#include "solver/contact/ccd.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <random>

using namespace gale::solver;
using gale::fields::Param;

namespace {

struct Solid {
    std::vector<std::array<int, 3>> tris;
    std::vector<double> pos; // at the origin
};

// A closed UV sphere, outward winding.
Solid uvSphere(double r, int nlat, int nlon) {
    const gale::geometry::TriangleMesh m = gale::geometry::uvSphereMesh({0, 0, 0}, r, nlat, nlon);
    Solid s;
    for (const auto& p : m.points) s.pos.insert(s.pos.end(), {p[0], p[1], p[2]});
    for (const auto& t : m.triangles)
        s.tris.push_back({static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])});
    return s;
}

// A box of half sizes (hx, hy, hz), outward winding.
Solid box(double hx, double hy, double hz) {
    Solid s;
    for (int k = 0; k < 8; ++k)
        s.pos.insert(s.pos.end(), {(k & 1) ? hx : -hx, (k & 2) ? hy : -hy, (k & 4) ? hz : -hz});
    const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (auto& f : q) {
        s.tris.push_back({f[0], f[1], f[2]});
        s.tris.push_back({f[0], f[2], f[3]});
    }
    return s;
}

// Frames 0..frames of the solid, each vertex at R_f p + c_f.
std::shared_ptr<const MeshSequence> posed(const Solid& s, int frames, double fps,
                                          const std::function<Mat3(int)>& rotation,
                                          const std::function<Vec3(int)>& centre) {
    std::vector<std::vector<double>> pos;
    for (int f = 0; f <= frames; ++f) {
        std::vector<double> p(s.pos.size());
        const Mat3 R = rotation(f);
        const Vec3 c = centre(f);
        for (size_t v = 0; v < p.size() / 3; ++v)
            vec3At(p.data(), v) = R * vec3At(s.pos.data(), v) + c;
        pos.push_back(std::move(p));
    }
    return std::make_shared<MeshSequence>(s.tris, pos, 0, fps);
}

// Frames 0..frames of the solid translated from `start` at `velocity` (m/s), at fps.
std::shared_ptr<const MeshSequence> flying(const Solid& s, const Vec3& start, const Vec3& velocity,
                                           int frames, double fps) {
    return posed(
        s, frames, fps, [](int) { return Mat3(Mat3::Identity()); },
        [&](int f) { return Vec3(start + velocity * (f / fps)); });
}

// The largest signed plane distance of x over the faces (< 0: inside a convex solid).
double convexDepth(const Solid& s, const Vec3& centre, const Vec3& x) {
    double m = -INFINITY;
    for (const auto& t : s.tris) {
        const Vec3 a = vec3At(s.pos.data(), t[0]) + centre, b = vec3At(s.pos.data(), t[1]) + centre,
                   c = vec3At(s.pos.data(), t[2]) + centre;
        const Vec3 n = (b - a).cross(c - a).normalized();
        m = std::max(m, (x - a).dot(n));
    }
    return m;
}

struct Outcome {
    double worstDepth = INFINITY; // the smallest convexDepth over vertices and frames (m)
    int behind = 0;               // vertices behind the centre within the silhouette
    double carried = 0.0;         // mean z travelled by the sheet's middle (m)
    int rejected = 0;
    long long unresolved = 0; // CCD passes that ended with a hit left
};

// A size × size sheet of res × res vertices at z = 0 (lift and drag as defaults: still air
// drags it back against the body); "behind" counts vertices with z below the body's centre
// whose distance from its path is below `silhouette`.
Outcome run(const Solid& solid, double silhouette, const Vec3& start, int frames, double size,
            int res) {
    const double fps = 24.0;
    const Vec3 vel(0, 0, 5.0);
    Collider c;
    c.shape = ColliderShape::Mesh;
    c.thickness = 0.005;
    c.friction = 0.3;
    c.moving = std::make_shared<MovingMeshContact>(flying(solid, start, vel, frames + 1, fps));
    ClothMaterial mat;
    mat.density = 0.1;
    auto cloth = std::make_unique<Cloth>(
        "sheet", makeGrid(size, size, res, res, Vec3(-0.5 * size, -0.5 * size, 0.0)), mat);
    Cloth* sheet = cloth.get();
    WorldSettings ws;
    ws.fps = fps;
    ws.substeps = 1;
    World world(ws);
    world.addBody(std::move(cloth));
    world.addCollider(c);
    Outcome o;
    for (int f = 1; f <= frames; ++f) {
        FrameStats fs = world.advanceFrame(f);
        REQUIRE(!fs.failed);
        o.rejected += fs.bodies[0].rejected;
        const Vec3 centre = start + vel * (f / fps);
        for (size_t i = 0; i < sheet->vertexCount(); ++i) {
            const Vec3 x = vec3At(sheet->positions().data(), i);
            o.worstDepth = std::min(o.worstDepth, convexDepth(solid, centre, x));
            if (std::hypot(x.x() - centre.x(), x.y() - centre.y()) < silhouette &&
                x.z() < centre.z())
                ++o.behind;
        }
    }
    o.carried = vec3At(sheet->positions().data(), (res / 2) * res + res / 2).z();
    o.unresolved = c.moving->stats().unresolved;
    return o;
}

} // namespace

TEST_CASE("moving mesh: closest points carry the surface velocity", "[collider][moving]") {
    const Solid s = box(0.5, 0.5, 0.5);
    MovingMeshContact m(flying(s, Vec3::Zero(), Vec3(0, 0, 2.4), 3, 24.0));
    m.prepare(0.0, 1.0 / 24.0);
    ContactPoint cp;
    REQUIRE(m.closest(Vec3(0.1, 0.2, 0.503), false, 0.01, cp));
    CHECK(cp.distance == Approx(0.003));
    CHECK(cp.normal.isApprox(Vec3::UnitZ()));
    CHECK(cp.velocity.isApprox(Vec3(0, 0, 2.4)));
    REQUIRE(m.closest(Vec3(0.1, 0.2, 0.603), true, 0.01, cp)); // the face moved 0.1 m
    CHECK(cp.distance == Approx(0.003));
    CHECK_FALSE(m.closest(Vec3(0.1, 0.2, 0.7), false, 0.01, cp));
    CHECK(std::isinf(cp.distance));
}

TEST_CASE("moving mesh: a ball at 5 m/s carries a free sheet, one substep per frame",
          "[collider][moving]") {
    const Solid ball = uvSphere(0.15, 12, 16);
    // A 0.3 m sheet: half its diagonal (0.21 m) is shorter than the ball's quarter circumference
    // (0.24 m), so wrapped round the ball it stays in front of the centre.
    const Outcome o = run(ball, 1e9, Vec3(0, 0, -0.4), 12, 0.3, 13);
    INFO("depth " << o.worstDepth << " behind " << o.behind << " carried " << o.carried
                  << " rejected " << o.rejected);
    CHECK(o.worstDepth > 0.0);
    CHECK(o.behind == 0);
    CHECK(o.carried > 1.5); // the ball's centre reached z = 2.1; the sheet rides its front
}

TEST_CASE("moving mesh: a 2 cm paddle at 5 m/s does not tunnel, face- or edge-first",
          "[collider][moving]") {
    {
        const Solid paddle = box(0.3, 0.3, 0.01); // face-first along z: 0.21 m per frame
        const Outcome o =
            run(paddle, 1e9, Vec3(0, 0, -0.3), 12, 0.5, 21); // smaller than the paddle
        INFO("depth " << o.worstDepth << " behind " << o.behind << " carried " << o.carried);
        CHECK(o.worstDepth > 0.0);
        CHECK(o.behind == 0);
        CHECK(o.carried > 1.5);
    }
    {
        const Solid paddle = box(0.01, 0.3, 0.3); // edge-first: a 2 cm face between 5 cm vertices
        const Outcome o = run(paddle, 0.0, Vec3(0.013, 0, -0.4), 12, 1.0, 21);
        INFO("depth " << o.worstDepth << " carried " << o.carried);
        CHECK(o.worstDepth > 0.0);
        CHECK(o.carried > 1.5);
    }
}

namespace {

// A rod along z of diameter `d`: an octagonal prism from z = −length to 0 with a pointed cone
// (height d/2) at each end, like a finger; tip vertex at (0, 0, d/2).
Solid rod(double d, double length) {
    Solid s;
    const int m = 8;
    for (int ring = 0; ring < 2; ++ring)
        for (int k = 0; k < m; ++k) {
            const double a = 2.0 * M_PI * k / m;
            s.pos.insert(s.pos.end(),
                         {0.5 * d * std::cos(a), 0.5 * d * std::sin(a), ring == 0 ? 0.0 : -length});
        }
    const int front = 2 * m, back = 2 * m + 1;
    s.pos.insert(s.pos.end(), {0.0, 0.0, 0.5 * d});
    s.pos.insert(s.pos.end(), {0.0, 0.0, -length - 0.5 * d});
    for (int k = 0; k < m; ++k) {
        const int a = k, b = (k + 1) % m, c = m + k, e = m + (k + 1) % m;
        s.tris.push_back({a, c, e});
        s.tris.push_back({a, e, b});
        s.tris.push_back({front, a, b});
        s.tris.push_back({back, e, c});
    }
    return s;
}

// Does segment pq cross triangle abc (strictly through its plane, inside or on its border)?
// Möller & Trumbore 1997, written out here apart from the solver's CCD.
bool segmentCrossesTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                            const Vec3& c) {
    const Vec3 d = q - p, e1 = b - a, e2 = c - a;
    const Vec3 hv = d.cross(e2);
    const double det = e1.dot(hv);
    if (std::abs(det) < 1e-18) return false;
    const Vec3 s = p - a;
    const double u = s.dot(hv) / det;
    const Vec3 qv = s.cross(e1);
    const double v = d.dot(qv) / det, t = e2.dot(qv) / det;
    return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < 1.0;
}

// Intersecting (rod triangle, cloth triangle) pairs: an edge of either crossing the other.
int crossings(const std::vector<std::array<int, 3>>& rodTris, const std::vector<double>& rodPos,
              const std::vector<std::array<int, 3>>& clothTris, const VecX& clothPos) {
    int count = 0;
    for (const auto& r : rodTris)
        for (const auto& c : clothTris) {
            Vec3 R[3], C[3];
            for (int k = 0; k < 3; ++k) {
                R[k] = vec3At(rodPos.data(), r[k]);
                C[k] = vec3At(clothPos.data(), c[k]);
            }
            bool hit = false;
            for (int e = 0; e < 3 && !hit; ++e)
                hit = segmentCrossesTriangle(R[e], R[(e + 1) % 3], C[0], C[1], C[2]) ||
                      segmentCrossesTriangle(C[e], C[(e + 1) % 3], R[0], R[1], R[2]);
            count += hit;
        }
    return count;
}

struct RodOutcome {
    int crossings = 0;        // summed over the frames' ends
    double maxStretch = 0.0;  // the largest edge length / rest length at a frame's end
    double lastStretch = 0.0; // the same at the last frame
    double pushed = 0.0;      // the sheet's largest z (m) at the last frame: how far it was carried
    double tip = 0.0;         // the rod tip's z (m) at the last frame
    bool finite = true;
    int rejected = 0;
};

// A 0.3 m sheet of 2.5 cm spacing (13 × 13) hanging in the xy plane at z = 0 from its pinned top
// row; a 1 cm rod, its tip 3 cm in front of the sheet, pokes tip first at 2 m/s along its axis
// (z, or tilted about x) through a face's interior (the centroid of the triangle
// (6,6)-(7,6)-(7,7), no cloth vertex or edge within 5 mm of its path): a two-frame sequence, 8 cm
// in 0.04 s, then held, its tip 5 cm past the sheet's plane; 6 frames at 24 fps.
RodOutcome rodThroughSheet(int substeps, double tiltDegrees, double friction) {
    const double fps = 24.0, spacing = 0.025;
    const int res = 13, frames = 6;
    const Solid r = rod(0.01, 0.2);
    const Vec3 hitPoint(-0.15 + (6 + 2.0 / 3.0) * spacing, (6 + 1.0 / 3.0) * spacing, 0.0);
    // The rod tilted about x (the axis and the motion stay along the rod: a poke, tip first).
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(tiltDegrees * M_PI / 180.0, Vec3::UnitX()).toRotationMatrix();
    const Vec3 dir = R * Vec3::UnitZ();
    const Vec3 start = hitPoint - (0.03 / dir.z()) * dir; // the tip 3 cm in front (along z)
    const double speed = 2.0, travel = 0.08;              // m/s, m along the rod
    std::vector<std::vector<double>> pos(2, r.pos);
    for (int f = 0; f < 2; ++f)
        for (size_t i = 0; i < r.pos.size() / 3; ++i)
            vec3At(pos[f].data(), i) = R * vec3At(r.pos.data(), i) + start + travel * f * dir;
    auto seq = std::make_shared<MeshSequence>(r.tris, pos, 0, speed / travel); // then held
    Collider c;
    c.shape = ColliderShape::Mesh;
    c.thickness = 0.003;
    c.friction = friction;
    c.moving = std::make_shared<MovingMeshContact>(seq);
    ClothMaterial mat;
    mat.density = 0.2;
    auto cloth =
        std::make_unique<Cloth>("sheet", makeGrid(0.3, 0.3, res, res, Vec3(-0.15, 0.0, 0.0)), mat);
    PinSet pins;
    for (int i = 0; i < res; ++i) pins.vertices.push_back((res - 1) * res + i);
    cloth->addPins(pins);
    Cloth* sheet = cloth.get();
    WorldSettings ws;
    ws.fps = fps;
    ws.substeps = substeps;
    World world(ws);
    world.addBody(std::move(cloth));
    world.addCollider(c);
    RodOutcome o;
    std::vector<double> at;
    for (int f = 1; f <= frames; ++f) {
        const FrameStats fs = world.advanceFrame(f);
        REQUIRE(!fs.failed);
        o.rejected += fs.bodies[0].rejected;
        const VecX& x = sheet->positions();
        o.finite = o.finite && x.allFinite() && sheet->velocities().allFinite();
        seq->positionsAt(f / fps, at);
        o.crossings += crossings(r.tris, at, sheet->mesh().triangles, x);
        double frameStretch = 0.0;
        for (const auto& e : meshEdges(sheet->mesh().triangles)) {
            const double rest = (vec3At(sheet->mesh().positions.data(), e[1]) -
                                 vec3At(sheet->mesh().positions.data(), e[0]))
                                    .norm();
            frameStretch = std::max(
                frameStretch, (vec3At(x.data(), e[1]) - vec3At(x.data(), e[0])).norm() / rest);
        }
        o.maxStretch = std::max(o.maxStretch, frameStretch);
        o.lastStretch = frameStretch;
        o.pushed = -INFINITY;
        for (size_t i = 0; i < sheet->vertexCount(); ++i)
            o.pushed = std::max(o.pushed, x[3 * i + 2]);
        o.tip = vec3At(at.data(), 16).z(); // the front tip vertex (rod())
    }
    return o;
}

} // namespace

TEST_CASE("moving mesh: a 1 cm rod at 2 m/s does not pass through a sheet of 2.5 cm spacing",
          "[collider][moving]") {
    // The rod's cross-section is under half the sheet's spacing and it enters a face's
    // interior: no cloth vertex meets its triangles and no cloth edge its edges; only its tip
    // vertex meets the face (the body vertex–cloth triangle pair). Crossings are counted from
    // the geometry at each frame's end (any rod triangle and cloth triangle intersecting).
    // Without the pair (the code before it) the rod went through: 32 intersecting pairs over
    // the frames in each of the four runs below.
    for (double mu : {0.0, 0.3})
        for (int substeps : {1, 2})
            for (double tilt : {0.0, 30.0}) {
                const RodOutcome o = rodThroughSheet(substeps, tilt, mu);
                INFO("friction " << mu << ", substeps " << substeps << " tilt " << tilt
                                 << ": crossings " << o.crossings << ", stretch " << o.maxStretch
                                 << " (last frame " << o.lastStretch << "), sheet at z " << o.pushed
                                 << " m, tip at " << o.tip << " m, rejected " << o.rejected);
                CHECK(o.crossings == 0);
                CHECK(o.finite);
                // Pushed: the sheet is carried ahead of the tip, which is 5 cm (tilted: 4.4 cm)
                // past where the sheet hung.
                CHECK(o.tip > 0.04);
                CHECK(o.pushed > o.tip);
                // Not torn: no edge past the solver's own over-stretch limit (BodyLimits, 3×).
                // The in-solve contact planes of the pair carry the tent (measured 1.14–1.25,
                // and 2.63 at one substep tilted, at the first impact, which only the
                // continuous pass sees; with the pass alone, 2.4–3.1).
                CHECK(o.maxStretch < 3.0);
                // Frictionless, the tent settles while the rod is held: at the last frame no
                // edge is stretched more than the 6 % a straight line from the pins (14 cm
                // above) to a point 5 cm out would need (measured 1.002–1.05). With friction
                // (0.3, implicit in the solve) the cloth held on the tip need not slide back
                // within the 4 frames (measured 1.20 at one substep tilted): static friction
                // may hold a tent, so only the bounds above apply.
                if (mu == 0.0) CHECK(o.lastStretch < 1.1);
            }
}

// Hair roots pinned within the collider's thickness (moving_collider.cpp, ξ_e): the root
// segment is held off the body by the root's own clearance, so nothing throws its free end.
// 1. The root 0.55 ξ over a box's ridge that rises 0.1 ξ in the step (a skinned scalp under a
//    root 5 mm off it, ξ = 1 cm, as in examples/11_character with the roots lowered), the segment
//    2 cm out over the ridge and slightly down, its point nearest the ridge ~4 % along it: held
//    off by ξ at the point met (before), the free end was thrown by shortfall / weight = 0.16 m
//    (6 m in the character). 2. The root on the top face, the box sliding 2 mm under it: its
//    edges pass through the root; the free end (2 cm up) is not pushed (before: up to ξ a pass,
//    sideways; the character's root segments 1.45× their rest length).
TEST_CASE("moving mesh: a root pinned within the thickness does not throw its segment",
          "[collider][moving]") {
    const double xi = 0.01, h = 1.0 / 24.0;
    const Solid s = box(0.1, 0.05, 0.1); // the ridge along x at y = 0.05, z = 0.1
    const std::vector<uint8_t> movable = {0, 1};
    SECTION("a ridge rising under a root 0.55 ξ above it") {
        MovingMeshContact m(flying(s, Vec3::Zero(), Vec3(0, 0.1 * xi / h, 0), 3, 24.0));
        m.prepare(0.0, h);
        VecX x0(6);
        x0 << 0.0, 0.05 + 0.55 * xi, 0.0998, 0.0, 0.05 + 0.55 * xi - 0.002, 0.1198;
        VecX x1 = x0, v1 = VecX::Zero(6);
        m.sweep(x0, x1, v1, movable, {{0, 1}}, {}, xi, 0.0, h);
        CHECK((x1.segment<3>(0) - x0.segment<3>(0)).norm() == 0.0);
        // At most the root's clearance at the end (0.45 ξ): nothing needs moving at all here.
        CHECK((x1.segment<3>(3) - x0.segment<3>(3)).norm() <= 0.45 * xi);
        CHECK(v1.allFinite());
        // Still above the ridge (y = 0.05 + 0.1 ξ at the end) where it passes over it.
        const double sRidge = (0.1 - x1[2]) / (x1[5] - x1[2]);
        CHECK(x1[1] + sRidge * (x1[4] - x1[1]) > 0.05 + 0.1 * xi);
    }
    SECTION("a box sliding under a root on its face") {
        MovingMeshContact m(flying(s, Vec3::Zero(), Vec3(0.002 / h, 0, 0), 3, 24.0));
        m.prepare(0.0, h);
        VecX x0(6);
        x0 << 0.001, 0.05, 0.0, 0.006, 0.07, 0.0; // the root on the diagonal's path
        VecX x1 = x0, v1 = VecX::Zero(6);
        m.sweep(x0, x1, v1, movable, {{0, 1}}, {}, xi, 0.0, h);
        CHECK((x1.segment<3>(0) - x0.segment<3>(0)).norm() == 0.0);
        CHECK((x1.segment<3>(3) - x0.segment<3>(3)).norm() <= 1e-3 * xi);
    }
}

// The trees and their queries live in the frame moving with the body (its mean displacement
// taken out of every swept box): a ball travelling 2 m in one step, with points near it at
// both ends. Closest points and nearest vertices match a brute-force search over the mesh at
// that end; a vertex riding 3 mm off the surface meets only the triangles near it (in the
// world frame its 2 m swept box met every triangle the ball swept past), and one that passes
// into the ball relative to it is still caught.
TEST_CASE("moving mesh: queries in the body's moving frame", "[collider][moving]") {
    const double h = 1.0 / 24.0, r = 0.2, xi = 0.005;
    const Solid s = uvSphere(r, 24, 48);
    const Vec3 vel(48.0, 12.0, -24.0); // 2 m, 0.5 m, −1 m over the step
    MovingMeshContact m(flying(s, Vec3::Zero(), vel, 3, 24.0));
    m.prepare(0.0, h);
    const auto brute = [&](const Vec3& x, bool atEnd, double& d2) {
        d2 = INFINITY;
        const Vec3 c = atEnd ? Vec3(vel * h) : Vec3::Zero();
        for (const auto& t : s.tris) {
            double w[3];
            d2 = std::min(d2, contact::pointTriangleDistance2(x, vec3At(s.pos.data(), t[0]) + c,
                                                              vec3At(s.pos.data(), t[1]) + c,
                                                              vec3At(s.pos.data(), t[2]) + c, w));
        }
    };
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int k = 0; k < 200; ++k) {
        const bool atEnd = k % 2;
        Vec3 dir(U(rng), U(rng), U(rng));
        if (dir.norm() < 1e-3) continue;
        dir.normalize();
        const Vec3 x = (atEnd ? Vec3(vel * h) : Vec3::Zero()) + (r + 0.01 * U(rng)) * dir;
        double want2;
        brute(x, atEnd, want2);
        ContactPoint cp;
        const bool found = m.closest(x, atEnd, 0.02, cp);
        REQUIRE(found == (want2 < 0.02 * 0.02));
        if (found) CHECK(cp.distance == Approx(std::sqrt(want2)).margin(1e-12));
        if (found) CHECK(cp.velocity.isApprox(vel, 1e-9));
    }
    // The body vertex nearest a small cloth triangle at the start.
    for (int k = 0; k < 50; ++k) {
        Vec3 dir(U(rng), U(rng), U(rng));
        if (dir.norm() < 1e-3) continue;
        dir.normalize();
        const Vec3 a = (r + 0.004) * dir, b = a + Vec3(0.01, 0, 0), c = a + Vec3(0, 0.01, 0.003);
        double want2 = INFINITY;
        for (size_t v = 0; v < s.pos.size() / 3; ++v) {
            double w[3];
            want2 = std::min(want2,
                             contact::pointTriangleDistance2(vec3At(s.pos.data(), v), a, b, c, w));
        }
        Vec3 p, velocity;
        double w[3], dist;
        const bool found = m.nearestVertex(a, b, c, 0.02, p, w, dist, velocity);
        REQUIRE(found == (want2 < 0.02 * 0.02));
        if (found) CHECK(dist == Approx(std::sqrt(want2)).margin(1e-12));
    }
    // Riding: 3 mm above the top of the ball, carried with it; and a second vertex 3 mm above
    // its side at the start that ends 5 mm inside it (relative to the ball).
    VecX x0(6), x1(6), v1(6);
    x0 << 0.0, r + 0.003, 0.0, r + 0.003, 0.0, 0.0;
    x1 << 0.0, r + 0.003, 0.0, r - 0.005, 0.0, 0.0;
    for (int i = 0; i < 2; ++i) x1.segment<3>(3 * i) += vel * h;
    v1 = (x1 - x0) / h;
    const long long before = m.stats().candidates;
    m.sweep(x0, x1, v1, {1, 1}, {}, {}, xi, 0.0, h);
    const long long candidates = m.stats().candidates - before;
    CHECK(candidates < static_cast<long long>(s.tris.size()) / 10); // over all passes
    // The riding vertex is untouched; the other ends at the thickness off the ball's side.
    CHECK((x1.segment<3>(0) - (x0.segment<3>(0) + vel * h)).norm() == 0.0);
    CHECK((x1.segment<3>(3) - vel * h).norm() >= r + 0.5 * xi);
}

namespace {

// Step after step, the same queries of `kept` (prepared step after step, so that it may keep
// its trees) and of a contact built afresh at each step give the same answers, exactly.
void sameAsFresh(const std::shared_ptr<const MeshSequence>& seq, int steps, double r,
                 long long& kept, long long& refits) {
    const double h = 1.0 / 24.0, xi = 0.005;
    MovingMeshContact m(seq);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int k = 0; k < steps; ++k) {
        const double t0 = k * h, t1 = (k + 1) * h;
        m.prepare(t0, t1);
        MovingMeshContact fresh(seq);
        fresh.prepare(t0, t1);
        std::vector<double> c0, c1;
        seq->positionsAt(t0, c0);
        seq->positionsAt(t1, c1);
        Vec3 m0 = Vec3::Zero(), m1 = Vec3::Zero();
        for (size_t v = 0; v < c0.size() / 3; ++v) {
            m0 += vec3At(c0.data(), v);
            m1 += vec3At(c1.data(), v);
        }
        m0 /= static_cast<double>(c0.size() / 3);
        m1 /= static_cast<double>(c1.size() / 3);
        for (int q = 0; q < 60; ++q) {
            Vec3 dir(U(rng), U(rng), U(rng));
            if (dir.norm() < 1e-3) continue;
            dir.normalize();
            const bool atEnd = q % 2;
            const Vec3 x = (atEnd ? m1 : m0) + (r + 0.008 * U(rng)) * dir;
            ContactPoint a, b;
            REQUIRE(m.closest(x, atEnd, 0.02, a) == fresh.closest(x, atEnd, 0.02, b));
            CHECK(a.distance == b.distance);
            CHECK(a.normal == b.normal);
            CHECK(a.velocity == b.velocity);
            const Vec3 ta = m0 + (r + 0.004) * dir, tb = ta + Vec3(0.01, 0, 0),
                       tc = ta + Vec3(0, 0.01, 0.003);
            Vec3 pa, pb, va, vb;
            double wa[3], wb[3], da = 0.0, db = 0.0;
            REQUIRE(m.nearestVertex(ta, tb, tc, 0.02, pa, wa, da, va) ==
                    fresh.nearestVertex(ta, tb, tc, 0.02, pb, wb, db, vb));
            CHECK(pa == pb);
            CHECK(da == db);
        }
        // The continuous pass: a few vertices riding 3 mm off the surface, some ending inside.
        const int n = 24;
        VecX x0(3 * n), x1(3 * n);
        for (int i = 0; i < n; ++i) {
            Vec3 dir(U(rng), U(rng), U(rng));
            dir.normalize();
            x0.segment<3>(3 * i) = m0 + (r + 0.003) * dir;
            x1.segment<3>(3 * i) = m1 + (r + 0.003 - (i % 3) * 0.004) * dir;
        }
        VecX y1 = x1, v1 = (x1 - x0) / h, w1 = v1;
        const std::vector<uint8_t> movable(n, 1);
        m.sweep(x0, x1, v1, movable, {}, {}, xi, 0.3, h);
        fresh.sweep(x0, y1, w1, movable, {}, {}, xi, 0.3, h);
        CHECK(x1 == y1);
        CHECK(v1 == w1);
    }
    kept = m.stats().kept;
    refits = m.stats().refits;
}

} // namespace

TEST_CASE("moving mesh: a body moving as one keeps its trees, with the answers of a refit",
          "[collider][moving]") {
    const double r = 0.2;
    const Solid s = uvSphere(r, 24, 48);
    long long kept = 0, refits = 0;
    // In flight, falling and speeding up (every vertex by the same displacement): the trees
    // built at the first step serve every later one.
    sameAsFresh(posed(
                    s, 8, 24.0, [](int) { return Mat3(Mat3::Identity()); },
                    [](int f) {
                        const double t = f / 24.0;
                        return Vec3(5.0 * t, 2.0 * t - 4.9 * t * t, -t);
                    }),
                6, r, kept, refits);
    CHECK(kept == 5);
    CHECK(refits == 0);
    // Turning 10° a frame: the vertices leave the carried boxes by ~3 cm, so each step refits.
    sameAsFresh(
        posed(
            s, 8, 24.0,
            [](int f) { return Mat3(Eigen::AngleAxisd(f * 10.0 * M_PI / 180.0, Vec3::UnitY())); },
            [](int f) { return Vec3(f / 24.0, 0.0, 0.0); }),
        6, r, kept, refits);
    CHECK(kept == 0);
    CHECK(refits == 5);
}

TEST_CASE("moving mesh: a closest-point query's hint changes nothing but its cost",
          "[collider][moving]") {
    const double h = 1.0 / 24.0, r = 0.2;
    const Solid s = uvSphere(r, 24, 48);
    MovingMeshContact m(flying(s, Vec3::Zero(), Vec3(2.0, 0.0, 0.0), 3, 24.0));
    m.prepare(0.0, h);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    std::uniform_int_distribution<int> anyTri(0, static_cast<int>(s.tris.size()) - 1);
    int found = 0;
    for (int k = 0; k < 300; ++k) {
        Vec3 dir(U(rng), U(rng), U(rng));
        if (dir.norm() < 1e-3) continue;
        dir.normalize();
        const bool atEnd = k % 2;
        // Some points at a vertex of the mesh (equal distances to several triangles: the tie).
        const Vec3 centre = atEnd ? Vec3(2.0 * h, 0.0, 0.0) : Vec3::Zero();
        const Vec3 x = k % 5 == 0
                           ? Vec3(centre + 1.01 * vec3At(s.pos.data(), k % (s.pos.size() / 3)))
                           : Vec3(centre + (r + 0.008 * U(rng)) * dir);
        ContactPoint plain;
        const bool hit = m.closest(x, atEnd, 0.01, plain);
        found += hit;
        for (int hint : {plain.triangle, anyTri(rng), -1, static_cast<int>(s.tris.size()) + 3}) {
            ContactPoint cp;
            REQUIRE(m.closest(x, atEnd, 0.01, cp, hint) == hit);
            CHECK(cp.distance == plain.distance);
            CHECK(cp.triangle == plain.triangle);
            CHECK(cp.normal == plain.normal);
            CHECK(cp.velocity == plain.velocity);
        }
    }
    CHECK(found > 100);
}
