// Tests for point-set I/O: round trips through every format, arbitrary and big-endian PLY,
// faces, malformed files reported at the right line, number formatting, host variables.
#include "io/pointset.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <unistd.h>

using namespace gale::io;

namespace {

PointSet readCsvText(const std::string& text, IoError* err = nullptr) {
    std::istringstream in(text);
    PointSet ps;
    IoError e = readPointsCsv(in, "t.csv", ps);
    if (err)
        *err = e;
    else
        REQUIRE_FALSE(e);
    return ps;
}

PointSet readPlyText(const std::string& text, IoError* err = nullptr) {
    std::istringstream in(text);
    PointSet ps;
    IoError e = readPointsPly(in, "t.ply", ps);
    if (err)
        *err = e;
    else if (e)
        FAIL(e.render());
    return ps;
}

std::string write(const PointSet& ps, PointFormat f, const std::vector<int>& npy = {}) {
    std::ostringstream out;
    IoError e = writePoints(out, ps, f, npy);
    REQUIRE_FALSE(e);
    return out.str();
}

PointSet sample() {
    PointSet ps;
    ps.names = {"x", "y", "z", "u"};
    ps.columns = {{0, 1.5, -2}, {0.25, 2, 3}, {1, -0.5, 4}, {7, 8, 9}};
    ps.faces = {{0, 1, 2}};
    return ps;
}

// A temporary folder removed at the end of the test.
using test::TempDir;

template <class T>
void putBE(std::string& s, T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    // Assumes a little-endian host (x86-64, arm64): reverse for big-endian.
    for (size_t i = sizeof(T); i-- > 0;) s += static_cast<char>(b[i]);
}
template <class T>
void putLE(std::string& s, T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    for (size_t i = 0; i < sizeof(T); ++i) s += static_cast<char>(b[i]);
}

} // namespace

TEST_CASE("formatNumber gives the shortest round-trip text", "[pointset]") {
    CHECK(formatNumber(7) == "7");
    CHECK(formatNumber(0) == "0");
    CHECK(formatNumber(-0.0) == "-0");
    CHECK(formatNumber(0.1) == "0.1");
    CHECK(formatNumber(1e-7) == "1e-07");
    CHECK(formatNumber(-2.5) == "-2.5");
    CHECK(formatNumber(std::nan("")) == "nan");
    CHECK(formatNumber(-std::nan("")) == "nan");
    CHECK(formatNumber(std::numeric_limits<double>::infinity()) == "inf");
    CHECK(formatNumber(-std::numeric_limits<double>::infinity()) == "-inf");
    double third = 1.0 / 3.0;
    CHECK(std::stod(formatNumber(third)) == third);
    double x = 0.1 + 0.2;
    CHECK(std::stod(formatNumber(x)) == x);
    CHECK(formatNumber(1e300) == "1e+300");
}

TEST_CASE("CSV: header, rows, comments, blank lines, CRLF", "[pointset][csv]") {
    PointSet ps = readCsvText(
        "# a comment\r\nx, y ,z,u\r\n\r\n1,2,3,4\r\n  # indented comment\n+5,-6e1,.5,nan\n");
    REQUIRE(ps.names == std::vector<std::string>{"x", "y", "z", "u"});
    REQUIRE(ps.size() == 2);
    CHECK(ps.columns[0] == std::vector<double>{1, 5});
    CHECK(ps.columns[1] == std::vector<double>{2, -60});
    CHECK(ps.columns[2][1] == 0.5);
    CHECK(std::isnan(ps.columns[3][1]));
    CHECK(ps.find("u") == 3);
    CHECK(ps.find("w") == -1);
}

TEST_CASE("CSV: errors name line and column", "[pointset][csv]") {
    IoError e;
    readCsvText("x,y,z\n1,2,3\n4,abc,6\n", &e);
    REQUIRE(e);
    CHECK(e.kind == IoError::Data);
    CHECK(e.line == 3);
    CHECK(e.col == 3);
    CHECK(e.render() == "t.csv:3:3: error: expected a number, found 'abc'");

    readCsvText("x,y,z,u\n\n1,2,3\n", &e);
    REQUIRE(e);
    CHECK(e.line == 3);
    CHECK(e.message.find("row has 3 fields") != std::string::npos);
    CHECK(e.message.find("has 4") != std::string::npos);

    readCsvText("x,y,z\n1,2,\n", &e);
    REQUIRE(e);
    CHECK(e.line == 2);
    CHECK(e.col == 5);

    readCsvText("1,2,3\n", &e);
    REQUIRE(e);
    CHECK(e.line == 1);
    CHECK(e.message.find("header") != std::string::npos);

    readCsvText("x,y,x\n", &e);
    REQUIRE(e);
    CHECK(e.message.find("duplicate") != std::string::npos);

    readCsvText("\n# nothing\n", &e);
    REQUIRE(e);
    CHECK(e.message.find("header") != std::string::npos);

    readCsvText("x,y,z\n1e999,0,0\n", &e);
    REQUIRE(e);
    CHECK(e.message.find("out of range") != std::string::npos);
}

TEST_CASE("CSV round trip keeps every double exactly", "[pointset][csv]") {
    PointSet ps = sample();
    ps.columns[3] = {1.0 / 3.0, 1e-7, -0.0};
    PointSet back = readCsvText(write(ps, PointFormat::Csv));
    CHECK(back.names == ps.names);
    CHECK(back.columns == ps.columns);
    CHECK(std::signbit(back.columns[3][2]));
    CHECK(write(sample(), PointFormat::Csv).substr(0, 18) == "x,y,z,u\n0,0.25,1,7");
}

TEST_CASE("CSV in chunks: the rows, errors and output of the whole-file path", "[pointset][csv]") {
    // 10 rows with a comment and a blank line among them, read 3 rows at a time.
    std::string text = "# points\nx,y,z\n";
    for (int i = 0; i < 10; ++i) {
        text += std::to_string(i) + ",0.5," + std::to_string(-i) + "\n";
        if (i == 4) text += "\n# middle\n";
    }
    PointSet whole;
    {
        std::istringstream in(text);
        REQUIRE_FALSE(readPointsCsv(in, "p.csv", whole));
    }
    std::istringstream in(text);
    CsvPointReader reader(in, "p.csv");
    PointSet header, chunk;
    REQUIRE_FALSE(reader.readHeader(header));
    CHECK(header.names == std::vector<std::string>{"x", "y", "z"});
    CHECK(header.size() == 0);
    std::ostringstream streamed;
    std::vector<size_t> sizes;
    for (bool first = true;; first = false) {
        REQUIRE_FALSE(reader.readRows(chunk, 3));
        if (chunk.size() == 0) break;
        sizes.push_back(chunk.size());
        CHECK(chunk.columns[0][0] == static_cast<double>(3 * (sizes.size() - 1)));
        chunk.addColumn("extra"); // dropped again by the next readRows
        chunk.float32.assign(chunk.names.size(), true);
        REQUIRE_FALSE(writePointsCsv(streamed, chunk, first));
    }
    CHECK(sizes == std::vector<size_t>{3, 3, 3, 1});
    PointSet expected = whole;
    expected.addColumn("extra");
    expected.float32.assign(expected.names.size(), true);
    std::ostringstream once;
    REQUIRE_FALSE(writePoints(once, expected, PointFormat::Csv));
    CHECK(streamed.str() == once.str());

    // A bad row in a later chunk is reported at its line of the whole file.
    std::istringstream bad("x,y,z\n1,2,3\n4,5,6\n7,8,9\n1,oops,3\n");
    CsvPointReader badReader(bad, "b.csv");
    REQUIRE_FALSE(badReader.readHeader(header));
    REQUIRE_FALSE(badReader.readRows(chunk, 2));
    CHECK(chunk.size() == 2);
    IoError e = badReader.readRows(chunk, 2);
    REQUIRE(e);
    CHECK(e.render() == "b.csv:5:3: error: expected a number, found 'oops'");
}

TEST_CASE("float32 columns print as the shortest float", "[pointset]") {
    PointSet ps;
    ps.names = {"a", "b"};
    ps.columns = {{static_cast<float>(0.1)}, {static_cast<float>(0.1)}};
    ps.float32 = {true};
    CHECK(write(ps, PointFormat::Csv) == "a,b\n0.1,0.10000000149011612\n");
    int c = ps.addColumn("a");
    CHECK(c == 0);
    CHECK_FALSE(ps.isFloat32(0));
    CHECK(ps.columns[0] == std::vector<double>{0.0});
}

TEST_CASE("PLY binary and ascii round trips with faces", "[pointset][ply]") {
    PointSet ps = sample();
    for (PointFormat f : {PointFormat::Ply, PointFormat::PlyAscii}) {
        std::string text = write(ps, f);
        CHECK(text.find(f == PointFormat::Ply ? "binary_little_endian" : "format ascii") !=
              std::string::npos);
        CHECK(text.find("property float u\n") != std::string::npos);
        CHECK(text.find("property list uchar int vertex_indices") != std::string::npos);
        PointSet back = readPlyText(text);
        CHECK(back.plyBinary == (f == PointFormat::Ply));
        CHECK(back.names == ps.names);
        CHECK(back.columns == ps.columns); // all values are exact in float
        CHECK(back.faces == ps.faces);
        CHECK(back.isFloat32(0));
    }
}

TEST_CASE("PLY ascii with arbitrary properties and skipped elements", "[pointset][ply]") {
    std::string text = "ply\n"
                       "format ascii 1.0\n"
                       "comment made by hand\n"
                       "obj_info nothing\n"
                       "element vertex 2\n"
                       "property float32 x\nproperty float y\nproperty double z\n"
                       "property uchar red\nproperty short s\nproperty uint16 us\n"
                       "property list uchar int extra\n"
                       "property int8 c\n"
                       "element material 1\n"
                       "property list uint float values\nproperty int id\n"
                       "element face 2\n"
                       "property uchar flags\n"
                       "property list uchar uint vertex_index\n"
                       "end_header\n"
                       "0.1 2 3.25 255 -7 65535 2 10 11 -3\n"
                       "4 5 6 0 0 0 0 1\n"
                       "3 1.5 2.5 3.5 42\n"
                       "9 3 0 1 1\n"
                       "0 4 1 0 1 0\n";
    PointSet ps = readPlyText(text);
    CHECK_FALSE(ps.plyBinary);
    REQUIRE(ps.names == std::vector<std::string>{"x", "y", "z", "red", "s", "us", "c"});
    REQUIRE(ps.size() == 2);
    CHECK(ps.columns[0][0] == static_cast<double>(0.1f)); // float properties are float32
    CHECK(ps.columns[2][0] == 3.25);
    CHECK(ps.columns[3][0] == 255);
    CHECK(ps.columns[4][0] == -7);
    CHECK(ps.columns[5][0] == 65535);
    CHECK(ps.columns[6][0] == -3);
    CHECK(ps.columns[6][1] == 1);
    CHECK(ps.isFloat32(0));
    CHECK_FALSE(ps.isFloat32(2));
    REQUIRE(ps.faces.size() == 2);
    CHECK(ps.faces[0] == std::vector<int>{0, 1, 1});
    CHECK(ps.faces[1] == std::vector<int>{1, 0, 1, 0});
    // float32 columns print as written.
    CHECK(write(ps, PointFormat::Csv).find("\n0.1,2,3.25,255,-7,65535,-3\n") != std::string::npos);
}

TEST_CASE("PLY binary big-endian and little-endian with mixed types", "[pointset][ply]") {
    for (bool big : {true, false}) {
        std::string s = std::string("ply\nformat ") +
                        (big ? "binary_big_endian" : "binary_little_endian") +
                        " 1.0\nelement vertex 2\nproperty double x\nproperty float y\n"
                        "property int z\nproperty uchar red\nproperty ushort w\n"
                        "element edge 1\nproperty list uchar int ends\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
        auto put = [&](auto v) { big ? putBE(s, v) : putLE(s, v); };
        put(1.25);
        put(2.5f);
        put(int32_t(-3));
        put(uint8_t(200));
        put(uint16_t(60000));
        put(-0.5);
        put(0.75f);
        put(int32_t(100000));
        put(uint8_t(1));
        put(uint16_t(2));
        put(uint8_t(2));
        put(int32_t(0));
        put(int32_t(1));
        put(uint8_t(3));
        put(int32_t(1));
        put(int32_t(0));
        put(int32_t(1));
        PointSet ps = readPlyText(s);
        CHECK(ps.plyBinary);
        REQUIRE(ps.names == std::vector<std::string>{"x", "y", "z", "red", "w"});
        CHECK(ps.columns[0] == std::vector<double>{1.25, -0.5});
        CHECK(ps.columns[1] == std::vector<double>{2.5, 0.75});
        CHECK(ps.columns[2] == std::vector<double>{-3, 100000});
        CHECK(ps.columns[3] == std::vector<double>{200, 1});
        CHECK(ps.columns[4] == std::vector<double>{60000, 2});
        REQUIRE(ps.faces.size() == 1);
        CHECK(ps.faces[0] == std::vector<int>{1, 0, 1});
    }
}

TEST_CASE("PLY errors", "[pointset][ply]") {
    IoError e;
    readPlyText("plx\n", &e);
    REQUIRE(e);
    CHECK(e.line == 1);

    readPlyText("ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n1\n", &e);
    REQUIRE(e);
    CHECK(e.line == 4);
    CHECK(e.message.find("flot") != std::string::npos);

    readPlyText("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nbogus\nend_header\n",
                &e);
    REQUIRE(e);
    CHECK(e.line == 5);

    readPlyText("ply\nformat ascii 1.0\nproperty float x\n", &e);
    REQUIRE(e);
    CHECK(e.line == 3);

    readPlyText("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", &e);
    REQUIRE(e);
    CHECK(e.message.find("end_header") != std::string::npos);

    readPlyText("ply\nformat binary_middle_endian 1.0\n", &e);
    REQUIRE(e);
    CHECK(e.line == 2);

    readPlyText("ply\nformat ascii 1.0\nelement vertex -1\n", &e);
    REQUIRE(e);
    CHECK(e.line == 3);

    // ascii body: a bad number at its line and column; a short file.
    readPlyText("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                "end_header\n1 2\n3 oops\n",
                &e);
    REQUIRE(e);
    CHECK(e.line == 8);
    CHECK(e.col == 3);
    CHECK(e.message.find("oops") != std::string::npos);
    CHECK(e.message.find("vertex 1") != std::string::npos);

    readPlyText("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "end_header\n1 2\n3 4\n5\n",
                &e);
    REQUIRE(e);
    CHECK(e.message.find("end of file") != std::string::npos);

    // binary: truncated data.
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nend_header\n";
    putLE(s, 1.0f);
    putLE(s, uint16_t(0));
    readPlyText(s, &e);
    REQUIRE(e);
    CHECK(e.message.find("truncated") != std::string::npos);

    // a count far beyond the data is caught before allocating.
    readPlyText(
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
        "end_header\n",
        &e);
    REQUIRE(e);
    CHECK(e.message.find("truncated") != std::string::npos);

    // face index out of range.
    readPlyText("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement face 1\n"
                "property list uchar int vertex_indices\nend_header\n0\n3 0 0 5\n",
                &e);
    REQUIRE(e);
    CHECK(e.line == 9);
    CHECK(e.message.find("vertex 5") != std::string::npos);
}

TEST_CASE("JSON output", "[pointset][json]") {
    PointSet ps;
    ps.names = {"x", "v\"q"};
    ps.columns = {{1, 0.5}, {std::nan(""), -std::numeric_limits<double>::infinity()}};
    CHECK(write(ps, PointFormat::Json) ==
          "[\n  {\"x\": 1, \"v\\\"q\": null},\n  {\"x\": 0.5, \"v\\\"q\": null}\n]\n");
    PointSet empty;
    empty.names = {"x"};
    empty.columns = {{}};
    CHECK(write(empty, PointFormat::Json) == "[]\n");
}

TEST_CASE("NPY output: version 1.0 header, <f4, C order", "[pointset][npy]") {
    PointSet ps = sample();
    auto parse = [](const std::string& bytes, std::string& header) {
        REQUIRE(bytes.size() >= 10);
        REQUIRE(bytes.substr(0, 6) == "\x93NUMPY");
        REQUIRE(bytes[6] == 1);
        REQUIRE(bytes[7] == 0);
        size_t len =
            static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
        REQUIRE((10 + len) % 64 == 0);
        header = bytes.substr(10, len);
        REQUIRE(header.back() == '\n');
        std::vector<float> data((bytes.size() - 10 - len) / 4);
        std::memcpy(data.data(), bytes.data() + 10 + len, data.size() * 4);
        return data;
    };
    std::string header;
    std::vector<float> data = parse(write(ps, PointFormat::Npy, {0, 1, 2}), header);
    CHECK(header.find("'descr': '<f4'") != std::string::npos);
    CHECK(header.find("'fortran_order': False") != std::string::npos);
    CHECK(header.find("'shape': (3, 3)") != std::string::npos);
    CHECK(data == std::vector<float>{0, 0.25f, 1, 1.5f, 2, -0.5f, -2, 3, 4});

    data = parse(write(ps, PointFormat::Npy, {3}), header);
    CHECK(header.find("'shape': (3,)") != std::string::npos);
    CHECK(data == std::vector<float>{7, 8, 9});

    data = parse(write(ps, PointFormat::Npy), header);
    CHECK(header.find("'shape': (3, 4)") != std::string::npos);
    CHECK(data.size() == 12);

    std::ostringstream out;
    CHECK(writePoints(out, ps, PointFormat::Npy, {9}));
}

TEST_CASE("files: formats by extension, OBJ, atomic writes, missing files", "[pointset][file]") {
    TempDir dir;
    PointFormat f;
    CHECK(formatFromPath("a/b.PLY", f));
    CHECK(f == PointFormat::Ply);
    CHECK(formatFromPath("b.npy", f));
    CHECK(f == PointFormat::Npy);
    CHECK_FALSE(formatFromPath("b.txt", f));

    PointSet ps = sample();
    for (const char* name : {"p.csv", "p.ply", "p.obj"}) {
        std::string path = dir.file(name);
        REQUIRE(formatFromPath(path, f));
        IoError e = writePointsFile(path, ps, f);
        REQUIRE_FALSE(e);
        PointSet back;
        e = readPoints(path, back);
        if (e) FAIL(e.render());
        CHECK(back.columns[0] == ps.columns[0]);
        CHECK(back.columns[2] == ps.columns[2]);
        if (f != PointFormat::Csv) CHECK(back.faces == ps.faces);
    }
    // Nothing but the three outputs is left in the folder (no temporaries).
    size_t count = 0;
    for (auto& entry : std::filesystem::directory_iterator(dir.path)) {
        (void)entry;
        ++count;
    }
    CHECK(count == 3);

    // OBJ with a quad and a normal index.
    {
        std::ofstream obj(dir.file("q.obj"));
        obj << "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n";
    }
    PointSet quad;
    IoError e = readPoints(dir.file("q.obj"), quad);
    REQUIRE_FALSE(e);
    CHECK(quad.names == std::vector<std::string>{"x", "y", "z"});
    CHECK(quad.size() == 4);
    CHECK(quad.columns[2][3] == 0.5);
    REQUIRE(quad.faces.size() == 1);
    CHECK(quad.faces[0] == std::vector<int>{0, 1, 2, 3});

    PointSet none;
    for (const char* name : {"missing.csv", "missing.ply", "missing.obj"}) {
        e = readPoints(dir.file(name), none);
        REQUIRE(e);
        CHECK(e.kind == IoError::Io);
        CHECK(e.message.find("No such file") != std::string::npos);
        CHECK(e.render().find(name) != std::string::npos);
    }
    e = readPoints(dir.file("x.txt"), none);
    CHECK(e.kind == IoError::Data);
    e = readPoints(dir.path.string() + "/", none);
    CHECK(e);

    // An unwritable destination: an Io error naming the file, and no temporary left.
    e = writePointsFile(dir.file("no/such/dir/out.csv"), ps, PointFormat::Csv);
    REQUIRE(e);
    CHECK(e.kind == IoError::Io);
    CHECK(e.file == dir.file("no/such/dir/out.csv"));

    // stdin reads CSV.
    std::istringstream in("x,y,z\n1,2,3\n");
    e = readPoints("-", none, &in);
    REQUIRE_FALSE(e);
    CHECK(none.size() == 1);
}

TEST_CASE("pointVariables maps columns to host variables", "[pointset]") {
    PointSet ps;
    ps.names = {"u", "x", "y", "z", "nz", "ny", "nx", "my col", "2nd", "P", "a.b"};
    ps.columns.assign(ps.names.size(), std::vector<double>(1, 0.0));
    std::vector<PointVariable> vars = pointVariables(ps);
    REQUIRE(vars.size() == 6);
    CHECK(vars[0].name == "P");
    CHECK(vars[0].columns == std::vector<int>{1, 2, 3});
    CHECK(vars[1].name == "N");
    CHECK(vars[1].columns == std::vector<int>{6, 5, 4});
    CHECK(vars[2].name == "u");
    CHECK(vars[3].name == "my_col");
    CHECK(vars[3].columns == std::vector<int>{7});
    CHECK(vars[4].name == "_2nd");
    // "P" (a duplicate of x,y,z's P) is left out; "a.b" keeps its dot.
    CHECK(vars[5].name == "a.b");
    ps.names[9] = "Q";
    std::vector<PointVariable> v2 = pointVariables(ps);
    REQUIRE(v2.size() == 7);
    CHECK(v2[6].name == "a.b");
}
