// Frame tokens in file names (frame_pattern.h): '#' runs, printf's %0Nd and Houdini's $FN.
#include "io/frame_pattern.h"

#include "io/grid.h"

#include <cctype>
#include <cstdlib>

namespace gale::io {

const char* const kFrameTokens = "a run of '#' (body.####.obj), %04d or $F4";

namespace {

bool isDigit(char c) {
    return c >= '0' && c <= '9';
}

// The token starting at `i` of `s`, if any: its length and width (and whether it is printf's,
// whose width counts a minus sign).
bool tokenAt(const std::string& s, size_t i, size_t& length, int& width, bool* printf = nullptr) {
    if (printf) *printf = s[i] == '%';
    if (s[i] == '#') {
        size_t end = s.find_first_not_of('#', i);
        if (end == std::string::npos) end = s.size();
        length = end - i;
        width = length == 1 ? 4 : static_cast<int>(length);
        return true;
    }
    if (s[i] == '%') { // %d, %4d, %04d
        size_t j = i + 1;
        while (j < s.size() && isDigit(s[j])) ++j;
        if (j >= s.size() || s[j] != 'd' || j - i - 1 > 2) return false;
        width = j > i + 1 ? std::atoi(s.substr(i + 1, j - i - 1).c_str()) : 1;
        width = std::max(width, 1);
        length = j + 1 - i;
        return true;
    }
    if (s[i] == '$' && i + 1 < s.size() && s[i + 1] == 'F') { // $F, $F4 (not $FF: a float frame)
        size_t j = i + 2;
        while (j < s.size() && isDigit(s[j])) ++j;
        if (j < s.size() && (std::isalpha(static_cast<unsigned char>(s[j])) || s[j] == '_'))
            return false;
        if (j - i - 2 > 2) return false;
        width = j > i + 2 ? std::max(1, std::atoi(s.substr(i + 2, j - i - 2).c_str())) : 1;
        length = j - i;
        return true;
    }
    return false;
}

} // namespace

bool hasFrameToken(const std::string& name) {
    size_t length = 0;
    int width = 0;
    for (size_t i = 0; i < name.size(); ++i)
        if (tokenAt(name, i, length, width)) return true;
    return false;
}

std::string foreignTokenHint(const std::string& fileName) {
    if (fileName.find_first_of("%@<{$") == std::string::npos) return "";
    return std::string("; if it names a frame sequence, write the frame number as ") + kFrameTokens;
}

bool parseFramePattern(const std::string& name, FramePattern& out, std::string* error) {
    bool found = false;
    for (size_t i = 0; i < name.size();) {
        size_t length = 0;
        int width = 0;
        bool printf = false;
        if (!tokenAt(name, i, length, width, &printf)) {
            ++i;
            continue;
        }
        if (found) {
            if (error)
                *error = "'" + name + "' has more than one frame number; a sequence has one (" +
                         kFrameTokens + ")";
            return false;
        }
        found = true;
        out.prefix = name.substr(0, i);
        out.suffix = name.substr(i + length);
        out.width = width;
        out.signInWidth = printf;
        i += length;
    }
    return found;
}

std::string formatFrame(const FramePattern& p, long frame) {
    std::string digits = std::to_string(frame < 0 ? -frame : frame);
    const int width = p.signInWidth && frame < 0 ? p.width - 1 : p.width; // printf: -001
    if (digits.size() < static_cast<size_t>(width)) digits.insert(0, width - digits.size(), '0');
    if (frame < 0) digits.insert(0, 1, '-');
    return p.prefix + digits + p.suffix;
}

bool matchFrame(const FramePattern& p, const std::string& name, long& frame) {
    if (name.size() <= p.prefix.size() + p.suffix.size()) return false;
    if (name.compare(0, p.prefix.size(), p.prefix) != 0) return false;
    if (name.compare(name.size() - p.suffix.size(), p.suffix.size(), p.suffix) != 0) return false;
    const std::string middle =
        name.substr(p.prefix.size(), name.size() - p.prefix.size() - p.suffix.size());
    const size_t digits0 = middle[0] == '-' ? 1 : 0;
    if (middle.size() <= digits0 || middle.size() > 12) return false;
    for (size_t i = digits0; i < middle.size(); ++i)
        if (!isDigit(middle[i])) return false;
    const long f = std::stol(middle);
    if (formatFrame(p, f) != name) return false; // another padding
    frame = f;
    return true;
}

bool framePath(const std::string& pattern, long frame, std::string& out) {
    FramePattern p;
    if (!parseFramePattern(pattern, p)) return false;
    out = formatFrame(p, frame);
    return true;
}

} // namespace gale::io
