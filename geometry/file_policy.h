// Which files an expression may name (sdf("body.obj", ...), vdb("wind.#.vdb", ...)) and how the
// names resolve: relative to the folder of the expression or scene file, never escaping it
// (absolute paths, `..`, symbolic links out of it) unless a folder is allowed explicitly
// (--allow-path). Also `#` frame sequences found on disk, and the cache keys of their files.
#pragma once

#include <string>
#include <vector>

namespace gale::geometry {

struct FileAccess {
    std::string baseDir;              // names resolve against this folder ("": the current one)
    std::string rootDir;              // and must stay inside it or this one (a scene's folder)
    std::vector<std::string> allowed; // --allow-path folders: anything inside them is allowed
    // False for files named by scene keys (a collider's or attachment's mesh sequence): the
    // user's own choice, not sandboxed (docs/limits.md), so frame files may be symbolic links
    // to a cache anywhere.
    bool sandboxed = true;
};

// Access for an expression read from `sourceFile`: its folder (the current folder for "", "-"
// or a name without a folder), with `allowed` folders besides.
FileAccess fileAccessFor(const std::string& sourceFile,
                         const std::vector<std::string>& allowed = {});

// One file of a reference: its path, frame number (0 for a plain file) and cache key (canonical
// path, modification time and size: a rewritten file is a new key).
struct FrameFile {
    long frame = 0;
    std::string path; // canonical
    std::string key;
};

// A file name from an expression, checked and found: a plain file, or a sequence whose one run
// of '#' in the file name stands for the frame number (`wind.#.vdb` -> wind.0001.vdb, ...; see
// framePath in grid_sample.h), with every frame present on disk.
struct FileRef {
    std::string name;    // as written
    std::string pattern; // the resolved path (with the '#' run for a sequence)
    bool sequence = false;
    std::vector<FrameFile> frames; // by frame; exactly one for a plain file
};

// Resolves and checks `name` under the policy, then finds its file (a plain name must be an
// existing regular file) or its frames (a sequence needs at least one). False with `error` (a
// sentence naming the file) otherwise. Every frame file is checked against the policy too.
bool findFiles(const FileAccess& access, const std::string& name, FileRef& out, std::string& error);

// A file named by a scene key rather than an expression (a [[collider]] mesh): its canonical path
// and cache key, without the policy. False with `error` when it is missing or a folder.
bool frameFileFor(const std::string& path, FrameFile& out, std::string& error);

// Resolves `name` under the policy without looking for the file; false with `error`.
bool resolveFileName(const FileAccess& access, const std::string& name, std::string& path,
                     std::string& error);

// The frame file used at (possibly fractional) `frame`: the nearest one present; frames before
// the first or after the last hold the first or last.
const FrameFile& nearestFrame(const FileRef& ref, double frame);

// The two frame files around `frame` (a <= frame <= b, consecutive among those present) and the
// weight of b (0..1); both the first or the last one, weight 0, outside the range.
void bracketFrames(const FileRef& ref, double frame, size_t& a, size_t& b, double& weight);

} // namespace gale::geometry
