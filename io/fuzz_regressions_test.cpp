// Regressions found by the libFuzzer harnesses (fuzz/, docs/fuzzing.md) in the field layer's
// readers and scene loader: each case is an input that once crashed or broke a property.
#include "io/pointset.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

using namespace gale::io;

namespace {

// Writes `text` to a fresh file named `name` in a private temp folder; returns its path.
struct TempFile {
    std::filesystem::path dir, path;
    TempFile(const std::string& name, const std::string& text) {
        dir =
            std::filesystem::temp_directory_path() / ("gale_fuzz_reg_" + std::to_string(getpid()));
        std::filesystem::create_directories(dir);
        path = dir / name;
        std::ofstream(path, std::ios::binary) << text;
    }
    ~TempFile() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
};

} // namespace

// fuzz_readers: an OBJ face naming a vertex that does not exist was kept, so the point set
// was written as a PLY that the PLY reader (rightly) rejects. Now the OBJ reader rejects it.
TEST_CASE("OBJ faces must name existing vertices, like PLY faces", "[fuzz][pointset][obj]") {
    {
        TempFile f("bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 4\n");
        PointSet ps;
        IoError e = readPointsObj(f.path.string(), ps);
        REQUIRE(e);
        CHECK(e.kind == IoError::Data);
        CHECK(e.message.find("face 2 refers to vertex 4") != std::string::npos);
    }
    {
        TempFile f("relative.obj", "v 0 0 1\nf -1 -2 -3\n"); // -2, -3: before the first vertex
        PointSet ps;
        CHECK(readPointsObj(f.path.string(), ps));
    }
    {
        // Valid relative indices still read, and the set survives a binary PLY round trip.
        TempFile f("good.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf -1 -2 -3\n");
        PointSet ps;
        IoError e = readPointsObj(f.path.string(), ps);
        INFO(e.render());
        REQUIRE(!e);
        REQUIRE(ps.faces.size() == 2);
        CHECK(ps.faces[1] == std::vector<int>{3, 2, 1});
        std::stringstream ply;
        REQUIRE(!writePoints(ply, ps, PointFormat::Ply));
        PointSet back;
        IoError r = readPointsPly(ply, "back.ply", back);
        INFO(r.render());
        REQUIRE(!r);
        CHECK(back.size() == 4);
        CHECK(back.faces == ps.faces);
    }
}

// fuzz_readers: CSV columns "a b" and "a_b" were both written to PLY as property "a_b" (a PLY
// name has no spaces), and the PLY reader rejects a property declared twice. Now the second
// one is "a_b_2"; control characters in names are replaced too.
TEST_CASE("PLY property names are made unique and free of spaces and controls",
          "[fuzz][pointset][ply]") {
    std::istringstream csv("a b,a_b,c\td\n1,2,3\n");
    PointSet ps;
    IoError e = readPointsCsv(csv, "names.csv", ps);
    INFO(e.render());
    REQUIRE(!e);
    REQUIRE(ps.names.size() == 3);
    for (PointFormat format : {PointFormat::Ply, PointFormat::PlyAscii}) {
        std::stringstream ply;
        REQUIRE(!writePoints(ply, ps, format));
        PointSet back;
        IoError r = readPointsPly(ply, "names.ply", back);
        INFO(r.render());
        REQUIRE(!r);
        CHECK(back.names == std::vector<std::string>{"a_b", "a_b_2", "c_d"});
        REQUIRE(back.size() == 1);
        CHECK(back.columns[2][0] == 3);
    }
}

// fuzz_readers: an element declared with a huge count and no properties was walked one
// (empty) element at a time, 4.8e18 of them: a hang. It holds no bytes; the elements after it
// read as written.
TEST_CASE("a PLY element without properties holds no data, whatever its count",
          "[fuzz][pointset][ply]") {
    for (const char* format : {"ascii", "binary_little_endian"}) {
        std::string text = std::string("ply\nformat ") + format +
                           " 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement marker 4766666666666666666\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
        const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        if (std::string(format) == "ascii") {
            text += "0 0 0\n1 0 0\n0 1 0\n3 2 1 0\n";
        } else {
            text.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
            const unsigned char n = 3;
            const int idx[3] = {2, 1, 0};
            text.append(reinterpret_cast<const char*>(&n), 1);
            text.append(reinterpret_cast<const char*>(idx), sizeof idx);
        }
        std::istringstream in(text);
        PointSet ps;
        IoError e = readPointsPly(in, "marker.ply", ps);
        INFO(format << ": " << e.render());
        REQUIRE(!e);
        REQUIRE(ps.size() == 3);
        CHECK(ps.columns[1][2] == 1);
        REQUIRE(ps.faces.size() == 1);
        CHECK(ps.faces[0] == std::vector<int>{2, 1, 0});
    }
}

// fuzz_readers: a face list's length was trusted before its items were read: a binary list of
// length 7e8 in a file of a few bytes reserved 2.9 GB (libFuzzer's out-of-memory in CI). A list
// cannot hold more items than the bytes left; the error names the element and the property.
TEST_CASE("a PLY list longer than the file is an error before anything is allocated",
          "[fuzz][pointset][ply]") {
    for (const char* format : {"ascii", "binary_little_endian"}) {
        std::string text = std::string("ply\nformat ") + format +
                           " 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 1\n"
                           "property list uint int vertex_indices\nend_header\n";
        const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        if (std::string(format) == "ascii") {
            text += "0 0 0\n1 0 0\n0 1 0\n717818799 2 1 0\n";
        } else {
            text.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
            const unsigned n = 717818799u;
            const int idx[3] = {2, 1, 0};
            text.append(reinterpret_cast<const char*>(&n), sizeof n);
            text.append(reinterpret_cast<const char*>(idx), sizeof idx);
        }
        std::istringstream in(text);
        PointSet ps;
        IoError e = readPointsPly(in, "long_list.ply", ps);
        INFO(format << ": " << e.render());
        REQUIRE(e);
        CHECK(e.render().find("list length 717818799 in face 0") != std::string::npos);
        CHECK(e.render().find("more than the file holds") != std::string::npos);
    }
    // A list as long as its items still reads.
    std::string ok = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 1\n"
                     "property list uint int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0\n0 1 0\n3 2 1 0";
    std::istringstream in(ok);
    PointSet ps;
    IoError e = readPointsPly(in, "ok.ply", ps);
    INFO(e.render());
    REQUIRE(!e);
    REQUIRE(ps.faces.size() == 1);
    CHECK(ps.faces[0] == std::vector<int>{2, 1, 0});
}

// fuzz_readers: a vertex element without properties and a count of 1e10 allocated its (empty)
// columns' template, 1e10 doubles, before the count was checked against anything (ASan's
// out-of-memory). It holds no data: read as no columns, whatever its count.
TEST_CASE("a PLY vertex element without properties allocates nothing, whatever its count",
          "[fuzz][pointset][ply]") {
    for (const char* format : {"ascii", "binary_little_endian"}) {
        const std::string text =
            std::string("ply\nformat ") + format + " 1.0\nelement vertex 10455446300\nend_header\n";
        std::istringstream in(text);
        PointSet ps;
        IoError e = readPointsPly(in, "no_properties.ply", ps);
        INFO(format << ": " << e.render());
        CHECK(ps.columns.empty());
        CHECK(ps.size() == 0);
    }
}
