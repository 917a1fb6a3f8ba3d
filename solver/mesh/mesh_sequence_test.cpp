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

TEST_CASE("mesh sequence: the pre-roll eases from the rest pose to the pose and velocity at the "
          "shot's start, C1 at both ends",
          "[mesh][sequence][preroll]") {
    // One triangle moving at 0.24 m/s along x (0.01 m per frame at 24 fps) from frame 10 on;
    // its rest pose is the same triangle 1 m up.
    const double fps = 24.0;
    std::vector<std::vector<double>> frames;
    for (int k = 0; k < 6; ++k) {
        const double x = 0.01 * k;
        frames.push_back({x, 0, 0, x + 1, 0, 0, x, 1, 0});
    }
    const MeshSequence seq({{0, 1, 2}}, frames, 10, fps);
    std::vector<double> rest = frames[0];
    for (size_t i = 1; i < rest.size(); i += 3) rest[i] += 1.0;
    const double from = 4.0 / fps, to = 10.0 / fps, T = to - from; // six frames of pre-roll
    std::string error;
    auto eased = seq.eased(rest, from, to, error);
    INFO(error);
    REQUIRE(eased);
    CHECK(eased->moving());
    CHECK(eased->frameCount() == seq.frameCount());
    std::vector<double> p, q;
    // Held at rest before `from`, exactly the rest pose there.
    eased->positionsAt(0.0, p);
    CHECK(p == rest);
    eased->positionsAt(from, p);
    CHECK(p == rest);
    // At and after `to`: the sequence itself.
    for (double t : {to, to + 0.5 / fps, to + 3.25 / fps}) {
        eased->positionsAt(t, p);
        seq.positionsAt(t, q);
        for (size_t i = 0; i < p.size(); ++i) CHECK(p[i] == Approx(q[i]).margin(1e-15));
    }
    // Halfway: h = 1/2, g = −1/8, so x = r + (p − r)/2 − T·v/8 (closed form).
    eased->positionsAt(from + 0.5 * T, p);
    const double v = 0.01 * fps;
    CHECK(p[0] == Approx(0.0 - T * v / 8.0));
    CHECK(p[1] == Approx(1.0 - 0.5));
    CHECK(p[2] == Approx(0.0));
    // Velocities (central differences; the acceleration's jump at the ends costs O(d)) continuous:
    // 0 leaving the rest pose, v arriving at `to` — against (p − r)/T = 4 m/s a jump would be O(1).
    const double d = 1e-6;
    auto velocity = [&](int coord, double t) {
        return (eased->vertexAt(0, t + d)[coord] - eased->vertexAt(0, t - d)[coord]) / (2.0 * d);
    };
    CHECK(velocity(0, from) == Approx(0.0).margin(1e-4));
    CHECK(velocity(1, from) == Approx(0.0).margin(1e-4));
    CHECK(velocity(0, to) == Approx(v).margin(1e-4));
    CHECK(velocity(1, to) == Approx(0.0).margin(1e-4));
    // vertexAt and positionsAt agree inside the pre-roll.
    eased->positionsAt(from + 0.3 * T, p);
    for (int vtx = 0; vtx < 3; ++vtx)
        for (int c = 0; c < 3; ++c)
            CHECK(eased->vertexAt(vtx, from + 0.3 * T)[c] == Approx(p[3 * vtx + c]));
    // The original is untouched.
    seq.positionsAt(from, p);
    CHECK(p == frames[0]);
    // A rest pose of another size, or an empty window, is refused.
    CHECK_FALSE(seq.eased({0, 0, 0}, from, to, error));
    CHECK(error.find("vertices") != std::string::npos);
    CHECK_FALSE(seq.eased(rest, to, to, error));
}
