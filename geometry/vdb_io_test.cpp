// Tests for the .vdb velocity files: a written grid read back has the same values, voxel size,
// origin, name, vector type and box (uniform regions included); errors for missing files,
// missing grids and wrong value counts.
#include "geometry/vdb_io.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace gale::geometry;
using namespace gale::io;

namespace {

using gale::io::test::TempDir;

// Values derived from the cell index (not from any sampling code): distinct per cell and
// component, with a zero region (cells with i == 0) and a constant region (i == nx-1).
std::vector<float> patternValues(const GridSpec& g) {
    std::vector<float> v;
    for (int i = 0; i < g.res[0]; ++i)
        for (int j = 0; j < g.res[1]; ++j)
            for (int k = 0; k < g.res[2]; ++k) {
                if (i == 0) {
                    v.insert(v.end(), {0.0f, 0.0f, 0.0f});
                } else if (i == g.res[0] - 1) {
                    v.insert(v.end(), {1.5f, -2.0f, 0.25f});
                } else {
                    v.push_back(static_cast<float>(i) + 0.125f * static_cast<float>(j));
                    v.push_back(-static_cast<float>(k) * 0.5f);
                    v.push_back(static_cast<float>(i * 10000 + j * 100 + k) * 1e-3f);
                }
            }
    return v;
}

} // namespace

TEST_CASE("a velocity grid round-trips through a .vdb file", "[vdb]") {
    TempDir dir;
    GridSpec g;
    g.origin = {-1.0, 0.5, 2.0};
    g.voxel = {0.25, 0.25, 0.25};
    g.res = {20, 9, 11}; // spans several 8^3 leaves, partly filled at the edges
    const std::vector<float> values = patternValues(g);
    VdbWriteOptions options;
    options.metadata["gale_source"] = "wind.se";
    options.floatMetadata["gale_time"] = 0.5;
    const std::string path = dir.file("wind.vdb");
    IoError e = writeVdbVelocity(path, g, values, options);
    REQUIRE_FALSE(e);

    // No temporary file left behind.
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path)) {
        (void)entry;
        ++files;
    }
    CHECK(files == 1);

    VdbVelocity r;
    e = readVdbVelocity(path, "vel", r);
    if (e) FAIL(e.render());
    CHECK(r.gridName == "vel");
    CHECK(r.vectorType == "contravariant-relative");
    CHECK(r.gridClass == "unknown");
    CHECK(r.uniformScale);
    CHECK(r.indexMin == std::vector<int>{0, 0, 0});
    CHECK(r.grid.res == g.res); // the zero and constant regions stay active
    for (int a = 0; a < 3; ++a) {
        CHECK(r.grid.voxel[static_cast<size_t>(a)] == Approx(0.25).epsilon(1e-12));
        CHECK(r.grid.origin[static_cast<size_t>(a)] ==
              Approx(g.origin[static_cast<size_t>(a)]).margin(1e-12));
    }
    REQUIRE(r.values.size() == values.size());
    CHECK(r.values == values);
    CHECK(r.metadata["gale_source"] == "wind.se");
    CHECK(std::stod(r.metadata["gale_time"]) == 0.5);

    // The first Vec3s grid when no name is given.
    VdbVelocity any;
    REQUIRE_FALSE(readVdbVelocity(path, "", any));
    CHECK(any.gridName == "vel");
}

TEST_CASE("non-cubic voxels and a uniform grid", "[vdb]") {
    TempDir dir;
    GridSpec g;
    g.origin = {0.0, 0.0, 0.0};
    g.voxel = {0.5, 1.0, 2.0};
    g.res = {3, 4, 5};
    // A uniform wind: stored as tiles, read back as every cell.
    std::vector<float> values;
    for (size_t i = 0; i < g.cellCount(); ++i) values.insert(values.end(), {3.0f, 0.0f, -1.0f});
    const std::string path = dir.file("u.vdb");
    REQUIRE_FALSE(writeVdbVelocity(path, g, values));
    VdbVelocity r;
    REQUIRE_FALSE(readVdbVelocity(path, "vel", r));
    CHECK_FALSE(r.uniformScale);
    CHECK(r.grid.res == g.res);
    CHECK(r.grid.voxel[0] == Approx(0.5));
    CHECK(r.grid.voxel[1] == Approx(1.0));
    CHECK(r.grid.voxel[2] == Approx(2.0));
    for (int a = 0; a < 3; ++a)
        CHECK(r.grid.origin[static_cast<size_t>(a)] == Approx(0.0).margin(1e-12));
    CHECK(r.values == values);

    // An all-zero grid keeps its box too.
    std::vector<float> zeros(values.size(), 0.0f);
    REQUIRE_FALSE(writeVdbVelocity(path, g, zeros));
    REQUIRE_FALSE(readVdbVelocity(path, "vel", r));
    CHECK(r.grid.res == g.res);
    CHECK(r.values == zeros);
}

TEST_CASE("vdb errors", "[vdb]") {
    TempDir dir;
    GridSpec g;
    g.res = {2, 2, 2};
    std::vector<float> values(24, 1.0f);
    VdbVelocity r;
    CHECK(readVdbVelocity(dir.file("missing.vdb"), "vel", r).kind == IoError::Io);
    { std::ofstream(dir.file("junk.vdb")) << "not a vdb file"; }
    CHECK(readVdbVelocity(dir.file("junk.vdb"), "vel", r).kind == IoError::Io);

    REQUIRE_FALSE(writeVdbVelocity(dir.file("v.vdb"), g, values));
    IoError e = readVdbVelocity(dir.file("v.vdb"), "density", r);
    CHECK(e.kind == IoError::Data);
    CHECK(e.message.find("density") != std::string::npos);

    CHECK(writeVdbVelocity(dir.file("w.vdb"), g, std::vector<float>(5)).kind == IoError::Data);
    e = writeVdbVelocity(dir.file("no/such/dir/v.vdb"), g, values);
    CHECK(e.kind == IoError::Io);
    CHECK_FALSE(std::filesystem::exists(dir.file("w.vdb")));
}
