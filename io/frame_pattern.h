// Frame-numbered file names as DCCs write them: one frame token in a file name — a run of '#'
// (`body.####.obj`, a lone '#' pads to 4 digits), printf's `%04d` / `%d` (Maya, Nuke) or
// Houdini's `$F4` / `$F` — formatted for a frame and matched against names found on disk.
#pragma once

#include <string>

namespace gale::io {

// What the tokens look like, for messages: "a run of '#' (body.####.obj), %04d or $F4".
extern const char* const kFrameTokens;

struct FramePattern {
    std::string prefix, suffix; // the name around the token
    int width = 4;              // digits, zero-padded (1: unpadded); the sign comes first
    bool signInWidth = false;   // %04d: printf's width counts the sign (frame -1 is -001)
};

// For a file that could not be read: when its name looks like another program's frame token
// (${F4}, @, %-4d, <f>, {frame:04d}), "; if it names a frame sequence, write the frame number as
// ..." (gale's tokens); otherwise empty.
std::string foreignTokenHint(const std::string& fileName);

// True when `name` holds a frame token anywhere (a sequence rather than a single file).
bool hasFrameToken(const std::string& name);

// The one frame token of `name`. False when it has none, or (with `error` set) more than one.
bool parseFramePattern(const std::string& name, FramePattern& out, std::string* error = nullptr);

// The name of `frame` (frame -3 at width 4 -> `-0003`; `%04d` as printf writes it, `-003`).
std::string formatFrame(const FramePattern& p, long frame);

// The frame number of `name` when it is exactly what formatFrame writes for some frame
// (prefix, the digits at the pattern's padding, suffix); false otherwise.
bool matchFrame(const FramePattern& p, const std::string& name, long& frame);

} // namespace gale::io
