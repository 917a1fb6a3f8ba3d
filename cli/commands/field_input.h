// What `gale sample` and `gale viz` share: the wind they take (FILE.se | -e EXPR | SCENE.toml,
// with --set) loaded as one Field with diagnostics printed, and the parsing of their
// comma-separated number flags (--bounds, --res) and frame ranges (--frames A:B).
#pragma once

#include "cli/commands.h"
#include "fields/field.h"
#include "fields/scene.h"

#include <memory>
#include <string>
#include <vector>

namespace gale::cli {

// A loaded wind: the field, and the scene when it came from a SCENE.toml (the scene's field
// points into it, so it is shared and must outlive the field).
struct FieldInput {
    std::shared_ptr<const fields::Scene> scene;
    fields::FieldPtr field;
    std::string name; // for titles and metadata: the file as given, or "<expr>"
    // Frames per second: --fps, else the scene's, else 24.
    double fps = 24.0;
    // The scene's time_zero (the frame at t = 0), else 0: frame F is at (F − timeZero) / fps.
    double timeZero = 0.0;
    double frameTime(double frame) const { return (frame - timeZero) / fps; }
};

// True for a path naming a scene file (.toml, any case).
bool isSceneFile(const std::string& path);

// Loads the wind. An expression is compiled wanting FP[3] (a scalar is promoted) with every
// --set NAME=VALUE overriding the parameter (or binding the variable) of that name; a scene
// is loaded with every --set KEY=VALUE overriding a dotted scene path. Prints every problem
// and returns an exit code (0 on success): 2 for bad --set syntax, 3 when a file cannot be
// read, 1 for diagnostics in the expression or scene.
int loadFieldInput(const SourceOptions& source, double fpsOverride, FieldInput& out);

// Parses `count` comma-separated finite numbers (spaces allowed around them). False, with
// `error` naming `flag`, otherwise.
bool parseNumbers(const std::string& text, size_t count, const std::string& flag,
                  std::vector<double>& out, std::string& error);

// Parses an inclusive frame range "A:B" (integers, A <= B) or a single frame "A".
bool parseFrameRange(const std::string& text, long& first, long& last, std::string& error);

} // namespace gale::cli
