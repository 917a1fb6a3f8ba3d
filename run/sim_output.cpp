// A run's files (run/sim_output.h): frames, caches, per-frame state, run.json, the folder lock,
// and --resume from the saved state.
#include "run/sim_output.h"

#include "io/atomic_file.h"
#include "io/pointset.h"
#include "run/sim_json.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace gale::run {

namespace {

namespace fs = std::filesystem;

std::string stateFile(const std::string& dir, int frame, const char* ext) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%04d.%s", frame, ext);
    return (fs::path(dir) / ".state" / buf).string();
}

// Settings text with its thread count blanked ("threads": N is the one key that changes no
// result).
std::string withoutThreads(const std::string& settings) {
    const std::string key = "\"threads\": ";
    const size_t at = settings.find(key);
    if (at == std::string::npos) return settings;
    size_t end = at + key.size();
    while (end < settings.size() && settings[end] >= '0' && settings[end] <= '9') ++end;
    return settings.substr(0, at + key.size()) + settings.substr(end);
}

bool readFile(const std::string& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

RunError ioError(const std::string& message) {
    RunError e;
    e.kind = RunError::Io;
    e.message = message;
    return e;
}

RunError writeBytes(const std::string& path, const std::string& bytes) {
    if (io::IoError e = io::writeBytesAtomic(path, bytes)) return ioError(e.render());
    return {};
}

// Takes an exclusive lock on OUTDIR/.state/lock for the rest of the process (the kernel drops it
// when the process ends, even killed), so two runs never write one folder at once: a wedge
// re-run while the simulations of a killed wedge still run, two farm tasks on one variant.
RunError lockOutput(const std::string& dir) {
    const std::string path = (fs::path(dir) / ".state" / "lock").string();
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return ioError(path + ": cannot create the lock file: " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        char buf[32] = {};
        const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
        const std::string pid = n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string();
        if (err != EWOULDBLOCK) return {}; // no locks on this file system: run unguarded
        ::close(fd);
        return ioError(dir + " is being written by another gale sim" +
                       (pid.empty() ? std::string() : " (pid " + pid + ")") +
                       "; wait for it to finish or stop it, then run again (with --resume to "
                       "continue its frames)");
    }
    const std::string pid = std::to_string(static_cast<long>(::getpid()));
    // The pid only names the holder in the message above; the lock holds without it.
    const bool noted =
        ::pwrite(fd, pid.data(), pid.size(), 0) == static_cast<ssize_t>(pid.size()) &&
        ::ftruncate(fd, static_cast<off_t>(pid.size())) == 0;
    (void)noted;
    return {}; // fd stays open (and locked) until the process ends
}

// Removes the temporary files a killed run left (a frame, cache, run.json or state being written).
void removeStaleTemps(const std::string& dir, const solver::World& w) {
    std::vector<std::string> names;
    for (const auto& b : w.bodies()) names.push_back(b->name() + ".");
    auto endsWith = [](const std::string& s, const char* tail) {
        const size_t n = std::strlen(tail);
        return s.size() >= n && s.compare(s.size() - n, n, tail) == 0;
    };
    io::removeStaleTempFiles(dir, [&](const std::string& target) {
        if (target == "run.json") return true;
        if (!endsWith(target, ".obj") && !endsWith(target, ".ply") && !endsWith(target, ".mdd"))
            return false;
        for (const std::string& n : names)
            if (target.compare(0, n.size(), n) == 0) return true;
        return false;
    });
    io::removeStaleTempFiles((fs::path(dir) / ".state").string(),
                             [](const std::string&) { return true; });
}

} // namespace

std::string frameFileName(const std::string& dir, const std::string& object, int frame,
                          const std::string& ext) {
    char buf[32];
    std::snprintf(buf, sizeof buf, ".%04d.", frame);
    return (fs::path(dir) / (object + buf + ext)).string();
}

RunError SimOutput::open(SimRun& run, const OutputOptions& o, std::vector<std::string>& notes) {
    mRun = &run;
    mOptions = o;
    mRunPath = (fs::path(o.dir) / "run.json").string();
    solver::World& world = run.world();
    const int first = run.first(), last = run.last();
    std::error_code ec;
    fs::create_directories(fs::path(o.dir) / ".state", ec);
    if (ec) return ioError(o.dir + ": cannot create the output folder: " + ec.message());
    if (RunError e = lockOutput(o.dir)) return e;
    removeStaleTemps(o.dir, world);

    // --resume: the last frame whose state and stats were saved, by this same run.
    mNext = first;
    if (o.resume) {
        std::string saved, inputs;
        // The thread count changes no result: a run may resume on another machine.
        if (readFile((fs::path(o.dir) / ".state" / "settings.json").string(), saved) &&
            withoutThreads(saved) != withoutThreads(run.settings())) {
            RunError e;
            e.kind = RunError::Input;
            e.message =
                o.dir +
                ": the saved run has different settings (scene, --set or --frames changed); "
                "run without --resume to start over";
            return e;
        }
        if (readFile((fs::path(o.dir) / ".state" / "inputs.txt").string(), inputs) &&
            inputs != run.inputsDigest()) {
            RunError e;
            e.kind = RunError::Input;
            e.message = o.dir +
                        ": the scene's inputs changed since the saved run (the scene file, an "
                        "expression, a mesh or a sequence); run without --resume to start over";
            return e;
        }
        int resumeAt = -1;
        for (int f = last; f >= first && resumeAt < 0; --f) {
            std::string st, js;
            if (readFile(stateFile(o.dir, f, "bin"), st) &&
                readFile(stateFile(o.dir, f, "json"), js)) {
                std::string error;
                if (!world.loadState(st, error)) {
                    // Damaged (a crash of the machine rather than of gale): an earlier frame's
                    // state gives the same frames, only later.
                    notes.push_back("gale: warning: " + stateFile(o.dir, f, "bin") + ": " + error +
                                    "; resuming from an earlier frame");
                    continue;
                }
                resumeAt = f;
            }
        }
        if (resumeAt >= 0) {
            for (int f = first; f <= resumeAt; ++f) {
                std::string js;
                if (!readFile(stateFile(o.dir, f, "json"), js))
                    return ioError(stateFile(o.dir, f, "json") +
                                   ": missing; run without --resume to start over");
                mFrames.push_back(js);
            }
            mNext = resumeAt + 1;
            notes.push_back("gale: resuming after frame " + std::to_string(resumeAt));
        }
    }
    if (mNext == first) {
        // Starting over: the states of an earlier run must not be resumed with this run's frames.
        std::vector<fs::path> old;
        for (fs::directory_iterator it(fs::path(o.dir) / ".state", ec), end; !ec && it != end;
             it.increment(ec))
            if (it->path().filename() != "lock") old.push_back(it->path());
        for (const fs::path& p : old) fs::remove(p, ec);
    }
    if (o.mdd) {
        // A cache keeps the frames up to the one resumed from: a writer killed after its cache
        // took a frame but before the frame's state was saved left one frame too many.
        for (const auto& b : world.bodies()) {
            mCaches.emplace_back((fs::path(o.dir) / (b->name() + ".mdd")).string(),
                                 static_cast<int32_t>(b->vertexCount()));
            if (mNext > first)
                if (io::IoError e = mCaches.back().resume(mNext - first))
                    return ioError(e.render());
        }
    }
    if (RunError e =
            writeBytes((fs::path(o.dir) / ".state" / "inputs.txt").string(), run.inputsDigest()))
        return e;
    return writeBytes((fs::path(o.dir) / ".state" / "settings.json").string(), run.settings());
}

RunError SimOutput::writeObjects(int frame, double time) {
    const solver::World& w = mRun->world();
    for (size_t i = 0; i < w.bodies().size(); ++i) {
        const solver::Body& b = *w.bodies()[i];
        const std::string& format = mRun->outputFormat(i);
        const std::string path = frameFileName(mOptions.dir, b.name(), frame, format);
        if (format == "ply") {
            if (io::IoError e =
                    io::writePointsFile(path, scene::bodyPointSet(b), io::PointFormat::Ply))
                return ioError(e.render());
        } else if (RunError e = writeBytes(path, scene::bodyObjText(b))) {
            return e;
        }
    }
    for (size_t i = 0; i < mCaches.size(); ++i)
        if (io::IoError e = mCaches[i].appendFrame(time, w.bodies()[i]->positions().data()))
            return ioError(e.render());
    return {};
}

RunError SimOutput::writeRun(const std::string& status, std::string* text) {
    std::string run =
        "{\"status\": \"" + status + "\", \"settings\": " + mRun->settings() + ", \"warnings\": [";
    for (size_t i = 0; i < mRun->warnings().size(); ++i)
        run += (i ? ", " : "") + io::jsonString(mRun->warnings()[i]);
    run += "], \"frames\": [";
    for (size_t i = 0; i < mFrames.size(); ++i) run += (i ? ",\n  " : "\n  ") + mFrames[i];
    run += "\n]}\n";
    RunError e = writeBytes(mRunPath, run);
    if (text) *text = std::move(run);
    return e;
}

RunError SimOutput::saveFrame(const solver::FrameStats& stats) {
    if (RunError e = writeObjects(stats.frame, stats.time)) return e;
    const std::string js = frameJson(stats);
    if (RunError e =
            writeBytes(stateFile(mOptions.dir, stats.frame, "bin"), mRun->world().saveState()))
        return e;
    if (RunError e = writeBytes(stateFile(mOptions.dir, stats.frame, "json"), js)) return e;
    mFrames.push_back(js);
    mNext = stats.frame + 1;
    // run.json holds every frame so far, so rewriting it after each frame costs O(frames²)
    // bytes over a run: while running it is rewritten at most once a second (and after the
    // first frame); --resume reads the per-frame .state files, never run.json.
    const auto now = std::chrono::steady_clock::now();
    if (mRunWritten && now - mLastRunWrite < std::chrono::seconds(1)) return {};
    mRunWritten = true;
    mLastRunWrite = now;
    return writeRun("running", nullptr);
}

void SimOutput::saveFailedFrame(const solver::FrameStats& stats, const std::string& status) {
    mFrames.push_back(frameJson(stats));
    writeRun(status, nullptr);
}

RunError SimOutput::finish(std::string& runText) {
    return writeRun("ok", &runText);
}

} // namespace gale::run
