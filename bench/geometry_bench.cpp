// Geometry fields: SDF build time against voxel size (a sphere and the example body), and
// sampling throughput of sdf()/sdfgrad()/shadow()/vdb() — direct (one accessor per batch of 256
// points, per thread) and through the VM — on 1 thread and on all threads.
// Usage: gale_bench_geometry [points=400000] [body.obj=examples/04_shelter/body.obj]
#include "fields/expression_field.h"
#include "fields/grid_sample.h"
#include "geometry/cache.h"
#include "geometry/geometry.h"
#include "geometry/vdb_io.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <random>
#include <thread>

using namespace gale;
using namespace gale::fields;
using namespace gale::geometry;
using namespace gale::io;

namespace {

double seconds(const std::function<void()>& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double bestSeconds(int repeats, const std::function<void()>& f) {
    double best = 1e30;
    for (int r = 0; r < repeats; ++r) best = std::min(best, seconds(f));
    return best;
}

// Points uniformly in a box around `b` grown by `margin`.
std::vector<double> pointsAround(const std::array<double, 6>& b, double margin, size_t n) {
    std::mt19937_64 rng(5);
    std::vector<double> p(3 * n);
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            std::uniform_real_distribution<double> u(b[a] - margin, b[3 + a] + margin);
            p[3 * i + static_cast<size_t>(a)] = u(rng);
        }
    return p;
}

// About n points on a regular grid over the same box, x slowest (the order `gale sample` uses):
// neighbouring points share voxels, as cloth vertices and grid cells do.
std::vector<double> gridPoints(const std::array<double, 6>& b, double margin, size_t n) {
    const double lx = b[3] - b[0] + 2 * margin, ly = b[4] - b[1] + 2 * margin,
                 lz = b[5] - b[2] + 2 * margin;
    const double h = std::cbrt(lx * ly * lz / static_cast<double>(n));
    const int nx = std::max(1, static_cast<int>(lx / h)), ny = std::max(1, static_cast<int>(ly / h)),
              nz = std::max(1, static_cast<int>(lz / h));
    std::vector<double> p;
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j)
            for (int k = 0; k < nz; ++k)
                p.insert(p.end(), {b[0] - margin + (i + 0.5) * lx / nx,
                                   b[1] - margin + (j + 0.5) * ly / ny,
                                   b[2] - margin + (k + 0.5) * lz / nz});
    return p;
}

// Runs fn(first, count) over [0, n) in batches of 256 (one accessor each, as the VM does) on
// `threads` threads.
void parallelBatches(size_t n, int threads, const std::function<void(size_t, size_t)>& fn) {
    const size_t batch = 256;
    std::vector<std::thread> pool;
    const size_t batches = (n + batch - 1) / batch;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (size_t b = static_cast<size_t>(t); b < batches; b += static_cast<size_t>(threads)) {
                const size_t first = b * batch;
                fn(first, std::min(batch, n - first));
            }
        });
    for (auto& th : pool) th.join();
}

void buildTable(const char* name, const TriangleMesh& mesh) {
    std::printf("### %s (%zu triangles)\n\n", name, mesh.triangles.size());
    std::printf("| voxel m | band voxels | build ms | active voxels | MiB |\n|---:|---:|---:|---:|---:|\n");
    for (double voxel : {0.04, 0.02, 0.01, 0.005}) {
        std::shared_ptr<const SdfVolume> sdf;
        SdfOptions o;
        o.voxel = voxel;
        const double s = bestSeconds(voxel >= 0.01 ? 3 : 1, [&] { SdfVolume::build(mesh, o, sdf); });
        std::printf("| %g | %d | %.1f | %zu | %.1f |\n", voxel, automaticBandVoxels(mesh, voxel),
                    1e3 * s, sdf->activeVoxels(), sdf->memoryBytes() / 1048576.0);
    }
    std::printf("\n");
}

std::shared_ptr<ExpressionField> compileIn(const std::string& dir, const std::string& text) {
    lang::SourceFile source("bench.se", text);
    ExpressionFieldOptions o;
    o.files = fileAccessFor(dir + "/bench.se");
    lang::DiagnosticSink sink;
    auto f = ExpressionField::compile(source, o, sink);
    if (!f) {
        std::fprintf(stderr, "%s", lang::renderDiagnostics(source, sink).c_str());
        std::exit(1);
    }
    return f;
}

} // namespace

int main(int argc, char** argv) {
    const size_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 400000;
    std::string bodyPath = argc > 2 ? argv[2] : "examples/04_shelter/body.obj";
#ifdef GALE_SOURCE_DIR
    if (argc <= 2 && !std::filesystem::exists(bodyPath))
        bodyPath = std::string(GALE_SOURCE_DIR) + "/examples/04_shelter/body.obj";
#endif
    const int hw = std::max(1u, std::thread::hardware_concurrency());
    std::printf("# Geometry fields (%zu points, %d hardware threads)\n\n", n, hw);

    std::printf("## SDF build (meshToLevelSet) against voxel size\n\n");
    const TriangleMesh sphere = uvSphereMesh({0, 0, 0}, 0.5, 64, 128);
    buildTable("UV sphere r = 0.5 m", sphere);
    TriangleMesh body;
    if (IoError e = readTriangleMesh(bodyPath, body)) {
        std::fprintf(stderr, "%s\n", e.render().c_str());
        return 1;
    }
    buildTable("examples/04_shelter/body.obj (1.75 m)", body);

    // Sampling: points in the body's box grown by 0.5 m (a mix of band and far points).
    std::shared_ptr<const SdfVolume> sdf;
    SdfOptions o;
    o.voxel = 0.02;
    SdfVolume::build(body, o, sdf);
    const std::vector<double> random = pointsAround(body.bounds(), 0.5, n);
    const std::vector<double> ordered = gridPoints(body.bounds(), 0.5, n);
    const size_t m = std::min(n, ordered.size() / 3);
    const double* xyz = random.data();
    std::vector<double> out(3 * n), len(n, 1.2), dir;
    for (size_t i = 0; i < n; ++i) dir.insert(dir.end(), {0.15, 0.0, -1.0});

    // A velocity volume: 128^3 cells over the same box.
    GridSpec grid;
    std::array<double, 6> b = body.bounds();
    const std::vector<int> res{128};
    std::string error;
    gridFromBounds({b[0] - 0.5, b[1] - 0.5, b[2] - 0.5, b[3] + 0.5, b[4] + 0.5, b[5] + 0.5}, res,
                   0.0, grid, error);
    FunctionField analytic(
        [](const Vec3& p, double) {
            return Vec3{std::sin(p[0]), std::cos(p[1]) * p[2], p[0] * p[1]};
        },
        "analytic");
    std::vector<float> values;
    sampleGrid(analytic, grid, SampleTime{}, values);
    const std::string dir0 = (std::filesystem::temp_directory_path() / "gale_bench_geometry").string();
    std::filesystem::create_directories(dir0);
    writeVdbVelocity(dir0 + "/vel.vdb", grid, values);
    std::filesystem::copy_file(bodyPath, dir0 + "/body.obj",
                               std::filesystem::copy_options::overwrite_existing);
    std::shared_ptr<const VelocityVolume> vol;
    VelocityVolume::load(dir0 + "/vel.vdb", "vel", vol);

    struct Case {
        const char* name;
        std::function<void(size_t, size_t)> direct;
        std::string expr;
    };
    const std::vector<Case> cases = {
        {"sdf (distance)", [&](size_t a, size_t c) { sdf->sample(&xyz[3 * a], c, &out[a], nullptr); },
         "sdf(\"body.obj\", $P)"},
        {"sdfgrad (6 more lookups)",
         [&](size_t a, size_t c) { sdf->sample(&xyz[3 * a], c, nullptr, &out[3 * a]); },
         "sdfgrad(\"body.obj\", $P)"},
        {"shadow (L = 1.2 m)",
         [&](size_t a, size_t c) { sdf->shadow(&xyz[3 * a], &dir[3 * a], &len[a], c, &out[a]); },
         "shadow(\"body.obj\", $P, [0.15, 0, -1], 1.2)"},
        {"vdb trilinear (128^3)",
         [&](size_t a, size_t c) { vol->sample(&xyz[3 * a], c, VolumeInterp::Trilinear, &out[3 * a]); },
         "vdb(\"vel.vdb\", \"vel\", $P)"},
        {"vdb quadratic",
         [&](size_t a, size_t c) { vol->sample(&xyz[3 * a], c, VolumeInterp::Quadratic, &out[3 * a]); },
         "vdb(\"vel.vdb\", \"vel\", $P, 2)"},
    };
    std::printf("## Sampling ns/point (body SDF at 0.02 m; points in its box + 0.5 m: %zu random, "
                "%zu on a grid in x-slowest order)\n\n", n, m);
    std::printf("| query | direct random 1 thread | direct grid 1 thread | direct grid %d threads | "
                "VM f32 grid 1 thread | VM f32 grid %d threads |\n", hw, hw);
    std::printf("|---|---:|---:|---:|---:|---:|\n");
    for (const Case& c : cases) {
        xyz = random.data();
        const double r1 = bestSeconds(3, [&] { parallelBatches(n, 1, c.direct); });
        xyz = ordered.data();
        const double g1 = bestSeconds(3, [&] { parallelBatches(m, 1, c.direct); });
        const double gn = bestSeconds(3, [&] { parallelBatches(m, hw, c.direct); });
        auto field = compileIn(dir0, c.expr);
        std::vector<double> v(3 * m);
        SampleTime when;
        when.threads = 1;
        field->sample(xyz, m, when, v.data()); // build outside the timing
        const double e1 = bestSeconds(3, [&] { field->sample(xyz, m, when, v.data()); });
        when.threads = 0;
        const double en = bestSeconds(3, [&] { field->sample(xyz, m, when, v.data()); });
        std::printf("| %s | %.1f | %.1f | %.1f | %.1f | %.1f |\n", c.name, 1e9 * r1 / n,
                    1e9 * g1 / m, 1e9 * gn / m, 1e9 * e1 / m, 1e9 * en / m);
    }
    std::printf("\n(vdb: %zu cells, voxel %.4f m, %.1f MiB)\n", grid.cellCount(), grid.voxel[0],
                vol->memoryBytes() / 1048576.0);
    std::error_code ec;
    std::filesystem::remove_all(dir0, ec);
    return 0;
}
