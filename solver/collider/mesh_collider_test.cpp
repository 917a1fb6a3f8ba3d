// Mesh colliders: the SDF of a box mesh against the analytic box distance and face normals,
// the same through queryCollider, cloth draped over a mesh sphere staying outside it (within a
// voxel), and the scene loader's [[collider]] type = "mesh" with its errors.
#include "geometry/geometry.h"
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/collider/mesh_collider.h"
#include "scene/sim_scene.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace gale::solver;
using gale::fields::Param;

namespace {

struct TempDir {
    std::filesystem::path path;
    TempDir() {
        char tmpl[] = "/tmp/gale_mesh_collider_XXXXXX";
        path = mkdtemp(tmpl);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    std::string file(const std::string& name) const { return (path / name).string(); }
};

// Distance to the box [-h, h] (outside: Euclidean; inside: minus the distance to the nearest face).
double boxDistance(const Vec3& p, const Vec3& h) {
    const Vec3 q = p.cwiseAbs() - h;
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

} // namespace

TEST_CASE("mesh collider: distance and normal of a box mesh", "[collider][mesh]") {
    TempDir dir;
    const Vec3 h(0.3, 0.2, 0.25);
    REQUIRE_FALSE(gale::geometry::writeTriangleMeshObj(
        dir.file("box.obj"), gale::geometry::boxMesh({-0.3, -0.2, -0.25}, {0.3, 0.2, 0.25})));
    std::string error;
    const double voxel = 0.01;
    auto mesh = MeshCollider::load(dir.file("box.obj"), voxel, error);
    INFO(error);
    REQUIRE(mesh);
    for (const Vec3& p : {Vec3(0.35, 0, 0), Vec3(0, 0.23, 0.1), Vec3(-0.1, 0.05, -0.31),
                          Vec3(0.25, 0.0, 0.0), Vec3(0.1, -0.15, 0.05)}) {
        double d = 0.0;
        Vec3 n;
        mesh->query(p, d, n);
        INFO("p " << p.transpose() << " d " << d);
        CHECK(std::abs(d - boxDistance(p, h)) < voxel);
        CHECK(n.norm() == Approx(1.0));
    }
    double d = 0.0;
    Vec3 n;
    mesh->query(Vec3(0.4, 0.02, -0.03), d, n); // in front of the +x face
    CHECK(n.x() > 0.99);
    mesh->query(Vec3(0.01, -0.27, 0.0), d, n); // below the -y face
    CHECK(n.y() < -0.99);

    // The same through the collider interface.
    Collider c;
    c.shape = ColliderShape::Mesh;
    c.mesh = mesh;
    const ContactPoint cp = queryCollider(colliderPose(c, 0.0), Vec3(0.4, 0.02, -0.03));
    CHECK(cp.distance == Approx(0.1).margin(voxel));
    CHECK(cp.normal.x() > 0.99);
    CHECK(cp.velocity.norm() == 0.0);

    CHECK_FALSE(MeshCollider::load(dir.file("missing.obj"), voxel, error));
    CHECK(error.find("missing.obj") != std::string::npos);
}

TEST_CASE("mesh collider: cloth draped over a mesh sphere stays outside it", "[collider][mesh]") {
    TempDir dir;
    REQUIRE_FALSE(gale::geometry::writeTriangleMeshObj(
        dir.file("ball.obj"), gale::geometry::uvSphereMesh({0, 0, 0}, 0.4, 24, 48)));
    std::string error;
    const double voxel = 0.02;
    auto ball = MeshCollider::load(dir.file("ball.obj"), voxel, error);
    REQUIRE(ball);
    TriMesh sheet = makeGrid(1.2, 1.2, 16, 16, Vec3(-0.6, 0.6, -0.6), Vec3::UnitX(), Vec3::UnitZ());
    ClothMaterial m;
    m.density = 0.1;
    m.lift.value = Param(0.0);
    m.drag.value = Param(0.0);
    World w(WorldSettings{});
    w.addBody(std::make_unique<Cloth>("sheet", sheet, m));
    Collider c;
    c.shape = ColliderShape::Mesh;
    c.mesh = ball;
    c.thickness = 0.01;
    w.addCollider(c);
    int contacts = 0;
    for (int f = 1; f <= 30; ++f) {
        const FrameStats fs = w.advanceFrame(f);
        REQUIRE_FALSE(fs.failed);
        contacts = fs.bodies[0].contacts;
        const VecX& x = w.bodies()[0]->positions();
        double minDist = 1e9;
        for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i)
            minDist = std::min(minDist, vec3At(x.data(), i).norm());
        // The SDF is within a voxel of the (tessellated) sphere.
        CHECK(minDist >= 0.4 + 0.01 - voxel);
    }
    CHECK(contacts > 10);
    CHECK(w.bodies()[0]->positions()[1] < 0.0); // the corners fell below the top
}
