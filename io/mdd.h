// LightWave MDD point caches, the one-object animation Houdini's MDD SOP, Blender's Mesh Cache
// modifier, 3ds Max's Point Cache, Modo and Cinema 4D play: big-endian int32 frame count and
// point count, float32 time (seconds) per frame, then float32 x y z per point per frame.
#pragma once

#include "io/pointset.h"

#include <cstdint>
#include <string>
#include <vector>

namespace gale::io {

// A whole cache in memory: `times.size()` frames of `points` points each (`xyz` holds
// frames × points × 3 floats, frame after frame).
struct MddCache {
    int32_t points = 0;
    std::vector<float> times;
    std::vector<float> xyz;
    int32_t frames() const { return static_cast<int32_t>(times.size()); }
};

// The file's bytes.
std::string encodeMdd(const MddCache& cache);

// Parses `bytes` (from `file`, for the message). The counts must match the size exactly (a
// file longer than its header says, or shorter, is an error naming both sizes).
bool decodeMdd(const std::string& bytes, const std::string& file, MddCache& out,
               std::string& error);

// Reads `path` (Io error when it cannot be read or is not an MDD file).
IoError readMddFile(const std::string& path, MddCache& out);

// A cache written frame by frame. MDD puts every frame's time between the header and the
// positions, so a frame added moves every position by four bytes: the format has no in-place
// append. Each appendFrame therefore writes the whole file again under a temporary name and
// renames it over the old one (io/atomic_file.h), so the file on disk is always a complete
// cache whose header counts the frames it holds, whatever moment the writer is killed at.
class MddWriter {
public:
    // A new, empty cache for `points` points at `path` (nothing is written before the first frame).
    MddWriter(std::string path, int32_t points);
    // Continues the cache at `path` keeping its first `keepFrames` frames (a resumed run). Io
    // error when the file is missing, holds another point count or fewer frames.
    IoError resume(int32_t keepFrames);

    // Adds one frame at `timeSeconds` (`xyz`: points × 3 doubles, stored as float32) and writes
    // the file.
    IoError appendFrame(double timeSeconds, const double* xyz);

    const std::string& path() const { return mPath; }
    const MddCache& cache() const { return mCache; }

private:
    std::string mPath;
    MddCache mCache;
};

} // namespace gale::io
