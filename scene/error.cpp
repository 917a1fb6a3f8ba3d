// Scene errors rendered like expression diagnostics: file:line:col, the offending line with a
// caret under the column, then notes.
#include "scene/error.h"

#include <fstream>

namespace gale::scene {

SceneError sceneErrorAt(const std::string& file, int line, int col, std::string message) {
    SceneError e;
    e.file = file;
    e.line = line;
    e.col = col;
    e.message = std::move(message);
    if (line > 0) {
        std::ifstream in(file);
        std::string text;
        for (int i = 0; i < line && std::getline(in, text); ++i) {
        }
        e.sourceLine = text;
    }
    return e;
}

std::string SceneError::location() const {
    std::string out = file.empty() ? std::string("<scene>") : file;
    if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(col > 0 ? col : 1);
    return out;
}

std::string SceneError::render() const {
    std::string out = location() + (warning ? ": warning: " : ": error: ") + message;
    if (line > 0 && !sourceLine.empty()) {
        out += "\n    ";
        for (char c : sourceLine) out += (static_cast<unsigned char>(c) < 0x20 && c != '\t') ? ' ' : c;
        out += "\n    ";
        // The caret under column `col` (columns count characters; tabs are kept as tabs).
        int column = 1;
        for (size_t i = 0; i < sourceLine.size() && column < col; ++i) {
            const unsigned char c = static_cast<unsigned char>(sourceLine[i]);
            if ((c & 0xC0) == 0x80) continue; // UTF-8 continuation byte
            out += c == '\t' ? '\t' : ' ';
            ++column;
        }
        out += '^';
    }
    for (const std::string& n : notes) out += "\nnote: " + n;
    return out;
}

bool isFileProblem(const std::string& message) {
    for (const char* said :
         {"cannot open", "cannot read '", "No such file", "no files of the sequence",
          "' is missing", "cannot list the folder", "which does not exist", "Permission denied"})
        if (message.find(said) != std::string::npos) return true;
    return false;
}

} // namespace gale::scene
