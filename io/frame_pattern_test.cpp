// Frame tokens as DCCs write them: each spelling formats the numbers its DCC writes (printf and
// Houdini's rules), matches exactly those names, and a name with two tokens is refused.
#include "io/frame_pattern.h"
#include "io/grid.h"

#include <catch2/catch.hpp>

#include <cstdio>
#include <string>

using namespace gale::io;

TEST_CASE("frame tokens: '#' runs, %0Nd and $FN format as their DCCs do", "[io][frames]") {
    struct Case {
        const char* pattern;
        const char* printfFormat; // the same name through printf, the reference
    };
    const Case cases[] = {{"body.####.obj", "body.%04d.obj"}, {"body.#.obj", "body.%04d.obj"},
                          {"body.##.obj", "body.%02d.obj"},   {"body.%04d.obj", "body.%04d.obj"},
                          {"body.%d.obj", "body.%d.obj"},     {"body.%3d.obj", "body.%03d.obj"},
                          {"body.$F4.obj", "body.%04d.obj"},  {"body.$F.obj", "body.%d.obj"},
                          {"cache_$F2.ply", "cache_%02d.ply"}};
    for (const Case& c : cases)
        for (long frame : {0L, 7L, 42L, 1001L, 123456L}) {
            char expected[64];
            std::snprintf(expected, sizeof expected, c.printfFormat, static_cast<int>(frame));
            std::string out;
            INFO(c.pattern << " frame " << frame);
            REQUIRE(framePath(c.pattern, frame, out));
            CHECK(out == expected);
            FramePattern p;
            REQUIRE(parseFramePattern(c.pattern, p));
            long back = -1;
            CHECK(matchFrame(p, out, back));
            CHECK(back == frame);
        }
    std::string out;
    REQUIRE(framePath("v.$F4.npy", -3, out));
    CHECK(out == "v.-0003.npy");
    // printf's width counts the sign: a pre-roll cache written with %04d from frame -5.
    for (long frame : {-1L, -5L, -42L, -1234L}) {
        char expected[64];
        std::snprintf(expected, sizeof expected, "body.%04d.obj", static_cast<int>(frame));
        REQUIRE(framePath("body.%04d.obj", frame, out));
        CHECK(out == expected);
        FramePattern p;
        REQUIRE(parseFramePattern("body.%04d.obj", p));
        long back = 0;
        CHECK(matchFrame(p, expected, back));
        CHECK(back == frame);
    }
}

TEST_CASE("frame tokens: names that are not frames of the pattern", "[io][frames]") {
    FramePattern p;
    REQUIRE(parseFramePattern("body.%04d.obj", p));
    long f = 0;
    CHECK_FALSE(matchFrame(p, "body.12.obj", f));    // another padding
    CHECK_FALSE(matchFrame(p, "body.00012.obj", f)); // another padding
    CHECK_FALSE(matchFrame(p, "body.0012.ply", f));  // another suffix
    CHECK_FALSE(matchFrame(p, "body.00a2.obj", f));  // not digits
    CHECK_FALSE(matchFrame(p, "body..obj", f));      // no digits
    CHECK(matchFrame(p, "body.0012.obj", f));
    CHECK(f == 12);

    CHECK_FALSE(hasFrameToken("body.obj"));
    CHECK_FALSE(hasFrameToken("100%.obj"));   // a percent sign that is no %d
    CHECK_FALSE(hasFrameToken("$FF.obj"));    // Houdini's float frame: not supported
    CHECK_FALSE(hasFrameToken("$FRAME.obj")); // not $F
    CHECK_FALSE(hasFrameToken("$F4_x.obj"));  // Houdini reads the variable F4_x
    CHECK(hasFrameToken("a.$F.obj"));
    std::string error;
    CHECK_FALSE(parseFramePattern("a.#.$F4.obj", p, &error));
    CHECK(error.find("more than one frame number") != std::string::npos);
    CHECK_FALSE(parseFramePattern("plain.obj", p, &error));
}
