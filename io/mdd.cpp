// LightWave MDD point caches: encoding, decoding and the frame-by-frame writer (io/mdd.h).
// Layout (checked against Blender's reader, MOD_meshcache_mdd): int32 frames, int32 points,
// frames × float32 times, frames × points × 3 float32; every value big-endian.
#include "io/mdd.h"

#include "io/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

namespace gale::io {

namespace {

void putBig32(std::string& out, uint32_t v) {
    const char b[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
    out.append(b, 4);
}

uint32_t getBig32(const std::string& in, size_t at) {
    const auto* p = reinterpret_cast<const unsigned char*>(in.data() + at);
    return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

uint32_t floatBits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

float bitsFloat(uint32_t u) {
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}

} // namespace

std::string encodeMdd(const MddCache& c) {
    std::string out;
    out.reserve(8 + 4 * c.times.size() + 4 * c.xyz.size());
    putBig32(out, static_cast<uint32_t>(c.frames()));
    putBig32(out, static_cast<uint32_t>(c.points));
    for (float t : c.times) putBig32(out, floatBits(t));
    for (float v : c.xyz) putBig32(out, floatBits(v));
    return out;
}

bool decodeMdd(const std::string& bytes, const std::string& file, MddCache& out,
               std::string& error) {
    if (bytes.size() < 8) {
        error = file + ": not an MDD cache (" + std::to_string(bytes.size()) +
                " bytes, shorter than its header)";
        return false;
    }
    const int32_t frames = static_cast<int32_t>(getBig32(bytes, 0));
    const int32_t points = static_cast<int32_t>(getBig32(bytes, 4));
    if (frames < 0 || points < 0) {
        error = file + ": not an MDD cache (negative frame or point count in the header)";
        return false;
    }
    const unsigned long long expect =
        8ull + 4ull * static_cast<unsigned long long>(frames) +
        12ull * static_cast<unsigned long long>(frames) * static_cast<unsigned long long>(points);
    if (expect != bytes.size()) {
        error = file + ": the header says " + std::to_string(frames) + " frames of " +
                std::to_string(points) + " points (" + std::to_string(expect) +
                " bytes) but the file has " + std::to_string(bytes.size()) + " bytes";
        return false;
    }
    out.points = points;
    out.times.resize(static_cast<size_t>(frames));
    out.xyz.resize(static_cast<size_t>(frames) * static_cast<size_t>(points) * 3);
    size_t at = 8;
    for (float& t : out.times) t = bitsFloat(getBig32(bytes, at)), at += 4;
    for (float& v : out.xyz) v = bitsFloat(getBig32(bytes, at)), at += 4;
    return true;
}

IoError readMddFile(const std::string& path, MddCache& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return ioErrorAt(path, "cannot read the MDD cache", errno);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string error;
    if (!decodeMdd(bytes, path, out, error)) {
        IoError e;
        e.kind = IoError::Data;
        e.file = path;
        e.message = error.substr(path.size() + 2);
        return e;
    }
    return {};
}

MddWriter::MddWriter(std::string path, int32_t points) : mPath(std::move(path)) {
    mCache.points = points;
}

IoError MddWriter::resume(int32_t keepFrames) {
    MddCache old;
    if (IoError e = readMddFile(mPath, old)) {
        e.message += "; run without --resume to write the cache from the first frame";
        return e;
    }
    IoError e;
    e.kind = IoError::Data;
    e.file = mPath;
    if (old.points != mCache.points) {
        e.message = "the cache has " + std::to_string(old.points) + " points, the object " +
                    std::to_string(mCache.points) + "; run without --resume to start over";
        return e;
    }
    if (old.frames() < keepFrames) {
        e.message = "the cache has " + std::to_string(old.frames()) +
                    " frames, the resumed run needs the first " + std::to_string(keepFrames) +
                    " (was it written without --cache mdd?); run without --resume "
                    "to write it from the first frame";
        return e;
    }
    old.times.resize(static_cast<size_t>(keepFrames));
    old.xyz.resize(static_cast<size_t>(keepFrames) * static_cast<size_t>(old.points) * 3);
    mCache = std::move(old);
    return {};
}

IoError MddWriter::appendFrame(double timeSeconds, const double* xyz) {
    mCache.times.push_back(static_cast<float>(timeSeconds));
    const size_t n = static_cast<size_t>(mCache.points) * 3;
    for (size_t i = 0; i < n; ++i) mCache.xyz.push_back(static_cast<float>(xyz[i]));
    IoError e = writeBytesAtomic(mPath, encodeMdd(mCache));
    if (e) { // the file keeps the frames before this one: so does the cache in memory
        mCache.times.pop_back();
        mCache.xyz.resize(mCache.xyz.size() - n);
    }
    return e;
}

} // namespace gale::io
