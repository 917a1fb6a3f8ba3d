// Scene files: the solver's sections read with their units and defaults, unknown keys and bad
// values reported at file:line:col, --set overrides by dotted path, painted maps from
// expressions, pins by box, and bodies built from grids and strand grids.
#include "scene/load.h"
#include "scene/sim_scene.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <random>
#include <fstream>
#include <unistd.h>

using namespace gale::solver;
using namespace gale::scene;

namespace {

struct TempDir {
    std::filesystem::path path;
    TempDir() {
        char tmpl[] = "/tmp/gale_solver_scene_XXXXXX";
        path = mkdtemp(tmpl);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path / name) << text;
        return (path / name).string();
    }
};

struct Loaded {
    bool ok = false;
    SimScene scene;
    std::vector<gale::scene::SceneError> errors;
    std::string all() const {
        std::string s;
        for (const auto& e : errors) s += e.render() + "\n";
        return s;
    }
};

Loaded load(const TempDir& dir, const std::string& text, std::vector<std::string> sets = {}) {
    Loaded l;
    l.ok = loadSimScene(dir.write("scene.toml", text), l.scene, l.errors, sets);
    return l;
}

const char* kCape = R"(
[scene]
fps = 24
frames = [1, 12]
substeps = 2

[[cloth]]
name = "cape"
grid = { size = [1.0, 1.5], res = [8, 12], origin = [-0.5, 0.0, 0.0] }
density = 0.05
stretch = 1500.0
shear = 150.0
bend = 0.002
damping = 0.005
lift = { source = "0.2 + 0.2 * $v" }
drag = { keys = [[0, 1.0], [1, 1.5]] }
aero_model = "smooth-lift"
aero_jacobian = "paper"
pins = { box = [-1, 1.49, -1, 1, 1.6, 1], translate = { keys = [[0, [0, 0, 0]], [1, [0, 0.5, 0]]] } }

[[hair]]
name = "tuft"
grid = { size = [0.1, 0.1], count = [2, 3], length = 0.2, segments = 5, origin = [0, 2, 0] }
radius = 1e-4
drag_normal = 1.0

[[collider]]
name = "ball"
type = "sphere"
center = [0, 0.5, 0.3]
radius = 0.2
friction = 0.4

[solver]
max_halvings = 4
)";

} // namespace

TEST_CASE("scene: the solver's sections with their values", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, kCape);
    INFO(l.all());
    REQUIRE(l.ok);
    REQUIRE(l.scene.cloths.size() == 1);
    const ClothSpec& c = l.scene.cloths[0];
    CHECK(c.name == "cape");
    CHECK(c.gridRes[0] == 8);
    CHECK(c.gridRes[1] == 12);
    CHECK(c.material.density == 0.05);
    CHECK(c.material.stretch.scalarAt(0) == 1500.0);
    CHECK(c.material.aeroModel == AeroModel::SmoothLift);
    CHECK(c.step.aeroJacobian == AeroJacobian::Paper);
    CHECK(c.drag.value.scalarAt(0.5) == Approx(1.25));
    CHECK(c.hasPins);
    CHECK(l.scene.hairs.size() == 1);
    CHECK(l.scene.hairs[0].material.radius == 1e-4);
    CHECK(l.scene.hairs[0].step.linearSolver == LinearSolverKind::Direct);
    REQUIRE(l.scene.colliders.size() == 1);
    CHECK(l.scene.colliders[0].shape == ColliderShape::Sphere);
    CHECK(l.scene.colliders[0].friction == 0.4);
    CHECK(l.scene.solver.maxHalvings == 4);
    CHECK(l.scene.wind.settings.substeps == 2);

    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<gale::scene::SceneError> errors;
    std::vector<std::string> warnings;
    REQUIRE(buildBodies(l.scene, bodies, errors, warnings));
    REQUIRE(bodies.size() == 2);
    const Cloth& cloth = dynamic_cast<const Cloth&>(*bodies[0]);
    CHECK(cloth.vertexCount() == 96);
    CHECK(cloth.pinnedVertices().size() == 8); // the top row
    // The painted lift: 0.2 + 0.2 v, v = j / (ny − 1).
    REQUIRE(cloth.material().lift.map.size() == 96);
    CHECK(cloth.material().lift.map[0] == Approx(0.2));
    CHECK(cloth.material().lift.map[95] == Approx(0.4));
    CHECK(bodies[1]->vertexCount() == 6 * 6);
    CHECK(bodies[1]->pinnedVertices().size() == 6);
    // Pins follow their keyframed translation.
    CHECK(cloth.pinTarget(0, 1.0).y() == Approx(1.5 + 0.5));
    // OBJ output: vertices then faces / lines.
    const std::string obj = bodyObjText(*bodies[1]);
    CHECK(obj.find("\nl 1 2 3 4 5 6\n") != std::string::npos);
    CHECK(bodyPointSet(*bodies[0]).faces.size() == cloth.mesh().triangles.size());
    // Vertex lines print exactly as printf's "v %.9g %.9g %.9g" (the bytes older runs wrote):
    // signs, zeros, subnormals, exponents, huge values and rounding at the 9th digit.
    Body& hair = *bodies[1];
    const double special[] = {0.0, -0.0, 1.0, -1.5, 1e-300, 4.9e-324, 1.23456789012e-7, 123456789.5,
                              -9.87654321e+22, 0.1, 2.0 / 3.0, 1e9, 999999999.5, 1.797e308};
    VecX x = hair.positions();
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> mant(-10.0, 10.0);
    std::uniform_int_distribution<int> expo(-30, 30);
    for (long i = 0; i < x.size(); ++i)
        x[i] = i < static_cast<long>(std::size(special)) ? special[i] : mant(rng) * std::pow(10.0, expo(rng));
    hair.setPositions(x);
    const std::string text = bodyObjText(hair);
    std::string expected;
    char buf[128];
    for (size_t i = 0; i < hair.vertexCount(); ++i) {
        std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        expected += buf;
    }
    CHECK(text.compare(text.find('\n') + 1, expected.size(), expected) == 0);
}

TEST_CASE("scene: --set overrides the solver's keys by dotted path", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, kCape, {"cloth.cape.drag=0.8", "collider.ball.radius=0.35", "cloth.0.grid.res=[4,5]",
                                 "solver.max_halvings=2", "hair.tuft.radius=2e-4", "scene.fps=30"});
    INFO(l.all());
    REQUIRE(l.ok);
    CHECK(l.scene.cloths[0].drag.value.scalarAt(0) == 0.8);
    CHECK(l.scene.cloths[0].gridRes[0] == 4);
    CHECK(l.scene.colliders[0].radius == 0.35);
    CHECK(l.scene.solver.maxHalvings == 2);
    CHECK(l.scene.hairs[0].material.radius == 2e-4);
    CHECK(l.scene.wind.settings.fps == 30);

    // Each aero_jacobian by its name; without the key, the default (bounded).
    for (const AeroJacobian j :
         {AeroJacobian::Bounded, AeroJacobian::Projected, AeroJacobian::Paper}) {
        Loaded named = load(
            dir, kCape, {std::string("cloth.cape.aero_jacobian=\"") + aeroJacobianName(j) + "\""});
        REQUIRE(named.ok);
        CHECK(named.scene.cloths[0].step.aeroJacobian == j);
    }
    CHECK(ClothSpec{}.step.aeroJacobian == AeroJacobian::Bounded);

    Loaded bad = load(dir, kCape, {"cloth.cloak.drag=0.8"});
    CHECK_FALSE(bad.ok);
    CHECK(bad.all().find("--set cloth.cloak.drag=0.8: error: the scene has no [[cloth]] named 'cloak'") != std::string::npos);
    Loaded badValue = load(dir, kCape, {"cloth.cape.density=-1"});
    CHECK_FALSE(badValue.ok);
    CHECK(badValue.all().find("density") != std::string::npos);
}

TEST_CASE("scene: unknown keys and bad values are errors at file:line:col", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, R"([[cloth]]
name = "c"
grid = { size = [1, 1], res = [4, 4] }
dragg = 1.0
stretch = "stiff"
aero_model = "frozn"
pins = { vertices = [0, -3] }

[[collider]]
type = "sphere"
center = [0, 0, 0]
point = [0, 0, 0]

[solver]
max_halvings = 2.5
)");
    CHECK_FALSE(l.ok);
    const std::string all = l.all();
    INFO(all);
    const std::string path = (dir.path / "scene.toml").string();
    CHECK(all.find(path + ":4:1: error: unknown key 'dragg' in [[cloth]]") != std::string::npos);
    CHECK(all.find("did you mean 'drag'?") != std::string::npos);
    CHECK(all.find(path + ":5:11: error: [[cloth]] 'c': stretch (N/m) must be a number") != std::string::npos);
    CHECK(all.find(path + ":6:14: error: unknown aero_model 'frozn'") != std::string::npos);
    CHECK(all.find(path + ":7:") != std::string::npos);
    CHECK(all.find("'point' does not apply to a sphere collider") != std::string::npos);
    CHECK(all.find("needs 'radius'") != std::string::npos);
    CHECK(all.find("max_halvings must be a whole number") != std::string::npos);
}

// fuzz_scene (UBSan): a whole number written as a huge float, 41e300, was converted to an
// integer as is (undefined behaviour). Now an error at its line and column.
TEST_CASE("scene: a whole number too large for an integer is an error", "[scene][fuzz]") {
    TempDir dir;
    Loaded l = load(dir, R"([[hair]]
name = "tuft"
grid = { size = [0.2, 0.2], count = [4, 41e300], length = 0.4, segments = 1e20 }
)");
    CHECK_FALSE(l.ok);
    const std::string all = l.all();
    INFO(all);
    const std::string path = (dir.path / "scene.toml").string();
    CHECK(all.find(path + ":3:41: error: [[hair]] 'tuft': grid count must be a whole number "
                          "below 1e15, not 4.1e+301") != std::string::npos);
    CHECK(all.find(path + ":3:75: error: [[hair]] 'tuft': grid segments must be a whole number "
                          "below 1e15, not 1e+20") != std::string::npos);
}

TEST_CASE("scene: the response to trouble ([solver] retry keys) is read and checked", "[scene]") {
    TempDir dir;
    Loaded ok = load(dir, R"([[cloth]]
name = "c"
grid = { size = [1, 1], res = [4, 4] }

[solver]
retry_newton = 2
retry_cg_tolerance = 0.05
retry_keep_coarse = true
retry_repeat = true
grow_back = true
retry_strain_limit = true
rotation_projection = true
)");
    INFO(ok.all());
    REQUIRE(ok.ok);
    CHECK(ok.scene.solver.rotationProjection == RotationProjection::Always);
    CHECK(ok.scene.solver.retryNewton == 2);
    CHECK(ok.scene.solver.retryCgTolerance == 0.05);
    CHECK(ok.scene.solver.retryKeepCoarse);
    CHECK(ok.scene.solver.retryRepeat);
    CHECK(ok.scene.solver.growBack);
    CHECK(ok.scene.solver.strainLimit);
    const WorldSettings ws = worldSettings(ok.scene, 1);
    CHECK(ws.retryNewtonIterations == 2);
    CHECK(ws.retryCgTolerance == 0.05);
    CHECK(ws.retryRepeat);
    CHECK(ws.growBack);
    CHECK(ws.strainLimitRetry);

    Loaded bad = load(dir, R"([[cloth]]
name = "c"
grid = { size = [1, 1], res = [4, 4] }

[solver]
retry_newton = -1
retry_cg_tolerance = 1.5
grow_back = "yes"
)");
    CHECK_FALSE(bad.ok);
    const std::string all = bad.all();
    INFO(all);
    const std::string path = (dir.path / "scene.toml").string();
    CHECK(all.find(path + ":6:16: error: [solver] retry_newton must be at least 0") !=
          std::string::npos);
    CHECK(all.find(path + ":7:22: error: [solver] retry_cg_tolerance must be below 1") !=
          std::string::npos);
    CHECK(all.find(path + ":8:13: error: [solver] grow_back must be true or false") !=
          std::string::npos);
}

TEST_CASE("scene: [solver] stretch_limit is 0 (none, the default) or at least 1", "[scene]") {
    TempDir dir;
    const auto with = [&](const std::string& value) {
        return load(dir, "[[cloth]]\nname = \"c\"\ngrid = { size = [1, 1], res = [4, 4] }\n" +
                             (value.empty() ? "" : "[solver]\nstretch_limit = " + value + "\n"));
    };
    const Loaded none = with("");
    REQUIRE(none.ok);
    CHECK(none.scene.solver.stretchLimit == 0.0);
    const Loaded limit = with("1.5");
    REQUIRE(limit.ok);
    CHECK(limit.scene.solver.stretchLimit == 1.5);
    const Loaded bad = with("0.5");
    CHECK_FALSE(bad.ok);
    const std::string path = (dir.path / "scene.toml").string();
    CHECK(bad.all().find(path + ":5:17: error: [solver] stretch_limit must be 0 (no limit) or at "
                                "least 1") != std::string::npos);
}

TEST_CASE("scene: [solver] rotation_projection is off, contact or always (the default)",
          "[scene]") {
    TempDir dir;
    const auto with = [&](const std::string& value) {
        return load(dir,
                    "[[cloth]]\nname = \"c\"\ngrid = { size = [1, 1], res = [4, 4] }\n" +
                        (value.empty() ? "" : "[solver]\nrotation_projection = " + value + "\n"));
    };
    const auto mode = [&](const std::string& value) {
        const Loaded l = with(value);
        INFO(value << ": " << l.all());
        REQUIRE(l.ok);
        return l.scene.solver.rotationProjection;
    };
    CHECK(mode("") == RotationProjection::Always);
    CHECK(mode("\"contact\"") == RotationProjection::Contact);
    CHECK(mode("\"off\"") == RotationProjection::Off);
    CHECK(mode("false") == RotationProjection::Off);
    CHECK(mode("\"always\"") == RotationProjection::Always);
    CHECK(mode("true") == RotationProjection::Always);
    const std::string path = (dir.path / "scene.toml").string();
    const Loaded typo = with("\"contacts\"");
    CHECK_FALSE(typo.ok);
    CHECK(typo.all().find(path + ":5:23: error: unknown [solver] rotation_projection 'contacts' "
                                 "(use \"off\", \"contact\", \"always\")") != std::string::npos);
    CHECK(typo.all().find("did you mean 'contact'") != std::string::npos);
    const Loaded number = with("1");
    CHECK_FALSE(number.ok);
    CHECK(number.all().find(path + ":5:23: error: [solver] rotation_projection must be \"off\", "
                                   "\"contact\" or \"always\" (or false, true), not ") !=
          std::string::npos);
}

TEST_CASE("scene: problems found while building are reported where the scene names them", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, R"([[cloth]]
name = "c"
mesh = "missing.obj"

[[cloth]]
name = "d"
grid = { size = [1, 1], res = [4, 4] }
lift = { map = "paint" }
drag = { source = "1 + $nope" }
)");
    REQUIRE(l.ok);
    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<gale::scene::SceneError> errors;
    std::vector<std::string> warnings;
    CHECK_FALSE(buildBodies(l.scene, bodies, errors, warnings));
    std::string all;
    for (const auto& e : errors) all += e.render() + "\n";
    INFO(all);
    CHECK(all.find("missing.obj") != std::string::npos);
    CHECK(all.find(":8:8: error: [[cloth]] 'd' lift: the geometry has no vertex property 'paint'") != std::string::npos);
    CHECK(all.find("the map expression has errors") != std::string::npos);
}

TEST_CASE("scene: meshes and painted maps from a PLY file", "[scene]") {
    TempDir dir;
    dir.write("sheet.ply", R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
property float lift
property float pin
element face 2
property list uchar int vertex_indices
end_header
0 0 0 0.1 0
1 0 0 0.2 0
1 1 0 0.3 1
0 1 0 0.4 1
3 0 1 2
3 0 2 3
)");
    Loaded l = load(dir, R"([[cloth]]
name = "sheet"
mesh = "sheet.ply"
lift = { map = "lift", scale = 2.0 }
pins = { map = "pin" }
)");
    INFO(l.all());
    REQUIRE(l.ok);
    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<gale::scene::SceneError> errors;
    std::vector<std::string> warnings;
    REQUIRE(buildBodies(l.scene, bodies, errors, warnings));
    const Cloth& c = dynamic_cast<const Cloth&>(*bodies[0]);
    CHECK(c.material().lift.map[3] == Approx(0.4));
    CHECK(c.material().lift.at(0) == 2.0);
    CHECK(c.pinnedVertices() == std::vector<int>{2, 3});
    CHECK(c.masses().sum() == Approx(0.1)); // default density 0.1 kg/m² × 1 m²
}

TEST_CASE("scene: keyframed body values go through the one keyframe parser", "[scene][keyframes]") {
    TempDir dir;
    const std::string grid = "[[cloth]]\nname = \"c\"\ngrid = { size = [1, 1], res = [4, 4] }\n";
    Loaded ok = load(dir, grid + "drag = { keys = [[0, 1.0], [1, 0.5]], interp = \"smooth\" }\n");
    INFO(ok.all());
    REQUIRE(ok.ok);
    CHECK(ok.scene.cloths[0].drag.value.isKeyed());
    // A negative key (the bodies' values are at least 0) and an unknown interpolation, each at
    // its own line and column, the latter with "did you mean"; then two keys at one time.
    Loaded bad = load(dir, grid + "drag = { keys = [[0, -1.0], [1, 2.0]], interp = \"smoth\" }\n");
    CHECK_FALSE(bad.ok);
    const std::string all = bad.all();
    INFO(all);
    CHECK(all.find(":4:22: error: [[cloth]] 'c': drag: a key's value must be at least 0, not -1") !=
          std::string::npos);
    CHECK(all.find(":4:49: error: unknown interpolation 'smoth'") != std::string::npos);
    CHECK(all.find("did you mean 'smooth'?") != std::string::npos);
    Loaded twice = load(dir, grid + "drag = { keys = [[0, 1.0], [0, 2.0]] }\n");
    CHECK_FALSE(twice.ok);
    CHECK(twice.all().find(":4:28: error: [[cloth]] 'c': drag: two keys at time 0") !=
          std::string::npos);
}

TEST_CASE("scene: pins rotate about a pivot, with keyed degrees", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, R"(
[scene]
fps = 24
frames = [1, 2]

[[cloth]]
name = "flag"
grid = { size = [1.0, 1.0], res = [4, 4] }
pins = { box = [-0.1, -0.1, -1, 0.1, 1.1, 1], rotate = { pivot = [0, 0, 0], axis = [0, 1, 0], angle = { keys = [[0, 0], [1, 90]] } } }
)");
    INFO(l.all());
    REQUIRE(l.ok);
    const PinSpec& p = l.scene.cloths[0].pins;
    CHECK(p.rotate.active);
    CHECK(p.rotate.axis == Vec3::UnitY());
    CHECK(p.rotate.angle.scalarAt(0.5) == Approx(45.0));
    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<gale::scene::SceneError> errors;
    std::vector<std::string> warnings;
    REQUIRE(buildBodies(l.scene, bodies, errors, warnings));
    // Vertex 4 is at (0, 1/3, 0) on the pivot's axis: it does not move; none is off it here, so
    // check a point off the axis through the rigid motion instead.
    REQUIRE(bodies[0]->pinnedVertices().size() == 4);
    CHECK((bodies[0]->pinTarget(1, 1.0) - bodies[0]->pinTarget(1, 0.0)).norm() < 1e-12);

    Loaded bad = load(dir, R"(
[[cloth]]
grid = { size = [1.0, 1.0], res = [4, 4] }
pins = { vertices = [0], rotate = { axis = [0, 0, 0] } }
)");
    CHECK_FALSE(bad.ok);
    CHECK(bad.all().find("rotate axis must not be zero") != std::string::npos);
    CHECK(bad.all().find("rotate needs angle") != std::string::npos);
    CHECK(bad.all().find(":4:") != std::string::npos);
}

TEST_CASE("scene: rest_shape and rest_mesh", "[scene][rest]") {
    TempDir dir;
    // A sheet folded 90° along its middle edge: start pose flat, rest pose folded.
    dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
    dir.write("fold.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 1\nf 1 2 3\nf 2 4 3\n");
    dir.write("fewer.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    Loaded l = load(dir, R"(
[[cloth]]
name = "a"
mesh = "flat.obj"
rest_mesh = "fold.obj"

[[cloth]]
name = "b"
mesh = "fold.obj"
rest_shape = "flat"
)");
    INFO(l.all());
    REQUIRE(l.ok);
    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<gale::scene::SceneError> errors;
    std::vector<std::string> warnings;
    REQUIRE(buildBodies(l.scene, bodies, errors, warnings));
    // a: starts flat (its positions), rest folded: bending energy > 0 at the start; the rest
    // lengths are the fold's, so the diagonal 2-3 (√2 in both) is unstretched.
    CHECK(bodies[0]->positions()[11] == 0.0);
    CHECK(bodies[0]->elasticEnergy(0.0) > 0.0);
    // b: a folded mesh with a flat rest costs the fold's energy; with the default ("mesh") none.
    CHECK(bodies[1]->elasticEnergy(0.0) > 0.0);
    Loaded d = load(dir, "[[cloth]]\nmesh = \"fold.obj\"\n");
    REQUIRE(d.ok);
    bodies.clear();
    REQUIRE(buildBodies(d.scene, bodies, errors, warnings));
    CHECK(bodies[0]->elasticEnergy(0.0) == Approx(0.0).margin(1e-15));

    Loaded bad = load(dir, "[[cloth]]\nmesh = \"flat.obj\"\nrest_mesh = \"fewer.obj\"\n");
    REQUIRE(bad.ok);
    bodies.clear();
    errors.clear();
    CHECK_FALSE(buildBodies(bad.scene, bodies, errors, warnings));
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].render().find("fewer.obj") != std::string::npos);
    CHECK(errors[0].render().find("3 vertices and 1 triangles against 4 and 2") != std::string::npos);
    CHECK(errors[0].line == 3);
    Loaded grid = load(dir, "[[cloth]]\ngrid = { size = [1, 1], res = [3, 3] }\nrest_mesh = \"fold.obj\"\n");
    CHECK_FALSE(grid.ok);
    CHECK(grid.all().find("rest_mesh needs mesh") != std::string::npos);
}

TEST_CASE("scene: moving mesh colliders and attachments from a '#' sequence", "[scene][attach]") {
    TempDir dir;
    // A unit square plate in y = 0 moving up 0.1 m per frame, frames 1..3.
    for (int f = 1; f <= 3; ++f) {
        const std::string y = std::to_string(0.1 * (f - 1));
        dir.write("plate.000" + std::to_string(f) + ".obj",
                  "v -1 " + y + " -1\nv 1 " + y + " -1\nv 1 " + y + " 1\nv -1 " + y + " 1\nf 1 2 3\nf 1 3 4\n");
    }
    Loaded l = load(dir, R"(
[scene]
fps = 10
frames = [1, 3]

[[cloth]]
name = "sheet"
grid = { size = [0.5, 0.5], res = [3, 3], origin = [-0.25, 0.01, -0.25], axes = "xz" }
attach = { mesh = "plate.#.obj", box = [-1, -1, -1, 0, 1, 1] }

[[hair]]
name = "tuft"
grid = { size = [0.1, 0.1], count = [2, 2], length = 0.1, segments = 2, origin = [0, 0.002, 0], direction = [0, 1, 0] }
attach = { mesh = "plate.#.obj" }

[[collider]]
name = "plate"
type = "mesh"
mesh = "plate.#.obj"
)");
    INFO(l.all());
    REQUIRE(l.ok);
    REQUIRE(l.scene.colliders.size() == 1);
    CHECK(l.scene.colliders[0].moving);
    CHECK(!l.scene.colliders[0].mesh);
    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<gale::scene::SceneError> errors;
    std::vector<std::string> warnings;
    REQUIRE(buildBodies(l.scene, bodies, errors, warnings));
    // Cloth: the 6 vertices with x ≤ 0, 1 cm above the plate, following it up (frame 3 at t = 0.3).
    REQUIRE(bodies[0]->pinnedVertices().size() == 6);
    for (size_t k = 0; k < 6; ++k) {
        const Vec3 p0 = bodies[0]->pinTarget(k, 0.1), p1 = bodies[0]->pinTarget(k, 0.3);
        CHECK(p0.y() == Approx(0.01));
        CHECK(p1.y() == Approx(0.21));
        CHECK(bodies[0]->pinVelocity(k, 0.15).y() == Approx(1.0)); // 0.1 m per frame at 10 fps
    }
    // Hair: all four roots attached.
    REQUIRE(bodies[1]->pinnedVertices().size() == 4);
    CHECK(bodies[1]->pinTarget(0, 0.3).y() == Approx(0.202));

    Loaded bad = load(dir, R"(
[[cloth]]
grid = { size = [0.5, 0.5], res = [3, 3] }
attach = { mesh = "plate.#.obj", translate = [0, 1, 0] }
)");
    CHECK_FALSE(bad.ok);
    CHECK(bad.all().find("translate") != std::string::npos);
    CHECK(bad.all().find("needs vertices") != std::string::npos);
    Loaded missing = load(dir, "[[collider]]\ntype = \"mesh\"\nmesh = \"nothing.#.obj\"\n");
    CHECK_FALSE(missing.ok);
    CHECK(missing.all().find("nothing.#.obj") != std::string::npos);
}
