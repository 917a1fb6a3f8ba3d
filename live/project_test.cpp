// live::Project's colliders at a time, against closed forms: a two-frame mesh sequence (a
// triangle moved 1 m along x between frames 1 and 2 at 24 fps) is at the linear blend of its
// frames between them and held outside (as solver::MeshSequence places it), and a sphere with
// keyframed centre at its keys' linear interpolation; the view box holds the sequence's motion.
#include "live/project.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace fs = std::filesystem;
using gale::live::ColliderShape;
using gale::live::Project;

namespace {

struct Scratch {
    fs::path dir = fs::temp_directory_path() / ("gale_project_" + std::to_string(::getpid()));
    Scratch() {
        fs::remove_all(dir);
        fs::create_directories(dir / "seq");
    }
    ~Scratch() { fs::remove_all(dir); }
    void write(const std::string& name, const std::string& text) const {
        std::ofstream(dir / name) << text;
    }
};

} // namespace

TEST_CASE("project: colliders placed at a time as the solver places them") {
    Scratch s;
    s.write("seq/tri.0001.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    s.write("seq/tri.0002.obj", "v 1 0 0\nv 2 0 0\nv 1 1 0\nf 1 2 3\n");
    s.write("wind.se", "[1, 0, 0]\n");
    s.write("scene.toml", R"([scene]
fps = 24
frames = [1, 4]

[[field]]
name = "w"
expr = "wind.se"

[[cloth]]
name = "c"
grid = { size = [0.2, 0.2], res = [2, 2], origin = [0, 2, 0], axes = "xy" }

[[collider]]
name = "tri"
type = "mesh"
mesh = "seq/tri.#.obj"

[[collider]]
name = "ball"
type = "sphere"
center = { keys = [[0, [0, 0, 0]], [1, [2, 4, 6]]] }
radius = 0.25
)");
    Project p((s.dir / "scene.toml").string());
    REQUIRE(p.load());
    REQUIRE(p.diagnostics().empty());
    const double fps = 24;
    for (double t : {0.0, 1 / fps, 1.25 / fps, 1.5 / fps, 2 / fps, 3 / fps, 0.5}) {
        const std::vector<ColliderShape> c = p.collidersAt(t);
        REQUIRE(c.size() == 2);
        CHECK(c[0].moving);
        REQUIRE(c[0].mesh.points.size() == 3);
        // Frame F at t = F / fps; linear within, held before the first and after the last.
        const double w = std::clamp(t * fps - 1, 0.0, 1.0);
        CHECK(c[0].mesh.points[0][0] == Approx(w).margin(1e-12));
        CHECK(c[0].mesh.points[1][0] == Approx(1 + w).margin(1e-12));
        CHECK(c[0].mesh.points[2][1] == Approx(1).margin(1e-12));
        REQUIRE(c[0].mesh.triangles.size() == 1);
        CHECK(c[1].shape == "sphere");
        CHECK_FALSE(c[1].moving);
        const double k = std::min(t, 1.0); // linear keys by default
        CHECK(c[1].a[0] == Approx(2 * k).margin(1e-9));
        CHECK(c[1].a[2] == Approx(6 * k).margin(1e-9));
        CHECK(c[1].radius == Approx(0.25));
    }
    // The box holds the triangle at its last frame too (x up to 2).
    CHECK(p.box().hi[0] >= 2.0);
    // The sequence's pattern is watched for, its files are not served.
    const auto& files = p.files();
    CHECK(std::find(files.begin(), files.end(), (s.dir / "seq/tri.0001.obj").string()) ==
          files.end());
    const auto& patterns = p.patterns();
    CHECK(std::find(patterns.begin(), patterns.end(),
                    (s.dir / "seq/tri.#.obj").lexically_normal().string()) != patterns.end());
}

TEST_CASE("project: with scene.time_zero, frame F of a sequence is at (F - time_zero) / fps") {
    Scratch s;
    s.write("seq/tri.1001.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    s.write("seq/tri.1002.obj", "v 2 0 0\nv 3 0 0\nv 2 1 0\nf 1 2 3\n");
    s.write("wind.se", "[1, 0, 0]\n");
    s.write("scene.toml", R"([scene]
fps = 24
time_zero = 1001
frames = [1001, 1004]

[[field]]
name = "w"
expr = "wind.se"

[[cloth]]
name = "c"
grid = { size = [0.2, 0.2], res = [2, 2], origin = [0, 2, 0], axes = "xy" }

[[collider]]
name = "tri"
type = "mesh"
mesh = "seq/tri.#.obj"
)");
    Project p((s.dir / "scene.toml").string());
    REQUIRE(p.load());
    CHECK(p.timeZero() == 1001);
    for (double t : {0.0, 0.25 / 24, 0.5 / 24, 1.0 / 24, 2.0 / 24}) {
        const std::vector<ColliderShape> c = p.collidersAt(t);
        REQUIRE(c.size() == 1);
        REQUIRE(c[0].mesh.points.size() == 3);
        const double w = std::clamp(t * 24, 0.0, 1.0); // frame 1001 at 0 s, 1002 at 1/24 s
        CHECK(c[0].mesh.points[0][0] == Approx(2 * w).margin(1e-12));
    }
}
