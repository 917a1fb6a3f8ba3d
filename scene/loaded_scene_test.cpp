// Scenes loaded by the scene loader and then used by the layers below it: fields built from a
// loaded scene (file names in expressions), a mesh collider from [[collider]], the
// preconditioner key of [[cloth]]. (The cases came from the fields and solver tests, which
// no longer see the loader.)
#include "fields/expression_field.h"
#include "geometry/geometry.h"
#include "io/test_support.h"
#include "scene/load.h"
#include "solver/collider/collider.h"
#include "solver/collider/mesh_collider.h"
#include "scene/sim_scene.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace gale::fields;
using namespace gale::scene;
using namespace gale::solver;
using gale::io::test::TempDir;
namespace fs = std::filesystem;

namespace {

std::vector<double> sampleAt(const Field& f, const std::vector<double>& xyz, double time = 0.0,
                             double fps = 24.0) {
    std::vector<double> v(xyz.size());
    SampleTime when;
    when.time = time;
    when.fps = fps;
    SampleStatus s = f.sample(xyz.data(), xyz.size() / 3, when, v.data());
    INFO(s.message);
    CHECK(s.ok);
    return v;
}

} // namespace

TEST_CASE("a scene's expressions name files relative to their own file, inside the scene's "
          "folder",
          "[geometry][builtins]") {
    TempDir dir;
    fs::create_directories(dir.path / "wind");
    REQUIRE_FALSE(gale::geometry::writeTriangleMeshObj(dir.file("body.obj"), gale::geometry::uvSphereMesh({0, 0, 0}, 0.5, 16, 32)));
    std::ofstream(dir.file("wind/around.se")) << "[sdf(\"../body.obj\", $P), 0, 0]\n";
    std::ofstream(dir.file("scene.toml"))
        << "[[field]]\nname = \"a\"\nexpr = \"wind/around.se\"\n"
           "[[field]]\nname = \"b\"\nsource = 'sdf(\"body.obj\", $P) * [0, 1, 0]'\n";
    Scene scene;
    std::vector<SceneError> errors;
    REQUIRE(loadScene(dir.file("scene.toml"), scene, errors));
    std::string report;
    FieldPtr f = buildSceneField(scene, gale::runtime::Precision::Double, report);
    INFO(report);
    REQUIRE(f);
    const std::vector<double> v = sampleAt(*f, {1.0, 0, 0});
    CHECK(v[0] == Approx(0.5).margin(0.02));
    CHECK(v[1] == Approx(0.5).margin(0.02));

    // An inline source that leaves the scene's folder: an error at its line and column.
    std::ofstream(dir.file("bad.toml"))
        << "[[field]]\nname = \"a\"\nsource = 'sdf(\"../x.obj\", $P)'\n";
    REQUIRE(loadScene(dir.file("bad.toml"), scene, errors));
    report.clear();
    CHECK_FALSE(buildSceneField(scene, gale::runtime::Precision::Double, report));
    CHECK(report.find("bad.toml:3:15: error: '../x.obj' leads outside") != std::string::npos);
}

TEST_CASE("mesh collider in a scene: [[collider]] type = \"mesh\"", "[collider][mesh][scene]") {
    TempDir dir;
    REQUIRE_FALSE(gale::geometry::writeTriangleMeshObj(
        dir.file("body.obj"), gale::geometry::boxMesh({-0.2, 0, -0.1}, {0.2, 1.6, 0.1})));
    auto load = [&](const std::string& text, SimScene& scene, std::string& all) {
        std::ofstream(dir.file("scene.toml")) << text;
        std::vector<gale::scene::SceneError> errors;
        const bool ok = loadSimScene(dir.file("scene.toml"), scene, errors);
        all.clear();
        for (const auto& e : errors) all += e.render() + "\n";
        return ok;
    };
    SimScene scene;
    std::string all;
    REQUIRE(load("[[collider]]\nname = \"body\"\ntype = \"mesh\"\nmesh = \"body.obj\"\n"
                 "voxel = 0.02\nthickness = 0.005\n",
                 scene, all));
    INFO(all);
    REQUIRE(scene.colliders.size() == 1);
    CHECK(scene.colliders[0].shape == ColliderShape::Mesh);
    REQUIRE(scene.colliders[0].mesh);
    CHECK(scene.colliders[0].mesh->sdf().voxel() == 0.02);
    const ContactPoint cp = queryCollider(colliderPose(scene.colliders[0], 0.0), gale::solver::Vec3(0.5, 1, 0));
    CHECK(cp.distance == Approx(0.3).margin(0.02));

    CHECK_FALSE(load("[[collider]]\ntype = \"mesh\"\nmesh = \"nobody.obj\"\n", scene, all));
    CHECK(all.find("scene.toml:3:8: error: [[collider]] 'collider0': cannot read") !=
          std::string::npos);
    CHECK(all.find("nobody.obj") != std::string::npos);
    CHECK_FALSE(load("[[collider]]\ntype = \"mesh\"\n", scene, all));
    CHECK(all.find("a mesh collider needs 'mesh'") != std::string::npos);
    CHECK_FALSE(load("[[collider]]\ntype = \"mesh\"\nmesh = \"body.obj\"\nradius = 1\n", scene, all));
    CHECK(all.find("'radius' does not apply to a mesh collider") != std::string::npos);
    CHECK_FALSE(load("[[collider]]\ntype = \"mesh\"\nmesh = \"body.obj\"\nvoxel = 0\n", scene, all));
    CHECK(all.find("voxel") != std::string::npos);
}

TEST_CASE("multigrid: the scene key picks the preconditioner; a bad value is an error at file:line:col",
          "[multigrid][scene]") {
    char tmpl[] = "/tmp/gale_multigrid_scene_XXXXXX";
    const int fd = mkstemp(tmpl);
    REQUIRE(fd >= 0);
    close(fd);
    const std::string path = tmpl;
    auto load = [&](const std::string& value, SimScene& scene, std::string& errors) {
        std::ofstream(path) << "[[cloth]]\nname = \"c\"\ngrid = { size = [1, 1], res = [4, 4] }\n"
                            << (value.empty() ? "" : "preconditioner = " + value + "\n");
        std::vector<gale::scene::SceneError> errs;
        const bool ok = loadSimScene(path, scene, errs, {});
        for (const auto& e : errs) errors += e.render() + "\n";
        return ok;
    };
    SimScene a, b, c, d;
    std::string ea, eb, ec, ed;
    REQUIRE(load("", a, ea));
    CHECK(a.cloths[0].step.preconditioner == Preconditioner::Multigrid); // the default
    REQUIRE(load("\"multigrid\"", b, eb));
    CHECK(b.cloths[0].step.preconditioner == Preconditioner::Multigrid);
    REQUIRE(load("\"jacobi\"", d, ed));
    CHECK(d.cloths[0].step.preconditioner == Preconditioner::BlockJacobi);
    CHECK_FALSE(load("\"amg\"", c, ec));
    INFO(ec);
    CHECK(ec.find(path + ":4:18: error: unknown preconditioner 'amg'") != std::string::npos);
    std::remove(path.c_str());
}

TEST_CASE("multigrid: the multigrid key picks plain or smoothed aggregation; a bad value is an error",
          "[multigrid][scene]") {
    char tmpl[] = "/tmp/gale_multigrid_kind_XXXXXX";
    const int fd = mkstemp(tmpl);
    REQUIRE(fd >= 0);
    close(fd);
    const std::string path = tmpl;
    auto load = [&](const std::string& value, SimScene& scene, std::string& errors) {
        std::ofstream(path) << "[[cloth]]\nname = \"c\"\ngrid = { size = [1, 1], res = [4, 4] }\n"
                            << (value.empty() ? "" : "multigrid = " + value + "\n");
        std::vector<gale::scene::SceneError> errs;
        const bool ok = loadSimScene(path, scene, errs, {});
        for (const auto& e : errs) errors += e.render() + "\n";
        return ok;
    };
    SimScene a, b, c, d, e, f;
    std::string ea, eb, ec, ed, ee, ef;
    REQUIRE(load("", a, ea));
    CHECK(a.cloths[0].step.multigrid == MultigridKind::Automatic); // the default
    REQUIRE(load("\"plain\"", b, eb));
    CHECK(b.cloths[0].step.multigrid == MultigridKind::Plain);
    REQUIRE(load("\"smoothed\"", c, ec));
    CHECK(c.cloths[0].step.multigrid == MultigridKind::Smoothed);
    REQUIRE(load("\"auto\"", d, ed));
    CHECK(d.cloths[0].step.multigrid == MultigridKind::Automatic);
    REQUIRE(load("\"smoothed-rotations\"", f, ef));
    CHECK(f.cloths[0].step.multigrid == MultigridKind::SmoothedRotations);
    CHECK_FALSE(load("\"sa\"", e, ee));
    INFO(ee);
    CHECK(ee.find(path + ":4:13: error: unknown multigrid 'sa'") != std::string::npos);
    std::remove(path.c_str());
}
