// Tests of vdb(): velocity volumes sampled in world space reproduce linear fields exactly,
// quadratics exactly with quadratic interpolation, smooth fields within the trilinear error
// bound; `gale sample`'s .vdb reads back identically at cell centres; `#` sequences blend
// frames; missing, truncated, garbage and wrong-grid files are clear errors.
#include "fields/expression_field.h"
#include "fields/grid_sample.h"
#include "geometry/geometry.h"
#include "geometry/vdb_io.h"
#include "io/test_support.h"
#include "lang/diagnostics.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

using namespace gale::fields;
using namespace gale::geometry;
using namespace gale::io;
namespace fs = std::filesystem;

namespace {

using gale::io::test::TempDir;

GridSpec testGrid() {
    GridSpec g;
    g.origin = {-1.0, -0.5, 0.25};
    g.voxel = {0.1, 0.1, 0.1};
    g.res = {20, 15, 12};
    return g;
}

// Samples fn on the grid and writes it as a .vdb (as `gale sample -o` does).
void writeField(const std::string& path, const GridSpec& g, FunctionField::Fn fn) {
    FunctionField field(std::move(fn), "analytic");
    std::vector<float> values;
    REQUIRE(sampleGrid(field, g, SampleTime{}, values).ok);
    IoError e = writeVdbVelocity(path, g, values);
    INFO(e.render());
    REQUIRE_FALSE(e);
}

std::shared_ptr<const VelocityVolume> load(const std::string& path, const std::string& grid = "vel") {
    std::shared_ptr<const VelocityVolume> v;
    IoError e = VelocityVolume::load(path, grid, v);
    INFO(e.render());
    REQUIRE_FALSE(e);
    return v;
}

// Random points at least `margin` cells inside the sampled box (so every stencil is inside).
std::vector<double> interiorPoints(const GridSpec& g, double margin, int n) {
    std::mt19937 rng(3);
    std::vector<double> xyz;
    for (int i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            std::uniform_real_distribution<double> u(
                g.origin[a] + (0.5 + margin) * g.voxel[a],
                g.origin[a] + (g.res[a] - 0.5 - margin) * g.voxel[a]);
            xyz.push_back(u(rng));
        }
    return xyz;
}

std::string compileError(const TempDir& dir, const std::string& text) {
    gale::lang::SourceFile source("expr.se", text);
    ExpressionFieldOptions o;
    o.files = fileAccessFor(dir.file("expr.se"));
    gale::lang::DiagnosticSink sink;
    CHECK_FALSE(ExpressionField::compile(source, o, sink));
    return gale::lang::renderDiagnostics(source, sink);
}

std::shared_ptr<ExpressionField> compileOk(const TempDir& dir, const std::string& text,
                                           gale::runtime::Precision p =
                                               gale::runtime::Precision::Double) {
    gale::lang::SourceFile source("expr.se", text);
    ExpressionFieldOptions o;
    o.files = fileAccessFor(dir.file("expr.se"));
    o.precision = p;
    gale::lang::DiagnosticSink sink;
    auto f = ExpressionField::compile(source, o, sink);
    INFO(gale::lang::renderDiagnostics(source, sink));
    REQUIRE(f);
    return f;
}

} // namespace

TEST_CASE("vdb volumes: linear fields exact, quadratics exact with quadratic interpolation",
          "[geometry][vdb]") {
    TempDir dir;
    const GridSpec g = testGrid();
    writeField(dir.file("lin.vdb"), g, [](const Vec3& p, double) {
        return Vec3{1 + 2 * p[0] - p[1], 0.5 * p[2], 3 - p[0] + 4 * p[1]};
    });
    writeField(dir.file("quad.vdb"), g, [](const Vec3& p, double) {
        return Vec3{p[0] * p[0], p[1] * p[2], 1 - p[2] * p[2] + p[0] * p[1]};
    });
    auto lin = load(dir.file("lin.vdb"));
    auto quad = load(dir.file("quad.vdb"));
    CHECK(lin->gridName() == "vel");
    const std::vector<double> xyz = interiorPoints(g, 1.0, 500);
    const size_t n = xyz.size() / 3;
    std::vector<double> v(3 * n), q(3 * n);
    lin->sample(xyz.data(), n, VolumeInterp::Trilinear, v.data());
    lin->sample(xyz.data(), n, VolumeInterp::Quadratic, q.data());
    double worstTrilinear = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
        const double want[3] = {1 + 2 * x - y, 0.5 * z, 3 - x + 4 * y};
        for (int c = 0; c < 3; ++c) {
            CHECK(v[3 * i + c] == Approx(want[c]).margin(2e-5));
            CHECK(q[3 * i + c] == Approx(want[c]).margin(2e-5));
        }
    }
    quad->sample(xyz.data(), n, VolumeInterp::Quadratic, q.data());
    quad->sample(xyz.data(), n, VolumeInterp::Trilinear, v.data());
    const double h = 0.1;
    for (size_t i = 0; i < n; ++i) {
        const double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
        const double want[3] = {x * x, y * z, 1 - z * z + x * y};
        for (int c = 0; c < 3; ++c) CHECK(q[3 * i + c] == Approx(want[c]).margin(2e-5));
        // Trilinear: the error of linear interpolation of x^2 is (x - x0)(x1 - x) <= h^2/4;
        // y*z is bilinear (exact); -z^2 + x*y gives at most h^2/4 too.
        CHECK(std::abs(v[3 * i] - want[0]) <= h * h / 4 + 2e-5);
        CHECK(std::abs(v[3 * i + 1] - want[1]) <= 2e-5);
        CHECK(std::abs(v[3 * i + 2] - want[2]) <= h * h / 4 + 2e-5);
        worstTrilinear = std::max(worstTrilinear, std::abs(v[3 * i] - want[0]));
    }
    CHECK(worstTrilinear > h * h / 8); // the bound is nearly reached: the test sees the error
}

TEST_CASE("vdb() reproduces a sampled smooth field within the trilinear error bound",
          "[geometry][vdb]") {
    TempDir dir;
    const GridSpec g = testGrid();
    // |d2/dx2 sin(2x)| <= 4, so linear interpolation errs by at most 4 h^2 / 8 per axis.
    auto fn = [](const Vec3& p, double) {
        return Vec3{std::sin(2 * p[0]) * std::cos(2 * p[1]), std::sin(2 * p[2]),
                    std::cos(2 * p[0] + 2 * p[2])};
    };
    writeField(dir.file("smooth.vdb"), g, fn);
    auto field = compileOk(dir, "vdb(\"smooth.vdb\", \"vel\", $P)");
    auto fieldQ = compileOk(dir, "vdb(\"smooth.vdb\", \"vel\", $P, 2)");
    const std::vector<double> xyz = interiorPoints(g, 1.0, 400);
    std::vector<double> v(xyz.size()), q(xyz.size());
    REQUIRE(field->sample(xyz.data(), xyz.size() / 3, SampleTime{}, v.data()).ok);
    REQUIRE(fieldQ->sample(xyz.data(), xyz.size() / 3, SampleTime{}, q.data()).ok);
    const double h = 0.1, bound = 3 * 4 * h * h / 8; // three axes, each |f''| <= 4
    double errT = 0.0, errQ = 0.0;
    for (size_t i = 0; i < xyz.size() / 3; ++i) {
        const Vec3 want = fn({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}, 0.0);
        for (int c = 0; c < 3; ++c) {
            CHECK(std::abs(v[3 * i + c] - want[c]) <= bound);
            errT += std::abs(v[3 * i + c] - want[c]);
            errQ += std::abs(q[3 * i + c] - want[c]);
        }
    }
    CHECK(errQ < errT); // quadratic interpolation is closer on a smooth field
}

TEST_CASE("round trip: a sampled grid read by vdb() gives the same floats at cell centres",
          "[geometry][vdb]") {
    TempDir dir;
    GridSpec g;
    g.origin = {-0.35, 0.1, 2.0};
    g.voxel = {0.05, 0.05, 0.05};
    g.res = {13, 7, 9};
    auto source = compileOk(dir, "[sin($P[0] * 3), $P[1] * $P[2], cos($P[2] * 5)]",
                            gale::runtime::Precision::Float);
    std::vector<float> values;
    REQUIRE(sampleGrid(*source, g, SampleTime{}, values).ok);
    REQUIRE_FALSE(writeVdbVelocity(dir.file("x.vdb"), g, values));
    auto back = compileOk(dir, "vdb(\"x.vdb\", \"vel\", $P)", gale::runtime::Precision::Float);
    auto nearest = compileOk(dir, "vdb(\"x.vdb\", \"vel\", $P, 0)", gale::runtime::Precision::Float);
    std::vector<double> centres;
    for (int i = 0; i < g.res[0]; ++i)
        for (int j = 0; j < g.res[1]; ++j)
            for (int k = 0; k < g.res[2]; ++k) {
                const Vec3 c = g.cellCenter(i, j, k);
                centres.insert(centres.end(), c.begin(), c.end());
            }
    std::vector<double> v(centres.size()), w(centres.size());
    REQUIRE(back->sample(centres.data(), g.cellCount(), SampleTime{}, v.data()).ok);
    REQUIRE(nearest->sample(centres.data(), g.cellCount(), SampleTime{}, w.data()).ok);
    size_t mismatches = 0;
    for (size_t i = 0; i < values.size(); ++i) {
        mismatches += static_cast<float>(v[i]) != values[i];
        mismatches += static_cast<float>(w[i]) != values[i];
    }
    CHECK(mismatches == 0);
    // Outside the sampled box the wind is zero (the background).
    std::vector<double> out(3);
    const double far[3] = {-5, 0, 0};
    REQUIRE(back->sample(far, 1, SampleTime{}, out.data()).ok);
    CHECK(out == std::vector<double>{0, 0, 0});
}

TEST_CASE("vdb() sequences: '#' follows $frame, blending the frames around it",
          "[geometry][vdb]") {
    TempDir dir;
    GridSpec g;
    g.origin = {0, 0, 0};
    g.voxel = {0.5, 0.5, 0.5};
    g.res = {4, 4, 4};
    writeField(dir.file("wind.0001.vdb"), g, [](const Vec3&, double) { return Vec3{1, 0, 0}; });
    writeField(dir.file("wind.0003.vdb"), g, [](const Vec3&, double) { return Vec3{3, 0, -2}; });
    auto f = compileOk(dir, "vdb(\"wind.#.vdb\", \"vel\", $P)");
    auto at = [&](double frame) {
        SampleTime when;
        when.fps = 24;
        when.time = frame / 24.0;
        const double p[3] = {1, 1, 1};
        double v[3];
        REQUIRE(f->sample(p, 1, when, v).ok);
        return std::vector<double>{v[0], v[1], v[2]};
    };
    CHECK(at(1) == std::vector<double>{1, 0, 0});
    CHECK(at(2)[0] == Approx(2.0));
    CHECK(at(2)[2] == Approx(-1.0));
    CHECK(at(2.5)[0] == Approx(2.5));
    CHECK(at(3) == std::vector<double>{3, 0, -2});
    CHECK(at(-4) == std::vector<double>{1, 0, 0}); // held before the first frame
    CHECK(at(40) == std::vector<double>{3, 0, -2}); // and after the last
}

TEST_CASE("vdb() errors: missing, truncated, garbage and wrong-grid files", "[geometry][vdb]") {
    TempDir dir;
    GridSpec g;
    g.res = {16, 16, 16};
    g.voxel = {0.1, 0.1, 0.1};
    writeField(dir.file("good.vdb"), g, [](const Vec3& p, double) { return Vec3{p[0], 1, 2}; });

    std::string d = compileError(dir, "vdb(\"missing.vdb\", \"vel\", $P)");
    CHECK(d.find("expr.se:1:5: error: cannot read 'missing.vdb'") != std::string::npos);

    // Truncated: the first half of a good file (and cut at several other places). OpenVDB's own
    // reader would take a block size it never read and allocate that many bytes; gale reads
    // through a stream that throws on a short read (vdb_io.cpp), so every cut is a clean error.
    {
        std::ifstream in(dir.file("good.vdb"), std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::ofstream(dir.file("trunc.vdb"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    }
    d = compileError(dir, "vdb(\"trunc.vdb\", \"vel\", $P)");
    CHECK(d.find("expr.se:1:5: error: cannot load 'trunc.vdb'") != std::string::npos);
    CHECK(d.find("trunc.vdb: cannot read the VDB file") != std::string::npos);
    std::shared_ptr<const VelocityVolume> v;
    CHECK(VelocityVolume::load(dir.file("trunc.vdb"), "vel", v).kind == IoError::Io);
    {
        std::ifstream in(dir.file("good.vdb"), std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        for (size_t cut : {size_t(8), size_t(40), bytes.size() / 5, bytes.size() * 4 / 5, bytes.size() - 1}) {
            std::ofstream(dir.file("cut.vdb"), std::ios::binary | std::ios::trunc) << bytes.substr(0, cut);
            INFO("cut at " << cut << " of " << bytes.size());
            std::shared_ptr<const VelocityVolume> w;
            CHECK(VelocityVolume::load(dir.file("cut.vdb"), "vel", w).kind == IoError::Io);
            VdbVelocity raw;
            CHECK(readVdbVelocity(dir.file("cut.vdb"), "vel", raw).kind == IoError::Io);
        }
    }

    std::ofstream(dir.file("text.vdb")) << "this is not a VDB file\n";
    d = compileError(dir, "vdb(\"text.vdb\", \"vel\", $P)");
    CHECK(d.find("cannot load 'text.vdb'") != std::string::npos);

    d = compileError(dir, "vdb(\"good.vdb\", \"velocity\", $P)");
    CHECK(d.find("the file has no grid named 'velocity' (its grids: vel (vec3s))") !=
          std::string::npos);

    // A level set (float grid) is not a velocity.
    std::shared_ptr<const SdfVolume> sdf;
    SdfOptions o;
    o.voxel = 0.1;
    REQUIRE_FALSE(SdfVolume::build(boxMesh({0, 0, 0}, {1, 1, 1}), o, sdf, "box"));
    REQUIRE_FALSE(sdf->writeVdb(dir.file("sdf.vdb")));
    d = compileError(dir, "vdb(\"sdf.vdb\", \"surface\", $P)");
    CHECK(d.find("grid 'surface' holds float values, not vectors") != std::string::npos);
    d = compileError(dir, "vdb(\"sdf.vdb\", \"\", $P)");
    CHECK(d.find("the file has no vector grid (its grids: surface (float))") != std::string::npos);
    // An empty grid name takes the first vector grid.
    compileOk(dir, "vdb(\"good.vdb\", \"\", $P)");

    // A sequence whose later frame lacks the grid: reported at compile time, naming the frame.
    REQUIRE_FALSE(sdf->writeVdb(dir.file("seq.0002.vdb"), "vel"));
    fs::copy_file(dir.file("good.vdb"), dir.file("seq.0001.vdb"));
    d = compileError(dir, "vdb(\"seq.#.vdb\", \"vel\", $P)");
    CHECK(d.find("cannot load 'seq.#.vdb' (frame 2)") != std::string::npos);
    CHECK(d.find("holds float values") != std::string::npos);
}
