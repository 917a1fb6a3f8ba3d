// The file policy of expressions that name files: resolution against the expression's folder,
// containment (canonical paths, so symbolic links cannot lead out), --allow-path folders, `#`
// frame sequences found by scanning their folder, and the per-file cache keys.
#include "geometry/file_policy.h"

#include "io/frame_pattern.h"

#include "io/grid.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace gale::geometry {

namespace fs = std::filesystem;

namespace {

fs::path currentDir() {
    std::error_code ec;
    fs::path p = fs::current_path(ec);
    return ec ? fs::path(".") : p;
}

fs::path absoluteDir(const std::string& dir) {
    if (dir.empty()) return currentDir();
    fs::path p(dir);
    return p.is_absolute() ? p : currentDir() / p;
}

// Canonical where it exists, lexically normal beyond.
fs::path canonicalOf(const fs::path& p) {
    std::error_code ec;
    fs::path c = fs::weakly_canonical(p, ec);
    return ec ? p.lexically_normal() : c;
}

// True when `p` is `dir` or inside it (both canonical).
bool inside(const fs::path& p, const fs::path& dir) {
    auto d = dir.begin(), q = p.begin();
    for (; d != dir.end(); ++d, ++q) {
        if (d->empty()) continue; // a trailing separator
        if (q == p.end() || *q != *d) return false;
    }
    return true;
}

// Whether the canonical `target` is inside the root or an allowed folder; `allowedOnly` skips
// the root (absolute names must be inside an --allow-path folder).
bool permitted(const FileAccess& access, const fs::path& target, bool allowedOnly) {
    if (!access.sandboxed) return true;
    if (!allowedOnly) {
        // The folder names resolve in (the expression's) and the root (a scene's folder).
        if (inside(target, canonicalOf(absoluteDir(access.baseDir)))) return true;
        if (!access.rootDir.empty() && inside(target, canonicalOf(absoluteDir(access.rootDir))))
            return true;
    }
    for (const std::string& a : access.allowed)
        if (!a.empty() && inside(target, canonicalOf(absoluteDir(a)))) return true;
    return false;
}

std::string rootText(const FileAccess& access) {
    const fs::path base = canonicalOf(absoluteDir(access.baseDir));
    if (access.rootDir.empty()) return base.string();
    const fs::path root = canonicalOf(absoluteDir(access.rootDir));
    return inside(base, root) ? root.string() : root.string() + " and " + base.string();
}

// The cache key of an existing file; false with `error` when it cannot be stat'ed.
bool fileKey(const fs::path& canonical, std::string& key, std::string& error) {
    std::error_code ec;
    const auto mtime = fs::last_write_time(canonical, ec);
    const auto size = ec ? 0 : fs::file_size(canonical, ec);
    if (ec) {
        error = ec.message();
        return false;
    }
    key = canonical.string() + "|" + std::to_string(mtime.time_since_epoch().count()) + "|" +
          std::to_string(size);
    return true;
}

bool hasHashRun(const std::string& s) { return io::hasFrameToken(s); }

} // namespace

FileAccess fileAccessFor(const std::string& sourceFile, const std::vector<std::string>& allowed) {
    FileAccess a;
    if (!sourceFile.empty() && sourceFile != "-")
        a.baseDir = fs::path(sourceFile).parent_path().string();
    a.allowed = allowed;
    return a;
}

bool resolveFileName(const FileAccess& access, const std::string& name, std::string& path,
                     std::string& error) {
    if (name.empty()) {
        error = "the file name is empty";
        return false;
    }
    const fs::path written(name);
    const bool absolute = written.is_absolute();
    const fs::path target = canonicalOf(absolute ? written : absoluteDir(access.baseDir) / written);
    if (absolute && !permitted(access, target, true)) {
        error = "'" + name + "' is an absolute path; name files relative to " +
                canonicalOf(absoluteDir(access.baseDir)).string() +
                " (the folder of the expression or scene), or allow its folder with "
                "--allow-path DIR";
        return false;
    }
    if (!absolute && !permitted(access, target, false)) {
        error = "'" + name + "' leads outside " + rootText(access) + " (to " + target.string() +
                "); files named by expressions must stay inside the folder of the expression "
                "or scene, unless allowed with --allow-path DIR";
        return false;
    }
    path = target.string();
    return true;
}

bool findFiles(const FileAccess& access, const std::string& name, FileRef& out,
               std::string& error) {
    std::string resolved;
    if (!resolveFileName(access, name, resolved, error)) return false;
    FileRef ref;
    ref.name = name;
    ref.pattern = resolved;
    const fs::path p(resolved);
    const std::string file = p.filename().string();
    if (hasHashRun(p.parent_path().string())) {
        error = "'" + name +
                "': a frame number (" + io::kFrameTokens +
                ") may only appear in the file name, not in a folder";
        return false;
    }
    std::error_code ec;
    if (!hasHashRun(file)) {
        // Plain file: must exist and be a regular file; its canonical path (symbolic links
        // resolved) was already checked against the policy.
        const fs::file_status st = fs::status(p, ec);
        if (ec || !fs::exists(st)) {
            error = "cannot read '" + name + "' (" + resolved + "): " + std::strerror(ENOENT);
            // Another program's frame token (${F4}, @, %-4d, <f>): say which ones gale reads.
            error += io::foreignTokenHint(file);
            return false;
        }
        if (fs::is_directory(st)) {
            error = "cannot read '" + name + "' (" + resolved + "): it is a folder";
            return false;
        }
        FrameFile f;
        f.path = resolved;
        if (!fileKey(p, f.key, error)) {
            error = "cannot read '" + name + "' (" + resolved + "): " + error;
            return false;
        }
        ref.frames.push_back(std::move(f));
        out = std::move(ref);
        return true;
    }
    // A sequence: one frame token ('#' run, %04d, $F4).
    io::FramePattern pattern;
    if (!io::parseFramePattern(file, pattern, &error)) return false;
    ref.sequence = true;
    const fs::path dir = p.parent_path();
    fs::directory_iterator it(dir, ec);
    if (ec) {
        error = "cannot list the folder of '" + name + "' (" + dir.string() + "): " + ec.message();
        return false;
    }
    for (; it != fs::directory_iterator(); it.increment(ec)) {
        if (ec) break;
        const std::string entry = it->path().filename().string();
        long frame = 0;
        if (!io::matchFrame(pattern, entry, frame)) continue; // another name, or other padding
        std::error_code sec;
        if (fs::is_symlink(it->symlink_status(sec)) && !fs::exists(it->path(), sec)) {
            // A frame linked into a cache that is not there (an unmounted volume): said, not
            // skipped (the body would stand still where the frames are missing).
            error = "frame file '" + entry + "' of '" + name + "' is a link to " +
                    fs::read_symlink(it->path(), sec).string() +
                    ", which does not exist (is its volume mounted?)";
            return false;
        }
        if (!fs::is_regular_file(it->path(), sec)) continue;
        const fs::path canonical = canonicalOf(it->path());
        if (!permitted(access, canonical, fs::path(name).is_absolute())) {
            error = "frame file '" + entry + "' of '" + name + "' leads outside " +
                    rootText(access) + " (to " + canonical.string() +
                    "); allow its folder with --allow-path DIR";
            return false;
        }
        FrameFile f;
        f.frame = frame;
        f.path = canonical.string();
        if (!fileKey(canonical, f.key, error)) {
            error = "cannot read '" + entry + "' of '" + name + "': " + error;
            return false;
        }
        ref.frames.push_back(std::move(f));
    }
    if (ref.frames.empty()) {
        error = "no files of the sequence '" + name + "' in " + dir.string() +
                " (frame 1 would be " + io::formatFrame(pattern, 1) + ", frame 1001 " +
                io::formatFrame(pattern, 1001) + "; frame numbers are written as " +
                io::kFrameTokens + ")";
        return false;
    }
    std::sort(ref.frames.begin(), ref.frames.end(),
              [](const FrameFile& a, const FrameFile& b) { return a.frame < b.frame; });
    out = std::move(ref);
    return true;
}

bool frameFileFor(const std::string& path, FrameFile& out, std::string& error) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) {
        error = "cannot read '" + path + "': " + std::strerror(ENOENT);
        return false;
    }
    if (fs::is_directory(st)) {
        error = "cannot read '" + path + "': it is a folder";
        return false;
    }
    const fs::path canonical = canonicalOf(fs::path(path));
    FrameFile f;
    f.path = canonical.string();
    if (!fileKey(canonical, f.key, error)) {
        error = "cannot read '" + path + "': " + error;
        return false;
    }
    out = std::move(f);
    return true;
}

const FrameFile& nearestFrame(const FileRef& ref, double frame) {
    size_t a = 0, b = 0;
    double w = 0.0;
    bracketFrames(ref, frame, a, b, w);
    return ref.frames[w > 0.5 ? b : a];
}

void bracketFrames(const FileRef& ref, double frame, size_t& a, size_t& b, double& weight) {
    const std::vector<FrameFile>& f = ref.frames;
    weight = 0.0;
    if (f.size() <= 1 || !(frame > static_cast<double>(f.front().frame))) {
        a = b = 0; // also NaN
        return;
    }
    if (frame >= static_cast<double>(f.back().frame)) {
        a = b = f.size() - 1;
        return;
    }
    // First frame strictly greater than `frame`.
    auto it = std::upper_bound(f.begin(), f.end(), frame,
                               [](double x, const FrameFile& ff) { return x < ff.frame; });
    b = static_cast<size_t>(it - f.begin());
    a = b - 1;
    const double fa = static_cast<double>(f[a].frame), fb = static_cast<double>(f[b].frame);
    weight = (frame - fa) / (fb - fa);
    if (weight <= 0.0) {
        weight = 0.0;
        b = a;
    }
}

} // namespace gale::geometry
