// Mesh sequences: frames found by the `#` rule, positions linear in time within a frame and
// held outside the range, and clear errors naming the file for a missing frame or a changed
// topology.
#include "solver/mesh/mesh_sequence.h"

#include "solver/contact/ccd.h"

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

namespace {
// A cylinder (radius 0.15 m, y 0.8–1.6 m; 24 × 17 vertices, quads split both ways) skinned to two
// bones by linear-blend skinning: the upper bone turns about z through (0, 1.2, 0) by 40° over
// frames 0–24, the weights blending over y 1.1–1.3 (smoothstep), so the skin bends and shears at
// the joint as a character's does.
MeshSequence skinnedCylinder() {
    const int na = 24, nr = 17;
    const double R = 0.15;
    std::vector<std::array<int, 3>> tris;
    for (int j = 0; j + 1 < nr; ++j)
        for (int i = 0; i < na; ++i) {
            const int a = j * na + i, b = j * na + (i + 1) % na, c = (j + 1) * na + (i + 1) % na,
                      d = (j + 1) * na + i;
            if ((i + j) % 2) {
                tris.push_back({a, b, c});
                tris.push_back({a, c, d});
            } else {
                tris.push_back({a, b, d});
                tris.push_back({b, c, d});
            }
        }
    std::vector<std::vector<double>> frames;
    for (int f = 0; f <= 24; ++f) {
        const double th = (40.0 * M_PI / 180.0) * f / 24.0;
        std::vector<double> x;
        for (int j = 0; j < nr; ++j)
            for (int i = 0; i < na; ++i) {
                const double y = 0.8 + 0.05 * j, ang = 2.0 * M_PI * i / na;
                const Vec3 p(R * std::cos(ang), y, R * std::sin(ang));
                const double u = std::clamp((y - 1.1) / 0.2, 0.0, 1.0),
                             wb = u * u * (3.0 - 2.0 * u);
                const Vec3 q = p - Vec3(0, 1.2, 0);
                const Vec3 turned = Vec3(std::cos(th) * q.x() - std::sin(th) * q.y(),
                                         std::sin(th) * q.x() + std::cos(th) * q.y(), q.z()) +
                                    Vec3(0, 1.2, 0);
                const Vec3 out = (1.0 - wb) * p + wb * turned;
                x.insert(x.end(), {out.x(), out.y(), out.z()});
            }
        frames.push_back(std::move(x));
    }
    return MeshSequence(std::move(tris), std::move(frames), 0, 24.0);
}
} // namespace

TEST_CASE("surface binding: a collar on a skinned cylinder rides the skin", "[mesh][binding]") {
    // A collar of 48 points (twice the mesh's angular resolution: on faces, edges and creases)
    // at height h above the skin, across the joint (y = 1.2) and above it. Each collar edge's
    // length ratio r_h (bound, over frames 0–24) against r_0, the same edge of the ring on the skin
    // itself: an offset surface at height h over a surface of curvature radius ≥ R changes a
    // length by at most about h/R, so |r_h − r_0| ≤ 2h/R. The rigid offset in each triangle's own
    // frame (computed here; what gale bound with before) breaks that at the joint's creases.
    const MeshSequence seq = skinnedCylinder();
    const double R = 0.15;
    const int nc = 48;
    auto ring = [&](double h, double yc, std::vector<Vec3>& c, std::vector<SurfaceBinding>& b) {
        c.clear();
        b.clear();
        for (int i = 0; i < nc; ++i) {
            const double ang = 2 * M_PI * (i + 0.3) / nc;
            c.push_back(Vec3((R + h) * std::cos(ang), yc, (R + h) * std::sin(ang)));
            b.push_back(bindToSurface(seq, c.back(), 0.0));
        }
    };
    for (double yc : {1.0, 1.2, 1.25}) {
        std::vector<Vec3> c0, c;
        std::vector<SurfaceBinding> b0, b;
        ring(0.0, yc, c0, b0);
        for (double h : {0.005, 0.02}) {
            ring(h, yc, c, b);
            double worst = 0.0, rigidWorst = 0.0;
            for (int i = 0; i < nc; ++i) {
                CHECK((boundPosition(seq, b[i], 0.0) - c[i]).norm() < 1e-9); // exact at bind
                CHECK_FALSE(b[i].alongFace);
            }
            // The rigid offset in the closest triangle's frame (ê₁, n̂ × ê₁, n̂).
            auto frameOf = [&](int tri, double t) {
                const auto& tr = seq.triangles()[tri];
                const Vec3 a = seq.vertexAt(tr[0], t), e = seq.vertexAt(tr[1], t) - a,
                           f = seq.vertexAt(tr[2], t) - a;
                Mat3 F;
                F.col(0) = e.normalized();
                F.col(2) = e.cross(f).normalized();
                F.col(1) = F.col(2).cross(F.col(0));
                return F;
            };
            std::vector<std::array<double, 3>> wq(nc);
            std::vector<Vec3> local(nc);
            auto closestPoint = [&](int i, double t) {
                const auto& tr = seq.triangles()[b[i].triangle];
                return Vec3(wq[i][0] * seq.vertexAt(tr[0], t) + wq[i][1] * seq.vertexAt(tr[1], t) +
                            wq[i][2] * seq.vertexAt(tr[2], t));
            };
            for (int i = 0; i < nc; ++i) {
                const auto& tr = seq.triangles()[b[i].triangle];
                gale::solver::contact::pointTriangleDistance2(c[i], seq.vertexAt(tr[0], 0),
                                                              seq.vertexAt(tr[1], 0),
                                                              seq.vertexAt(tr[2], 0), wq[i].data());
                local[i] = frameOf(b[i].triangle, 0).transpose() * (c[i] - closestPoint(i, 0));
            }
            for (int f = 0; f <= 24; ++f) {
                const double t = f / 24.0;
                for (int i = 0; i < nc; ++i) {
                    const int k = (i + 1) % nc;
                    const double r0 =
                        (boundPosition(seq, b0[i], t) - boundPosition(seq, b0[k], t)).norm() /
                        (c0[i] - c0[k]).norm();
                    const double r =
                        (boundPosition(seq, b[i], t) - boundPosition(seq, b[k], t)).norm() /
                        (c[i] - c[k]).norm();
                    const Vec3 pi = closestPoint(i, t) + frameOf(b[i].triangle, t) * local[i];
                    const Vec3 pk = closestPoint(k, t) + frameOf(b[k].triangle, t) * local[k];
                    worst = std::max(worst, std::fabs(r - r0));
                    rigidWorst = std::max(rigidWorst,
                                          std::fabs((pi - pk).norm() / (c[i] - c[k]).norm() - r0));
                }
            }
            INFO("y " << yc << ", h " << h << ": |r_h - r_0| up to " << worst << ", rigid offsets "
                      << rigidWorst << ", bound 2h/R " << 2 * h / R);
            CHECK(worst <= 2.0 * h / R);
            if (yc == 1.2 && h == 0.02) CHECK(rigidWorst > 2.0 * h / R); // the test can fail
        }
    }
}

TEST_CASE("surface binding: continuous across a crease as it folds", "[mesh][binding]") {
    // Two triangles hinged on the edge (0,0,0)-(1,0,0); the second folds up by 90° over a second.
    // A point 1 cm above the hinge's midpoint, nudged 1e-7 m to either side, binds to either
    // triangle; both bound points stay together (within a few times the nudge) while the crease
    // folds, where rigid offsets in the two faces' frames part by about h·θ.
    std::vector<std::vector<double>> frames;
    for (int f = 0; f <= 24; ++f) {
        const double th = 0.5 * M_PI * f / 24.0;
        frames.push_back({0, 0, 0, 1, 0, 0, 0.5, 0, -1, 0.5, std::sin(th), std::cos(th)});
    }
    const MeshSequence seq({{0, 1, 2}, {1, 0, 3}}, frames, 0, 24.0);
    const Vec3 x(0.5, 0.01, 0.0);
    const SurfaceBinding a = bindToSurface(seq, x - Vec3(0, 0, 1e-7), 0.0);
    const SurfaceBinding b = bindToSurface(seq, x + Vec3(0, 0, 1e-7), 0.0);
    REQUIRE(a.triangle != b.triangle);
    for (int f = 0; f <= 24; ++f) {
        const double t = f / 24.0;
        CHECK((boundPosition(seq, a, t) - boundPosition(seq, b, t)).norm() < 1e-6);
    }
    // Halfway folded, the point rides the hinge along the crease's bisector: its height over the
    // hinge stays 1 cm (the vertex normals there are the faces' mean).
    const Vec3 p = boundPosition(seq, a, 0.5);
    CHECK((p - Vec3(0.5, 0.0, 0.0)).norm() == Approx(0.01).epsilon(1e-5));
}
