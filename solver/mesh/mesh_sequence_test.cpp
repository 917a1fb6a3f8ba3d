// Mesh sequences: frames found by the `#` rule, positions linear in time within a frame and
// held outside the range, and clear errors naming the file for a missing frame or a changed
// topology.
#include "solver/mesh/mesh_sequence.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace gale::solver;

namespace {
struct TempDir {
    std::filesystem::path path;
    TempDir() {
        char tmpl[] = "/tmp/gale_meshseq_XXXXXX";
        path = mkdtemp(tmpl);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    void write(const std::string& name, const std::string& text) const {
        std::ofstream(path / name) << text;
    }
};
std::string tri(double z) {
    return "v 0 0 " + std::to_string(z) + "\nv 1 0 " + std::to_string(z) + "\nv 0 1 " +
           std::to_string(z) + "\nf 1 2 3\n";
}
} // namespace

TEST_CASE("mesh sequence: frames, interpolation in time, held outside", "[mesh][sequence]") {
    TempDir d;
    for (int f = 1; f <= 3; ++f) d.write("body.000" + std::to_string(f) + ".obj", tri(0.1 * f));
    std::string error;
    auto seq = MeshSequence::load((d.path / "body.#.obj").string(), 24.0, error);
    INFO(error);
    REQUIRE(seq);
    CHECK(seq->frameCount() == 3);
    CHECK(seq->firstFrame() == 1);
    CHECK(seq->moving());
    std::vector<double> p;
    seq->positionsAt(1.5 / 24.0, p);
    CHECK(p[2] == Approx(0.15));
    seq->positionsAt(2.25 / 24.0, p);
    CHECK(p[2] == Approx(0.225));
    seq->positionsAt(0.0, p); // before frame 1: frame 1
    CHECK(p[2] == Approx(0.1));
    seq->positionsAt(10.0, p); // after the last: the last
    CHECK(p[2] == Approx(0.3));
    // A plain file: one static frame.
    auto one = MeshSequence::load((d.path / "body.0002.obj").string(), 24.0, error);
    REQUIRE(one);
    CHECK_FALSE(one->moving());
}

TEST_CASE("mesh sequence: a missing frame or a changed topology names the file",
          "[mesh][sequence]") {
    TempDir d;
    d.write("gap.0001.obj", tri(0));
    d.write("gap.0002.obj", tri(0));
    d.write("gap.0004.obj", tri(0));
    std::string error;
    CHECK_FALSE(MeshSequence::load((d.path / "gap.#.obj").string(), 24.0, error));
    CHECK(error.find("gap.0003.obj") != std::string::npos);
    CHECK(error.find("has no frame 3") != std::string::npos);
    d.write("grow.0001.obj", tri(0));
    d.write("grow.0002.obj", tri(0) + "v 1 1 0\nf 2 4 3\n");
    CHECK_FALSE(MeshSequence::load((d.path / "grow.#.obj").string(), 24.0, error));
    CHECK(error.find("grow.0002.obj") != std::string::npos);
    CHECK(error.find("4 vertices and 2 triangles") != std::string::npos);
    d.write("faces.0001.obj", tri(0));
    d.write("faces.0002.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 3 2\n");
    CHECK_FALSE(MeshSequence::load((d.path / "faces.#.obj").string(), 24.0, error));
    CHECK(error.find("with other faces") != std::string::npos);
    CHECK_FALSE(MeshSequence::load((d.path / "none.#.obj").string(), 24.0, error));
    CHECK(error.find("none.#.obj") != std::string::npos);
}
