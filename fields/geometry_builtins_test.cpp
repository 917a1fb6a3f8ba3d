// Tests of the geometry built-ins inside expressions: sdf/sdfgrad/shadow agree with the volumes
// and closed forms, meshvel() gives a translating sphere's velocity with its falloff, scenes
// resolve names against their folder, and every misuse is a diagnostic at the argument's
// file:line:col naming the file (missing, outside the folder, not constant, varying settings).
#include "fields/expression_field.h"
#include "geometry/geometry.h"
#include "io/test_support.h"
#include "lang/diagnostics.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace gale::fields;
using namespace gale::geometry;
namespace fs = std::filesystem;

namespace {

using gale::io::test::TempDir;

struct Compiled {
    std::shared_ptr<ExpressionField> field;
    std::string diagnostics;
};

// Compiles `text` as if read from DIR/expr.se (diagnostics name "expr.se").
Compiled compileIn(const TempDir& dir, const std::string& text,
                   const std::vector<std::string>& allowed = {}) {
    gale::lang::SourceFile source("expr.se", text);
    ExpressionFieldOptions o;
    o.precision = gale::runtime::Precision::Double;
    o.files = fileAccessFor(dir.file("expr.se"), allowed);
    gale::lang::DiagnosticSink sink;
    Compiled c;
    c.field = ExpressionField::compile(source, o, sink);
    c.diagnostics = gale::lang::renderDiagnostics(source, sink);
    return c;
}

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

TEST_CASE("sdf() and sdfgrad() in an expression match the volume and |p - c| - r",
          "[geometry][builtins]") {
    TempDir dir;
    REQUIRE_FALSE(writeTriangleMeshObj(dir.file("ball.obj"), uvSphereMesh({0, 1, 0}, 0.4, 32, 64)));
    Compiled c = compileIn(dir, "sdf(\"ball.obj\", $P, 0.02)");
    INFO(c.diagnostics);
    REQUIRE(c.field);
    Compiled g = compileIn(dir, "sdfgrad(\"ball.obj\", $P, 0.02)");
    REQUIRE(g.field);
    std::vector<double> xyz;
    for (int i = 0; i < 600; ++i) {
        const double a = 0.01 * i;
        const double rho = 0.2 + 0.0005 * i; // 0.2 .. 0.5 from the centre
        xyz.insert(xyz.end(), {rho * std::cos(a) * std::sin(1 + a), 1 + rho * std::cos(1 + a),
                               rho * std::sin(a) * std::sin(1 + a)});
    }
    const std::vector<double> d = sampleAt(*c.field, xyz), n = sampleAt(*g.field, xyz);
    for (size_t i = 0; i < 600; ++i) {
        const double x = xyz[3 * i], y = xyz[3 * i + 1] - 1, z = xyz[3 * i + 2];
        const double rho = std::sqrt(x * x + y * y + z * z);
        CHECK(std::abs(d[3 * i] - (rho - 0.4)) < 0.02);
        CHECK(d[3 * i + 2] == d[3 * i]); // a scalar promoted to the three components
        CHECK((n[3 * i] * x + n[3 * i + 1] * y + n[3 * i + 2] * z) / rho > 0.99);
    }
    // The default voxel (0.02) is the same volume.
    Compiled dflt = compileIn(dir, "sdf(\"ball.obj\", $P)");
    REQUIRE(dflt.field);
    CHECK(sampleAt(*dflt.field, xyz) == d);
    // The idiom: wind that flows around the body (the normal component removed near it).
    Compiled around = compileIn(dir, "$wind = [3, 0, 0];\n"
                                     "n = sdfgrad(\"ball.obj\", $P);\n"
                                     "k = 1 - smoothstep(sdf(\"ball.obj\", $P), 0, 0.3);\n"
                                     "$wind - k * min(dot($wind, n), 0) * n");
    INFO(around.diagnostics);
    REQUIRE(around.field);
    const std::vector<double> front = sampleAt(*around.field, {-0.41, 1, 0});
    CHECK(std::abs(front[0]) < 0.3); // head-on at the surface: the flow into the body is removed
}

TEST_CASE("shadow() in an expression: sheltered behind the ball, free elsewhere",
          "[geometry][builtins]") {
    TempDir dir;
    REQUIRE_FALSE(writeTriangleMeshObj(dir.file("ball.obj"), uvSphereMesh({0, 0, 0}, 0.3, 24, 48)));
    Compiled c = compileIn(dir, "shadow(\"ball.obj\", $P, [1, 0, 0], 1.5) * [4, 0, 0]");
    INFO(c.diagnostics);
    REQUIRE(c.field);
    const std::vector<double> v =
        sampleAt(*c.field, {-1, 0, 0, 0, 0, 0, 0.35, 0, 0, 1.0, 0, 0, 2.0, 0, 0, 1.0, 0.8, 0});
    CHECK(v[0] == Approx(4.0));           // upwind
    CHECK(v[3] == Approx(0.0).margin(1e-9)); // inside
    CHECK(v[6] < 0.2);                    // right behind
    CHECK(v[9] > v[6]);
    CHECK(v[9] < 4.0);
    CHECK(v[12] == Approx(4.0));          // beyond the length
    CHECK(v[15] == Approx(4.0));          // beside
}

TEST_CASE("meshvel(): the velocity of a moving sphere near its surface, faded by distance",
          "[geometry][builtins]") {
    TempDir dir;
    // Frames 1..4: a sphere moving +x by 0.05 m per frame; frame 5 is missing (held still).
    for (int f = 1; f <= 4; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "body.%04d.obj", f);
        REQUIRE_FALSE(writeTriangleMeshObj(dir.file(name),
                                           uvSphereMesh({0.05 * f, 0, 0}, 0.3, 16, 32)));
    }
    Compiled c = compileIn(dir, "meshvel(\"body.#.obj\", $P, 0.2, 0.02)");
    INFO(c.diagnostics);
    REQUIRE(c.field);
    const double fps = 24.0, speed = 0.05 * fps; // 1.2 m/s
    // At frame 2 (t = 2/24) the centre is at x = 0.1.
    const double t = 2.0 / fps;
    const std::vector<double> v = sampleAt(
        *c.field, {0.1, 0.3, 0,      // on the surface (top)
                   0.1 - 0.4, 0, 0,  // 0.1 m out on the left: half way through the falloff
                   0.1, 0, 0.6,      // 0.3 m out: beyond the falloff
                   0.35, 0, 0},      // inside, 0.05 m from the surface
        t, fps);
    CHECK(v[0] == Approx(speed).epsilon(0.02));
    CHECK(std::abs(v[1]) < 1e-3);
    CHECK(v[3] == Approx(0.5 * speed).epsilon(0.05)); // 1 - smoothstep(0.5) = 0.5
    CHECK(v[6] == 0.0);
    CHECK(v[9] == Approx(0.84375 * speed).epsilon(0.05)); // 1 - smoothstep(0.25)
    // Between frames (2.5) the sphere is half way; the velocity is the same.
    const std::vector<double> mid = sampleAt(*c.field, {0.125, 0.3, 0}, 2.5 / fps, fps);
    CHECK(mid[0] == Approx(speed).epsilon(0.02));
    // After the last frame on disk the mesh holds still.
    CHECK(sampleAt(*c.field, {0.2, 0.3, 0}, 6.0 / fps, fps)[0] == 0.0);
    // fps scales the velocity (m per frame * frames per second).
    CHECK(sampleAt(*c.field, {0.1, 0.3, 0}, 2.0 / 30.0, 30.0)[0] ==
          Approx(0.05 * 30.0).epsilon(0.02));
    // A far-away or NaN point has no nearby triangle: no velocity, and no crash.
    CHECK(sampleAt(*c.field, {1e12, 0, 0}, t, fps)[0] == 0.0);
    const double atNan = sampleAt(*c.field, {std::nan(""), 0, 0}, t, fps)[0];
    CHECK((std::isnan(atNan) || atNan == 0.0));
    // A uniform voxel of 0 is only known at evaluation: the kernel fails (NaN, which the field
    // reports and zeroes) instead of converting an infinite voxel count to int (undefined;
    // caught by the float-cast-overflow sanitizer in `make test-asan`).
    Compiled z = compileIn(dir, "$vox = 0.0;\nmeshvel(\"body.#.obj\", $P, 0.2, $vox)");
    INFO(z.diagnostics);
    REQUIRE(z.field);
    const double atZero = sampleAt(*z.field, {0.1, 0.3, 0}, t, fps)[0];
    CHECK((std::isnan(atZero) || atZero == 0.0));
}

TEST_CASE("geometry diagnostics point at the argument and name the file",
          "[geometry][builtins]") {
    TempDir dir;
    fs::create_directories(dir.path / "shot");
    REQUIRE_FALSE(writeTriangleMeshObj(dir.file("outside.obj"), boxMesh({0, 0, 0}, {1, 1, 1})));
    REQUIRE_FALSE(writeTriangleMeshObj(dir.file("shot/box.obj"), boxMesh({0, 0, 0}, {1, 1, 1})));
    std::ofstream(dir.file("shot/points.obj")) << "v 0 0 0\nv 1 0 0\n";
    TempDir none; // an empty folder for the expression
    auto shot = [&](const std::string& text, const std::vector<std::string>& allowed = {}) {
        gale::lang::SourceFile source("expr.se", text);
        ExpressionFieldOptions o;
        o.files = fileAccessFor(dir.file("shot/expr.se"), allowed);
        gale::lang::DiagnosticSink sink;
        auto f = ExpressionField::compile(source, o, sink);
        CHECK((f != nullptr) == !sink.hasErrors());
        return gale::lang::renderDiagnostics(source, sink);
    };
    std::string d = shot("sdf(\"missing.obj\", $P)");
    CHECK(d.find("expr.se:1:5: error: cannot read 'missing.obj'") != std::string::npos);
    CHECK(d.find("No such file") != std::string::npos);
    d = shot("x = 1;\nsdf(\"../outside.obj\", $P)");
    CHECK(d.find("expr.se:2:5: error: '../outside.obj' leads outside") != std::string::npos);
    CHECK(shot("sdf(\"../outside.obj\", $P)", {dir.path.string()}).empty());
    d = shot("sdf(\"" + dir.file("shot/box.obj") + "\", $P)");
    CHECK(d.find("is an absolute path") != std::string::npos);
    d = shot("sdf(\"points.obj\", $P)");
    CHECK(d.find("cannot load 'points.obj'") != std::string::npos);
    CHECK(d.find("no faces") != std::string::npos);
    d = shot("name = \"box\" + \".obj\"; sdf(name, $P)");
    CHECK(d.empty()); // constant folding makes it a constant string
    d = shot("sdf(sprintf(\"box%d.obj\", $frame), $P)");
    CHECK(d.find("the mesh of 'sdf' must be a constant string") != std::string::npos);
    d = shot("sdf(\"box.obj\", $P, $P[0] + 0.1)");
    CHECK(d.find("'voxel' of 'sdf' must be uniform") != std::string::npos);
    d = shot("sdf(\"box.obj\", $P, -1)");
    CHECK(d.find("'voxel' of 'sdf' must be a positive number") != std::string::npos);
    d = shot("sdf(\"box.obj\", $P, 0.00001)");
    CHECK(d.find("larger voxel") != std::string::npos);
    d = shot("shadow(\"box.obj\", $P, [1, 0, 0], 2, $P[1])");
    CHECK(d.find("'voxel' of 'shadow' must be uniform") != std::string::npos);
    d = shot("meshvel(\"box.obj\", $P, 0.3)");
    CHECK(d.find("needs a per-frame mesh sequence") != std::string::npos);
    d = shot("meshvel(\"box.#.obj\", $P, 0.3)");
    CHECK(d.find("no files of the sequence 'box.#.obj'") != std::string::npos);
    d = shot("meshvel(\"box.obj\", $P, $P[0])");
    CHECK(d.find("'falloff' of 'meshvel' must be uniform") != std::string::npos);
    d = shot("vdb(\"box.obj\", \"vel\", $P, 3)");
    CHECK(d.find("'interp' of 'vdb' must be a constant 0") != std::string::npos);
    // A uniform voxel (a parameter) is fine: the volume is built at evaluation.
    CHECK(shot("$res = 0.05;\nsdf(\"box.obj\", $P, $res)").empty());
}
