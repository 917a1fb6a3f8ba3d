// Tests of the live page's literal editing: parameters and ramps found where the text has them,
// rewritten in place with every other byte kept, and refused when the value does not fit.
#include "live/literals.h"

#include <catch2/catch.hpp>

#include <cstdlib>

using namespace gale;

namespace {

const char* kSource = "# a breeze\n"
                      "$speed = 4.5;   # 0, 10  metres per second\n"
                      "$dir = [1, 0, -0.5];  # direction\n"
                      "$count = 3; # 1, 8\n"
                      "def bump(x) { y = curve(x, 0,0,4, 0.5,1,4, 1,0,4); y * 2 }\n"
                      "c = ccurve($P[1], 0,[0,0,1],1, 1,[1, 0.5, 0],1);\n"
                      "live = curve($P[0], 0,0,4, $speed,1,4);  # not literal: no ramp\n"
                      "[1, 0, 0] * ($speed + bump($P[0])) + c * -curve($t, 0,-1,1, 2,+3,1)\n";

} // namespace

TEST_CASE("parameters and ramps are found at their literals", "[live][literals]") {
    const std::string text = kSource;
    const lang::SourceFile file("wind.se", text);
    const live::SourceLiterals lits = live::findLiterals(file);
    REQUIRE(lits.params.size() == 3);
    const live::ParamLiteral& speed = lits.params[0];
    CHECK(speed.name == "speed");
    CHECK(speed.value == std::vector<double>{4.5});
    CHECK(speed.hasRange);
    CHECK(speed.min == 0);
    CHECK(speed.max == 10);
    CHECK_FALSE(speed.integer); // the value is not whole
    CHECK(speed.line == 2);
    CHECK(text.substr(speed.begin, speed.end - speed.begin) == "4.5");
    CHECK(text.substr(lits.params[1].begin, lits.params[1].end - lits.params[1].begin) ==
          "[1, 0, -0.5]");
    CHECK_FALSE(lits.params[1].hasRange);
    CHECK(lits.params[2].integer);

    // Literal ramps in a def, a statement and the result; the one with $speed is not literal.
    REQUIRE(lits.ramps.size() == 3);
    const live::RampLiteral& bump = lits.ramps[0];
    CHECK(bump.function == "curve");
    CHECK(bump.line == 5);
    CHECK(bump.col == 19);
    REQUIRE(bump.points.size() == 3);
    CHECK(bump.points[1].position == 0.5);
    CHECK(bump.points[1].value == std::vector<double>{1.0});
    CHECK(bump.points[1].interp == 4);
    CHECK(text.substr(bump.begin, bump.end - bump.begin) == "0,0,4, 0.5,1,4, 1,0,4");
    const live::RampLiteral& colour = lits.ramps[1];
    CHECK(colour.function == "ccurve");
    REQUIRE(colour.points.size() == 2);
    CHECK(colour.points[1].value == std::vector<double>{1.0, 0.5, 0.0});
    const live::RampLiteral& signedRamp = lits.ramps[2];
    REQUIRE(signedRamp.points.size() == 2);
    CHECK(signedRamp.points[0].value == std::vector<double>{-1.0});
    CHECK(signedRamp.points[1].value == std::vector<double>{3.0});
}

TEST_CASE("rewrites keep every other byte", "[live][literals]") {
    const std::string original = kSource;
    const live::SourceLiterals lits = live::findLiterals(lang::SourceFile("wind.se", original));
    std::string text = original, error;
    REQUIRE(live::rewriteParam(text, lits.params[0], {7.25}, error));
    std::string want = original;
    want.replace(want.find("4.5;"), 3, "7.25");
    CHECK(text == want);

    text = original;
    REQUIRE(live::rewriteParam(text, lits.params[1], {0, 1, 0.1}, error));
    want = original;
    want.replace(want.find("[1, 0, -0.5]"), 12, "[0, 1, 0.1]");
    CHECK(text == want);

    // A ramp with a point fewer: the text between the first position and the last code.
    text = original;
    REQUIRE(live::rewriteRamp(text, lits.ramps[0], {{0.0, {0.5}, 1}, {1.0, {2.0}, 3}}, error));
    want = original;
    want.replace(want.find("0,0,4, 0.5,1,4, 1,0,4"), 21, "0,0.5,1, 1,2,3");
    CHECK(text == want);
    text = original;
    REQUIRE(live::rewriteRamp(text, lits.ramps[1], {{0.25, {1, 1, 1}, 2}}, error));
    CHECK(text.find("ccurve($P[1], 0.25,[1, 1, 1],2);") != std::string::npos);

    // The rewritten text reads back with the new values at the same places.
    const live::SourceLiterals again = live::findLiterals(lang::SourceFile("wind.se", text));
    REQUIRE(again.ramps.size() == 3);
    CHECK(again.ramps[1].points.size() == 1);
    CHECK(again.ramps[1].points[0].position == 0.25);
}

TEST_CASE("bad values are refused and the text is untouched", "[live][literals]") {
    const std::string original = kSource;
    const live::SourceLiterals lits = live::findLiterals(lang::SourceFile("wind.se", original));
    std::string text = original, error;
    CHECK_FALSE(live::rewriteParam(text, lits.params[0], {1, 2}, error));
    CHECK(error.find("1 component") != std::string::npos);
    CHECK_FALSE(live::rewriteParam(text, lits.params[0], {std::strtod("nan", nullptr)}, error));
    CHECK_FALSE(live::rewriteParam(text, lits.params[0], {std::strtod("inf", nullptr)}, error));
    CHECK_FALSE(live::rewriteRamp(text, lits.ramps[0], {}, error));
    CHECK_FALSE(
        live::rewriteRamp(text, lits.ramps[0], {{0, {1, 2, 3}, 1}}, error));   // colour in curve()
    CHECK_FALSE(live::rewriteRamp(text, lits.ramps[1], {{0, {1}, 1}}, error)); // scalar in ccurve()
    CHECK_FALSE(live::rewriteRamp(text, lits.ramps[0], {{0, {1}, 5}}, error)); // interp 5
    std::string shorter = "x";
    CHECK_FALSE(live::rewriteParam(shorter, lits.params[0], {1}, error)); // the file changed
    CHECK(text == original);
}

TEST_CASE("numbers are written in their shortest exact form", "[live][literals]") {
    for (double v : {0.0, 1.0, -2.5, 0.1, 1.0 / 3.0, 1e-7, 12345678.9, 6.02e23, -0.35}) {
        const std::string s = live::numberText(v);
        CHECK(std::strtod(s.c_str(), nullptr) == v);
        // Shortest: one digit fewer no longer reads back (except exact one-digit values).
        if (s.size() > 2 && s.find('e') == std::string::npos) {
            std::string cut = s.substr(0, s.size() - 1);
            if (cut.back() != '.' && cut.back() != '-')
                CHECK(std::strtod(cut.c_str(), nullptr) != v);
        }
    }
    CHECK(live::numberText(0.35) == "0.35");
    CHECK(live::numberText(12) == "12");
}

TEST_CASE("a source that does not parse still has its parameters", "[live][literals]") {
    const live::SourceLiterals lits =
        live::findLiterals(lang::SourceFile("bad.se", "$a = 1; # 0, 2\nx = curve(1, 0,0,1;\n"));
    REQUIRE(lits.params.size() == 1);
    CHECK(lits.ramps.empty());
}
