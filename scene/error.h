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
    bool warning = false;           // a likely mistake that does not stop a run
    // "file:line:col: error: message" ("warning:" for a warning; without :line:col when line is
    // 0), then the source line
    // with a caret under the column, then "note: ..." lines.
    std::string render() const;
    // "file:line:col" ("<scene>" for no file; without :line:col when line is 0).
    std::string location() const;
};

// An error at file:line:col of `file`, its source line read from the file.
SceneError sceneErrorAt(const std::string& file, int line, int col, std::string message);

// Whether a loader's message (loadMesh, MeshSequence::load, loadStrands) says a file could not be
// found or read, rather than that its contents are wrong: such a SceneError is `io` (exit 3).
bool isFileProblem(const std::string& message);

} // namespace gale::scene
