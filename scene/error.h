// An error in a scene file at file:line:col, rendered like an expression diagnostic (the
// offending line with a caret under the column, then notes).
#pragma once

#include <string>
#include <vector>

namespace gale::scene {

// An error in a scene file, at file:line:col (1-based; 0 when unknown).
struct SceneError {
    std::string file;
    int line = 0;
    int col = 0;
    std::string message;            // what is wrong and what to do
    std::vector<std::string> notes; // extra lines ("did you mean", the declared parameters)
    std::string sourceLine;         // the offending line of the file, when known
    bool io = false;                // a file could not be read (the CLI exits 3, not 1)
    // "file:line:col: error: message" (without :line:col when line is 0), then the source line
    // with a caret under the column, then "note: ..." lines.
    std::string render() const;
};

} // namespace gale::scene
