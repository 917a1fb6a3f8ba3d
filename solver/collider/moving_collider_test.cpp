// Moving mesh colliders at one substep per frame: a ball flying at 5 m/s into a free sheet
// carries it in front (no vertex inside the ball, none behind its centre within its silhouette),
// and so does a 2 cm paddle at 5 m/s moving ten times its thickness per frame (the tunnelling
// case), face-first and edge-first; closest points at the step's ends carry the surface velocity.
#include "geometry/geometry.h"
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/collider/moving_collider.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>

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

// Frames 0..frames of the solid translated from `start` at `velocity` (m/s), at fps.
std::shared_ptr<const MeshSequence> flying(const Solid& s, const Vec3& start, const Vec3& velocity,
                                           int frames, double fps) {
    std::vector<std::vector<double>> pos;
    for (int f = 0; f <= frames; ++f) {
        std::vector<double> p = s.pos;
        const Vec3 c = start + velocity * (f / fps);
        for (size_t i = 0; i < p.size(); ++i) p[i] += c[i % 3];
        pos.push_back(std::move(p));
    }
    return std::make_shared<MeshSequence>(s.tris, pos, 0, fps);
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
    m.prepare(0.0, 1.0 / 24.0, 0.01);
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
