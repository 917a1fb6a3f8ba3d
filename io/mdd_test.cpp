// Tests for the MDD cache: the byte layout against values written out by hand (big-endian
// IEEE 754), round trips, the header/size check, and the writer's append and resume.
#include "io/mdd.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>

using namespace gale::io;

namespace {

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

} // namespace

TEST_CASE("mdd: the layout is big-endian counts, times, then x y z per point per frame", "[mdd]") {
    MddCache c;
    c.points = 1;
    c.times = {0.5f};
    c.xyz = {1.0f, -2.0f, 0.25f};
    // 1.0f = 0x3F800000, -2.0f = 0xC0000000, 0.25f = 0x3E800000, 0.5f = 0x3F000000.
    const std::string want("\x00\x00\x00\x01"
                           "\x00\x00\x00\x01"
                           "\x3F\x00\x00\x00"
                           "\x3F\x80\x00\x00"
                           "\xC0\x00\x00\x00"
                           "\x3E\x80\x00\x00",
                           24);
    CHECK(encodeMdd(c) == want);
}

TEST_CASE(
    "mdd: decode gives back what was encoded; a size that disagrees with the header is an error",
    "[mdd]") {
    MddCache c;
    c.points = 2;
    c.times = {0.0f, 1.0f / 24, 2.0f / 24};
    for (int i = 0; i < 18; ++i) c.xyz.push_back(0.125f * i - 1.0f);
    const std::string bytes = encodeMdd(c);
    REQUIRE(bytes.size() == 8 + 4 * 3 + 12 * 2 * 3);
    MddCache back;
    std::string error;
    REQUIRE(decodeMdd(bytes, "a.mdd", back, error));
    CHECK(back.points == 2);
    CHECK(back.times == c.times);
    CHECK(back.xyz == c.xyz);
    CHECK_FALSE(decodeMdd(bytes + "x", "a.mdd", back, error));
    CHECK(error.find("a.mdd: the header says 3 frames of 2 points") == 0);
    CHECK_FALSE(decodeMdd(bytes.substr(0, bytes.size() - 4), "a.mdd", back, error));
    CHECK_FALSE(decodeMdd("abc", "a.mdd", back, error));
}

TEST_CASE("mdd: the writer keeps a complete file after every frame and resumes keeping a prefix",
          "[mdd]") {
    test::TempDir dir;
    const std::string path = dir.file("cape.mdd");
    const double f0[6] = {0, 0, 0, 1, 2, 3};
    const double f1[6] = {0.5, 0, 0, 1, 2, 3.5};
    const double f2[6] = {1, 0, 0, 1, 2, 4};
    {
        MddWriter w(path, 2);
        REQUIRE_FALSE(w.appendFrame(1 / 24.0, f0));
        MddCache onDisk;
        REQUIRE_FALSE(readMddFile(path, onDisk));
        CHECK(onDisk.frames() == 1);
        REQUIRE_FALSE(w.appendFrame(2 / 24.0, f1));
        REQUIRE_FALSE(w.appendFrame(3 / 24.0, f2));
    }
    MddCache all;
    REQUIRE_FALSE(readMddFile(path, all));
    REQUIRE(all.frames() == 3);
    CHECK(all.times[2] == static_cast<float>(3 / 24.0));
    CHECK(all.xyz[3 * 2 * 2 + 5] == 4.0f);
    const std::string uninterrupted = slurp(path);

    // Resuming after frame index 1 drops frame 2 and writes it again: the same bytes.
    MddWriter r(path, 2);
    REQUIRE_FALSE(r.resume(2));
    CHECK(r.cache().frames() == 2);
    REQUIRE_FALSE(r.appendFrame(3 / 24.0, f2));
    CHECK(slurp(path) == uninterrupted);

    MddWriter wrongPoints(path, 5);
    IoError e = wrongPoints.resume(1);
    CHECK(e.kind == IoError::Data);
    CHECK(e.message.find("2 points") != std::string::npos);
    MddWriter tooShort(path, 2);
    CHECK(tooShort.resume(4).kind == IoError::Data);
    MddWriter missing(dir.file("none.mdd"), 2);
    CHECK(missing.resume(1).kind == IoError::Io);
}
