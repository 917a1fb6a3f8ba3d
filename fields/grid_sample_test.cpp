// Tests for grid sampling: geometry from bounds, cell-centred values of an analytic field
// (independent of threads and batch size), non-finite counting, the .npy and .csv grid
// writers, atomic files and frame-numbered names.
#include "io/test_support.h"
#include "fields/grid_sample.h"

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>

using namespace gale::fields;
using namespace gale::io;

namespace {

// v = (x, 2y, -z) + t * (1, 0, 0): written out here rather than through FunctionField so the
// test depends only on the Field interface.
class AnalyticField : public Field {
public:
    SampleStatus sample(const double* p, size_t count, const SampleTime& when,
                        double* v) const override {
        mCalls.fetch_add(1);
        for (size_t i = 0; i < count; ++i) {
            v[3 * i] = p[3 * i] + when.time;
            v[3 * i + 1] = 2.0 * p[3 * i + 1];
            v[3 * i + 2] = -p[3 * i + 2];
        }
        return {};
    }
    std::string describe() const override { return "analytic"; }
    mutable std::atomic<int> mCalls{0};
};

// Huge (finite in double, infinite in float) where x > 0; reports NaN (zeroed, counted, as
// the Field contract asks) where y > 0.5.
class BadField : public Field {
public:
    SampleStatus sample(const double* p, size_t count, const SampleTime&,
                        double* v) const override {
        SampleStatus s;
        for (size_t i = 0; i < count; ++i) {
            const bool nan = p[3 * i + 1] > 0.5;
            const double x = p[3 * i] > 0 ? 1e39 : 1.0;
            v[3 * i] = nan ? 0.0 : x;
            v[3 * i + 1] = v[3 * i + 2] = 0.0;
            if (nan) ++s.nonFinite;
        }
        return s;
    }
    std::string describe() const override { return "bad"; }
};

using gale::io::test::TempDir;

float readFloatLE(const std::string& bytes, size_t at) {
    uint32_t u = 0;
    for (int b = 0; b < 4; ++b)
        u |= static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + static_cast<size_t>(b)]))
             << (8 * b);
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}

GridSpec smallGrid() {
    GridSpec g;
    std::string error;
    // 2 m x 1 m x 1 m at 0.5 m: 4 x 2 x 2 cells from (-1, 0, 2).
    REQUIRE(gridFromBounds({-1, 0, 2, 1, 1, 3}, {}, 0.5, g, error));
    return g;
}

} // namespace

TEST_CASE("grid geometry from bounds and resolution", "[grid]") {
    GridSpec g;
    std::string error;
    REQUIRE(gridFromBounds({0, 0, 0, 4, 2, 1}, {4}, 0.0, g, error));
    CHECK(g.res == std::array<int, 3>{4, 2, 1});
    CHECK(g.voxel == std::array<double, 3>{1.0, 1.0, 1.0});
    CHECK(g.origin == std::array<double, 3>{0.0, 0.0, 0.0});
    CHECK(g.cellCount() == 8);

    // 1 / 0.1 is 10 cells even though 1.0 / 0.1 rounds above 10 in double.
    REQUIRE(gridFromBounds({0, 0, 0, 1, 1, 1}, {}, 0.1, g, error));
    CHECK(g.res == std::array<int, 3>{10, 10, 10});
    // 1 / 0.3: four cells reaching to 1.2.
    REQUIRE(gridFromBounds({0, -1, 5, 1, 0, 5.5}, {}, 0.3, g, error));
    CHECK(g.res == std::array<int, 3>{4, 4, 2});
    CHECK(g.origin == std::array<double, 3>{0.0, -1.0, 5.0});

    // Three counts: exactly those, per-axis voxel size.
    REQUIRE(gridFromBounds({0, 0, 0, 1, 2, 4}, {2, 4, 2}, 0.0, g, error));
    CHECK(g.res == std::array<int, 3>{2, 4, 2});
    CHECK(g.voxel == std::array<double, 3>{0.5, 0.5, 2.0});
    CHECK_FALSE(g.cubicVoxels());

    // --res N on a box whose longest side is y.
    REQUIRE(gridFromBounds({0, 0, 0, 1, 8, 2}, {16}, 0.0, g, error));
    CHECK(g.res == std::array<int, 3>{2, 16, 4});
    CHECK(g.cubicVoxels());

    CHECK_FALSE(gridFromBounds({0, 0, 0, 0, 1, 1}, {4}, 0.0, g, error));
    CHECK(error.find("along x") != std::string::npos);
    CHECK_FALSE(gridFromBounds({0, 0, 0, 1, 1, 1}, {0}, 0.0, g, error));
    CHECK_FALSE(gridFromBounds({0, 0, 0, 1, 1, 1}, {}, -1.0, g, error));
    CHECK_FALSE(gridFromBounds({0, 0, 0, 1, 1, 1}, {2, 2}, 0.0, g, error));
    CHECK_FALSE(gridFromBounds({0, 0, 0, 1, 1, 1}, {}, 1e-4, g, error));
    CHECK(error.find("limit") != std::string::npos);
}

TEST_CASE("an analytic field sampled at the cell centres", "[grid]") {
    const GridSpec g = smallGrid();
    REQUIRE(g.res == std::array<int, 3>{4, 2, 2});
    AnalyticField field;
    SampleTime when;
    when.time = 0.25;
    std::vector<float> values;
    SampleStatus s = sampleGrid(field, g, when, values);
    REQUIRE(s.ok);
    CHECK(s.nonFinite == 0);
    REQUIRE(values.size() == 4 * 2 * 2 * 3);
    // Centres: x = -0.75, -0.25, 0.25, 0.75; y = 0.25, 0.75; z = 2.25, 2.75; x slowest.
    const double xs[] = {-0.75, -0.25, 0.25, 0.75}, ys[] = {0.25, 0.75}, zs[] = {2.25, 2.75};
    size_t n = 0;
    for (double x : xs)
        for (double y : ys)
            for (double z : zs) {
                CHECK(values[n++] == static_cast<float>(x + 0.25));
                CHECK(values[n++] == static_cast<float>(2 * y));
                CHECK(values[n++] == static_cast<float>(-z));
            }

    // The same bits whatever the threads and batch size.
    for (int threads : {1, 2, 3})
        for (size_t batch : {size_t(1), size_t(5), size_t(4096)}) {
            GridSampleOptions o;
            o.threads = threads;
            o.batch = batch;
            std::vector<float> again;
            REQUIRE(sampleGrid(field, g, when, again, o).ok);
            CHECK(again == values);
        }

    // Batches: 16 cells in batches of 5 is 4 calls; progress reaches the total.
    AnalyticField counted;
    GridSampleOptions o;
    o.batch = 5;
    size_t lastDone = 0, lastTotal = 0;
    o.progress = [&](size_t done, size_t total) {
        CHECK(done >= lastDone);
        lastDone = done;
        lastTotal = total;
    };
    std::vector<float> again;
    REQUIRE(sampleGrid(counted, g, when, again, o).ok);
    CHECK(counted.mCalls.load() == 4);
    CHECK(lastDone == 16);
    CHECK(lastTotal == 16);
}

TEST_CASE("samplePoints at arbitrary points", "[grid]") {
    AnalyticField field;
    std::vector<double> p = {1, 2, 3, -4, 0.5, 0, 7, 7, 7};
    std::vector<double> v(9, -1.0);
    GridSampleOptions o;
    o.batch = 2;
    REQUIRE(samplePoints(field, p.data(), 3, SampleTime{}, v.data(), o).ok);
    CHECK(v == std::vector<double>{1, 4, -3, -4, 1, 0, 7, 14, -7});
}

TEST_CASE("non-finite velocities are zeroed and counted", "[grid]") {
    GridSpec g;
    std::string error;
    // x centres -0.5, 0.5; y centres 0.25, 0.75; one z cell.
    REQUIRE(gridFromBounds({-1, 0, 0, 1, 1, 0.5}, {2, 2, 1}, 0.0, g, error));
    BadField field;
    std::vector<float> values;
    SampleStatus s = sampleGrid(field, g, SampleTime{}, values);
    // (x>0) overflows float at y=0.25; y=0.75 is NaN (already zeroed) for both x.
    CHECK(s.nonFinite == 3);
    CHECK(values[3 * g.index(0, 0, 0)] == 1.0f);
    CHECK(values[3 * g.index(1, 0, 0)] == 0.0f);
    CHECK(values[3 * g.index(1, 1, 0)] == 0.0f);
}

TEST_CASE("npy grid: header, shape and float32 data in x-slowest order", "[grid]") {
    const GridSpec g = smallGrid();
    AnalyticField field;
    std::vector<float> values;
    REQUIRE(sampleGrid(field, g, SampleTime{}, values).ok);
    std::ostringstream out;
    REQUIRE_FALSE(writeGridNpy(out, g, values));
    const std::string bytes = out.str();
    REQUIRE(bytes.size() > 10);
    CHECK(bytes.compare(0, 8, std::string("\x93NUMPY\x01\x00", 8)) == 0);
    const size_t headerLength =
        static_cast<unsigned char>(bytes[8]) + 256u * static_cast<unsigned char>(bytes[9]);
    const size_t dataStart = 10 + headerLength;
    CHECK(dataStart % 64 == 0);
    const std::string header = bytes.substr(10, headerLength);
    CHECK(header.find("'descr': '<f4'") != std::string::npos);
    CHECK(header.find("'fortran_order': False") != std::string::npos);
    CHECK(header.find("'shape': (4, 2, 2, 3)") != std::string::npos);
    CHECK(header.back() == '\n');
    REQUIRE(bytes.size() == dataStart + 4 * 48);
    // Element [i][j][k][c] at ((i*2 + j)*2 + k)*3 + c: cell (2,1,0) is x=0.25, y=0.75, z=2.25.
    const size_t cell = (2 * 2 + 1) * 2 + 0;
    CHECK(readFloatLE(bytes, dataStart + 4 * (3 * cell + 0)) == 0.25f);
    CHECK(readFloatLE(bytes, dataStart + 4 * (3 * cell + 1)) == 1.5f);
    CHECK(readFloatLE(bytes, dataStart + 4 * (3 * cell + 2)) == -2.25f);
    // Wrong value count.
    std::vector<float> shortValues(5);
    std::ostringstream sink;
    CHECK(writeGridNpy(sink, g, shortValues).kind == IoError::Data);
}

TEST_CASE("csv grid: centres and shortest float text", "[grid]") {
    GridSpec g;
    std::string error;
    REQUIRE(gridFromBounds({0, 0, 0, 0.2, 0.1, 0.1}, {}, 0.1, g, error));
    REQUIRE(g.res == std::array<int, 3>{2, 1, 1});
    AnalyticField field;
    std::vector<float> values;
    REQUIRE(sampleGrid(field, g, SampleTime{}, values).ok);
    std::ostringstream out;
    REQUIRE_FALSE(writeGridCsv(out, g, values));
    // Centres 0.05 and 0.15000000000000002 (0 + 1.5 * 0.1 in double); the velocities are the
    // float values printed as floats.
    CHECK(out.str() == "x,y,z,vx,vy,vz\n"
                       "0.05,0.05,0.05,0.05,0.1,-0.05\n"
                       "0.15000000000000002,0.05,0.05,0.15,0.1,-0.05\n");
}

TEST_CASE("grid files are written atomically", "[grid]") {
    TempDir dir;
    const GridSpec g = smallGrid();
    AnalyticField field;
    std::vector<float> values;
    REQUIRE(sampleGrid(field, g, SampleTime{}, values).ok);
    const std::string path = (dir.path / "v.npy").string();
    REQUIRE_FALSE(writeGridFile(path, GridFormat::Npy, g, values));
    CHECK(std::filesystem::file_size(path) == 128 + 4 * 48);
    const std::string csv = (dir.path / "v.csv").string();
    REQUIRE_FALSE(writeGridFile(csv, GridFormat::Csv, g, values));
    // Only the two files: no temporaries left behind.
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path)) {
        (void)entry;
        ++files;
    }
    CHECK(files == 2);

    IoError e =
        writeGridFile((dir.path / "no" / "such" / "v.npy").string(), GridFormat::Npy, g, values);
    CHECK(e.kind == IoError::Io);
    CHECK(e.file == (dir.path / "no" / "such" / "v.npy").string());

    // A failing writer leaves the old file untouched and removes its temporary.
    e = writeFileAtomic(path, [](const std::string& tmp) {
        std::ofstream(tmp) << "partial";
        IoError bad;
        bad.kind = IoError::Io;
        bad.message = "disk full";
        return bad;
    });
    CHECK(e.kind == IoError::Io);
    CHECK(std::filesystem::file_size(path) == 128 + 4 * 48);
    files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path)) {
        (void)entry;
        ++files;
    }
    CHECK(files == 2);
}

TEST_CASE("atomic writes follow links and leave pipes in place", "[grid]") {
    TempDir dir;
    const GridSpec g = smallGrid();
    AnalyticField field;
    std::vector<float> values;
    REQUIRE(sampleGrid(field, g, SampleTime{}, values).ok);

    // A symbolic link stays a link; the file it points to gets the data.
    const std::filesystem::path target = dir.path / "target.npy", link = dir.path / "link.npy";
    std::ofstream(target) << "old";
    std::filesystem::create_symlink(target, link);
    REQUIRE_FALSE(writeGridFile(link.string(), GridFormat::Npy, g, values));
    CHECK(std::filesystem::is_symlink(std::filesystem::symlink_status(link)));
    CHECK(std::filesystem::file_size(target) == 128 + 4 * 48);

    // A FIFO is written through, not replaced by a regular file.
    const std::filesystem::path fifo = dir.path / "pipe.npy";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    std::string received;
    std::thread reader([&] {
        std::ifstream in(fifo, std::ios::binary);
        received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    });
    IoError e = writeGridFile(fifo.string(), GridFormat::Npy, g, values);
    reader.join();
    CHECK_FALSE(e);
    CHECK(received.size() == 128 + 4 * 48);
    CHECK(std::filesystem::is_fifo(fifo));

    // A folder is an error.
    e = writeGridFile(dir.path.string(), GridFormat::Npy, g, values);
    CHECK(e.kind == IoError::Io);
}

TEST_CASE("grid formats from file names", "[grid]") {
    GridFormat f;
    REQUIRE(gridFormatFromPath("a/wind.VDB", f));
    CHECK(f == GridFormat::Vdb);
    REQUIRE(gridFormatFromPath("w.0001.npy", f));
    CHECK(f == GridFormat::Npy);
    REQUIRE(gridFormatFromPath("w.csv", f));
    CHECK(f == GridFormat::Csv);
    CHECK_FALSE(gridFormatFromPath("w.ply", f));
    CHECK_FALSE(gridFormatFromPath("dir.vdb/w", f));
}

TEST_CASE("frame-numbered file names", "[grid]") {
    std::string out;
    REQUIRE(framePath("wind.#.vdb", 12, out));
    CHECK(out == "wind.0012.vdb");
    REQUIRE(framePath("v.##.npy", 7, out));
    CHECK(out == "v.07.npy");
    REQUIRE(framePath("v.##.npy", 123, out));
    CHECK(out == "v.123.npy");
    REQUIRE(framePath("out/f######", 5, out));
    CHECK(out == "out/f000005");
    REQUIRE(framePath("w#.csv", -3, out));
    CHECK(out == "w-0003.csv");
    CHECK_FALSE(framePath("wind.vdb", 1, out));
    CHECK_FALSE(framePath("a#b#.vdb", 1, out));
}
