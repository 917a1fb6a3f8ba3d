// The literals of an expression file that the live page edits in place: `$name = value; #
// min, max` parameters (found by fields::findParameters, the same table the compiler uses) and
// `curve`/`ccurve` calls whose control points are all literal numbers (ramps). Edits splice new
// text at the literals' byte offsets, so comments and layout survive.
#pragma once

#include "lang/source.h"

#include <string>
#include <vector>

namespace gale::live {

// A parameter declaration's value literal: `begin`..`end` covers the text between `=` and `;`
// without the spaces around it.
struct ParamLiteral {
    std::string name;
    std::vector<double> value;
    bool hasRange = false;
    double min = 0.0, max = 0.0;
    bool integer = false; // the range and the value are whole numbers: an integer slider
    std::string doc;      // the comment after the range
    int line = 0, col = 0;
    uint32_t begin = 0, end = 0;
};

// One control point of a ramp: position, value (1 component for curve, 3 for ccurve) and
// interpolation code (0 none, 1 linear, 2 smooth, 3 spline, 4 monotone spline).
struct RampPoint {
    double position = 0.0;
    std::vector<double> value;
    int interp = 1;
};

// A literal `curve(x, p, v, i, ...)` or `ccurve(x, p, [r, g, b], i, ...)`: `begin`..`end` covers
// the control points, from the first position to the last interpolation code.
struct RampLiteral {
    std::string function; // "curve" or "ccurve"
    std::vector<RampPoint> points;
    int line = 0, col = 0; // of the call
    uint32_t begin = 0, end = 0;
};

struct SourceLiterals {
    std::vector<ParamLiteral> params;
    std::vector<RampLiteral> ramps;
};

// Finds the parameters and ramps of `source`. Ramps come from a parse of the source; when it
// does not parse, only the parameters are found (they need only tokens).
SourceLiterals findLiterals(const lang::SourceFile& source);

// The shortest decimal text that reads back as exactly `v` ("0.35", "12", "-1e-07").
std::string numberText(double v);

// `text` with parameter `p`'s literal replaced by `value` (a number, or `[a, b, c]` for a
// vector of the parameter's width). False with `error` set when the width differs, a value is
// not finite, or the literal is no longer where it was found.
bool rewriteParam(std::string& text, const ParamLiteral& p, const std::vector<double>& value,
                  std::string& error);

// `text` with ramp `r`'s control points replaced by `points` (at least one; the values'
// width must be the ramp's: 1 for curve, 3 for ccurve; interp codes 0 to 4).
bool rewriteRamp(std::string& text, const RampLiteral& r, const std::vector<RampPoint>& points,
                 std::string& error);

} // namespace gale::live
