// Tests of the geometry volumes against closed forms: the SDF of a triangulated sphere and box
// within one voxel of the analytic distance, unit gradients along the analytic normal, the wind
// shadow's bounds and monotonicity behind a sphere, closest points on triangles, mesh reading
// (polygons fanned, errors) and the cache's once-per-key rule.
#include "geometry/cache.h"
#include "geometry/geometry.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>
#include <unistd.h>

using namespace gale::geometry;
using namespace gale::io;

namespace {

using gale::io::test::TempDir;

void writeText(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

double smooth(double lo, double hi, double x) {
    if (x <= lo) return 0.0;
    if (x >= hi) return 1.0;
    const double u = (x - lo) / (hi - lo);
    return u * u * (3.0 - 2.0 * u);
}

std::shared_ptr<const SdfVolume> buildSdf(const TriangleMesh& mesh, double voxel, int band = 0) {
    std::shared_ptr<const SdfVolume> sdf;
    SdfOptions o;
    o.voxel = voxel;
    o.bandVoxels = band;
    IoError e = SdfVolume::build(mesh, o, sdf, "test");
    INFO(e.render());
    REQUIRE_FALSE(e);
    return sdf;
}

double analyticBox(const double* p, const double* lo, const double* hi, double* grad) {
    double q[3], outside2 = 0.0, inside = -1e9;
    int axis = 0;
    for (int a = 0; a < 3; ++a) {
        const double c = 0.5 * (lo[a] + hi[a]), h = 0.5 * (hi[a] - lo[a]);
        q[a] = std::abs(p[a] - c) - h;
        outside2 += std::max(q[a], 0.0) * std::max(q[a], 0.0);
        if (q[a] > inside) {
            inside = q[a];
            axis = a;
        }
    }
    if (grad) {
        for (int a = 0; a < 3; ++a) {
            const double c = 0.5 * (lo[a] + hi[a]);
            const double s = p[a] >= c ? 1.0 : -1.0;
            grad[a] = outside2 > 0.0 ? s * std::max(q[a], 0.0) / std::sqrt(outside2)
                                     : (a == axis ? s : 0.0);
        }
    }
    return outside2 > 0.0 ? std::sqrt(outside2) : inside;
}

} // namespace

TEST_CASE("the SDF of a triangulated sphere is within one voxel of |p - c| - r", "[geometry]") {
    const double r = 0.5, voxel = 0.02;
    const std::array<double, 3> c{0.1, -0.2, 0.3};
    auto sdf = buildSdf(uvSphereMesh(c, r, 48, 96), voxel);
    REQUIRE(sdf->band() == Approx(std::ceil(0.25 * std::sqrt(3.0) * 2 * r / voxel) * voxel));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.2, 1.2);
    int checked = 0;
    for (int i = 0; i < 4000; ++i) {
        const double p[3] = {c[0] + u(rng), c[1] + u(rng), c[2] + u(rng)};
        const double dx = p[0] - c[0], dy = p[1] - c[1], dz = p[2] - c[2];
        const double rho = std::sqrt(dx * dx + dy * dy + dz * dz);
        const double exact = rho - r;
        double d = 0.0, g[3];
        sdf->sample(p, 1, &d, g);
        INFO("p = " << p[0] << "," << p[1] << "," << p[2] << " exact " << exact << " got " << d);
        if (std::abs(exact) < sdf->band() - 2 * voxel) {
            CHECK(std::abs(d - exact) < voxel);
            // The gradient: unit length, along the radial direction.
            CHECK(std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) == Approx(1.0).margin(1e-9));
            if (rho > 0.1) CHECK((g[0] * dx + g[1] * dy + g[2] * dz) / rho > 0.99);
            ++checked;
        } else if (exact > 0) {
            // At and beyond the band: a lower bound of the true distance, at least the band.
            CHECK(d >= std::min(exact, sdf->band()) - voxel);
            CHECK(d <= exact + voxel);
        } else {
            CHECK(d <= std::max(exact, -sdf->band()) + voxel);
        }
    }
    CHECK(checked > 500);
    // Far away the distance keeps growing (the bounding-box continuation).
    const double far[3] = {c[0] + 10.0, c[1], c[2]};
    double d = 0.0;
    sdf->sample(far, 1, &d, nullptr);
    CHECK(d == Approx(10.0 - r).margin(voxel));
}

TEST_CASE("the SDF of a box is within one voxel of the analytic box distance", "[geometry]") {
    const double lo[3] = {-0.4, 0.0, -0.25}, hi[3] = {0.4, 0.6, 0.25};
    const double voxel = 0.025;
    auto sdf = buildSdf(boxMesh({lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}), voxel, 12);
    CHECK(sdf->band() == Approx(12 * voxel));
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-0.8, 0.8);
    int checked = 0;
    for (int i = 0; i < 3000; ++i) {
        const double p[3] = {u(rng), 0.3 + u(rng), u(rng)};
        double ga[3];
        const double exact = analyticBox(p, lo, hi, ga);
        if (std::abs(exact) >= sdf->band() - 2 * voxel) continue;
        double d = 0.0, g[3];
        sdf->sample(p, 1, &d, g);
        INFO("p = " << p[0] << "," << p[1] << "," << p[2] << " exact " << exact << " got " << d);
        CHECK(std::abs(d - exact) < voxel);
        CHECK(std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) == Approx(1.0).margin(1e-9));
        // Away from edges and the medial planes the gradient is the face normal.
        if (exact > 2 * voxel || exact < -2 * voxel) {
            int big = 0;
            for (double c : ga) big += std::abs(c) > 0.999;
            if (big == 1 && exact > 0) CHECK(g[0] * ga[0] + g[1] * ga[1] + g[2] * ga[2] > 0.98);
        }
        ++checked;
    }
    CHECK(checked > 500);
}

TEST_CASE("batched sampling equals one-point sampling", "[geometry]") {
    auto sdf = buildSdf(uvSphereMesh({0, 0, 0}, 0.3, 16, 32), 0.03);
    std::vector<double> xyz;
    for (int i = 0; i < 300; ++i) xyz.insert(xyz.end(), {0.003 * i - 0.45, 0.1, -0.05});
    std::vector<double> d(300), g(900);
    sdf->sample(xyz.data(), 300, d.data(), g.data());
    for (int i = 0; i < 300; i += 37) {
        double d1, g1[3];
        sdf->sample(xyz.data() + 3 * i, 1, &d1, g1);
        CHECK(d1 == d[static_cast<size_t>(i)]);
        CHECK(g1[2] == g[3 * static_cast<size_t>(i) + 2]);
    }
}

TEST_CASE("shadow: 0 inside and just behind a sphere, rising monotonically to 1 downwind",
          "[geometry]") {
    const double r = 0.3, voxel = 0.02, L = 2.0;
    auto sdf = buildSdf(uvSphereMesh({0, 0, 0}, r, 32, 64), voxel);
    const double dir[3] = {1.0, 0.0, 0.0};
    auto shadowAt = [&](double x, double y, double z) {
        const double p[3] = {x, y, z};
        double s = -1.0;
        sdf->shadow(p, dir, &L, 1, &s);
        return s;
    };
    CHECK(shadowAt(0, 0, 0) == Approx(0.0).margin(1e-12));                 // inside
    CHECK(shadowAt(-1.0, 0, 0) == Approx(1.0).margin(1e-12));              // upwind, free air
    CHECK(shadowAt(1.0, 0.6, 0) == Approx(1.0).margin(1e-12));             // beside the shadow
    CHECK(shadowAt(r + L + 2 * voxel, 0, 0) == Approx(1.0).margin(1e-12)); // beyond `length`
    // On the axis behind the sphere the ray enters the body at s = x - r, so the shadow lies
    // between the smoothstep evaluated one soft-edge width (plus interpolation) either side.
    double previous = -1.0;
    for (double x = r + 0.01; x < r + L + 0.1; x += 0.0137) {
        const double s = shadowAt(x, 0, 0);
        INFO("x = " << x << " shadow " << s);
        CHECK(s >= previous - 1e-12);
        CHECK(s >= smooth(0, L, x - r - 2 * voxel) - 1e-9);
        CHECK(s <= smooth(0, L, x - r + 2 * voxel) + 1e-9);
        previous = s;
    }
    // Monotone along the wind off the axis too (a chord through the sphere).
    previous = -1.0;
    for (double x = 0.3; x < 2.5; x += 0.011) {
        const double s = shadowAt(x, 0.15, 0.05);
        CHECK(s >= previous - 1e-12);
        previous = s;
    }
    // A zero direction or length: only the body itself.
    const double zero[3] = {0, 0, 0}, p[3] = {0.5, 0, 0};
    double s = 0.0;
    sdf->shadow(p, zero, &L, 1, &s);
    CHECK(s == 1.0);
}

TEST_CASE("closest point on a triangle: face, edge and vertex regions", "[geometry]") {
    const std::array<double, 3> a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
    std::array<double, 3> w;
    auto q = closestPointOnTriangle({0.25, 0.25, 2.0}, a, b, c, w);
    CHECK(q[0] == Approx(0.25));
    CHECK(q[1] == Approx(0.25));
    CHECK(q[2] == Approx(0.0));
    CHECK(w[0] == Approx(0.5));
    CHECK(w[1] == Approx(0.25));
    q = closestPointOnTriangle({0.5, -1.0, 0.0}, a, b, c, w); // edge ab
    CHECK(q[0] == Approx(0.5));
    CHECK(q[1] == Approx(0.0));
    CHECK(w[1] == Approx(0.5));
    q = closestPointOnTriangle({1.0, 1.0, 0.0}, a, b, c, w); // edge bc, its midpoint
    CHECK(q[0] == Approx(0.5));
    CHECK(q[1] == Approx(0.5));
    q = closestPointOnTriangle({-1, -1, 3}, a, b, c, w); // vertex a
    CHECK(w[0] == 1.0);
    q = closestPointOnTriangle({3, -0.5, 0}, a, b, c, w); // vertex b
    CHECK(w[1] == 1.0);
}

TEST_CASE("meshes: OBJ quads and PLY faces are fanned into triangles; clear errors", "[geometry]") {
    TempDir dir;
    writeText(dir.file("quad.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                                    "f 1 2 3 4\nf 1 2 5\n");
    TriangleMesh m;
    IoError e = readTriangleMesh(dir.file("quad.obj"), m);
    INFO(e.render());
    REQUIRE_FALSE(e);
    REQUIRE(m.triangles.size() == 3);
    CHECK(m.triangles[0] == std::array<uint32_t, 3>{0, 1, 2});
    CHECK(m.triangles[1] == std::array<uint32_t, 3>{0, 2, 3});
    CHECK(m.bounds() == std::array<double, 6>{0, 0, 0, 1, 1, 1});

    writeText(dir.file("tri.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                   "property float y\nproperty float z\nelement face 1\n"
                                   "property list uchar int vertex_indices\nend_header\n"
                                   "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    REQUIRE_FALSE(readTriangleMesh(dir.file("tri.ply"), m));
    CHECK(m.triangles.size() == 1);

    writeText(dir.file("points.obj"), "v 0 0 0\nv 1 0 0\n");
    e = readTriangleMesh(dir.file("points.obj"), m);
    CHECK(e.kind == IoError::Data);
    CHECK(e.message.find("no faces") != std::string::npos);
    e = readTriangleMesh(dir.file("missing.obj"), m);
    CHECK(e.kind == IoError::Io);
    CHECK(e.file.find("missing.obj") != std::string::npos);
    e = readTriangleMesh(dir.file("mesh.csv"), m);
    CHECK(e.message.find(".obj or .ply") != std::string::npos);

    // A generated mesh written and read back.
    const TriangleMesh box = boxMesh({0, 0, 0}, {1, 2, 3});
    REQUIRE_FALSE(writeTriangleMeshObj(dir.file("box.obj"), box));
    REQUIRE_FALSE(readTriangleMesh(dir.file("box.obj"), m));
    CHECK(m.points == box.points);
    CHECK(m.triangles == box.triangles);
}

TEST_CASE("SDF build errors: empty meshes, bad voxels, too many voxels", "[geometry]") {
    std::shared_ptr<const SdfVolume> sdf;
    SdfOptions o;
    CHECK(SdfVolume::build(TriangleMesh{}, o, sdf, "empty.obj").message.find("no triangles") !=
          std::string::npos);
    o.voxel = -1.0;
    CHECK(SdfVolume::build(boxMesh({0, 0, 0}, {1, 1, 1}), o, sdf, "b").message.find("positive") !=
          std::string::npos);
    o.voxel = 1e-5;
    IoError e = SdfVolume::build(boxMesh({0, 0, 0}, {1, 1, 1}), o, sdf, "b");
    CHECK(e.kind == IoError::Data);
    CHECK(e.message.find("larger voxel") != std::string::npos);
}

TEST_CASE("the geometry cache builds each key once, even when asked concurrently", "[geometry]") {
    GeometryCache cache(1000);
    std::atomic<int> calls{0};
    auto build = [&](std::shared_ptr<const int>& v, size_t& bytes) -> IoError {
        ++calls;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        v = std::make_shared<const int>(42);
        bytes = 400;
        return {};
    };
    std::vector<std::thread> threads;
    std::atomic<int> sum{0};
    for (int i = 0; i < 4; ++i)
        threads.emplace_back([&] {
            std::shared_ptr<const int> v;
            if (!cache.get<int>("a", build, v)) sum += *v;
        });
    for (auto& t : threads) t.join();
    CHECK(calls == 1);
    CHECK(sum == 4 * 42);
    // The budget holds two entries of 400 bytes: a third evicts the least recently used.
    std::shared_ptr<const int> v;
    REQUIRE_FALSE(cache.get<int>("b", build, v));
    REQUIRE_FALSE(cache.get<int>("a", build, v)); // touch a
    REQUIRE_FALSE(cache.get<int>("c", build, v)); // evicts b
    CHECK(cache.entries() == 2);
    CHECK(cache.bytes() == 800);
    const int before = calls;
    REQUIRE_FALSE(cache.get<int>("a", build, v));
    CHECK(calls == before);
    REQUIRE_FALSE(cache.get<int>("b", build, v));
    CHECK(calls == before + 1);
    // Errors are not cached.
    auto failing = [&](std::shared_ptr<const int>&, size_t&) -> IoError {
        ++calls;
        IoError e;
        e.kind = IoError::Io;
        e.message = "nope";
        return e;
    };
    CHECK(cache.get<int>("x", failing, v).message == "nope");
    CHECK(cache.get<int>("x", failing, v).message == "nope");
    CHECK(calls == before + 3);
}
