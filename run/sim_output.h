// A run's files in its output folder: one OBJ/PLY per object and frame (atomically), optional
// MDD caches, the solver state per frame for --resume, run.json, and the folder's lock so two
// runs never write one folder at once. Returns errors; prints nothing.
#pragma once

#include "io/mdd.h"
#include "run/sim_run.h"

#include <chrono>
#include <string>
#include <vector>

namespace gale::run {

struct OutputOptions {
    std::string dir;     // OUTDIR
    bool resume = false; // continue after the last complete frame saved there
    bool mdd = false;    // also OUTDIR/<object>.mdd, one point cache per object
};

// OUTDIR/<object>.<frame:04d>.<ext>
std::string frameFileName(const std::string& dir, const std::string& object, int frame,
                          const std::string& ext);

class SimOutput {
public:
    // Creates and locks the folder, removes temporary files of killed writers and, with
    // `resume`, loads the last saved state into `run`'s world. `notes` receives the lines to
    // show ("gale: warning: ...", "gale: resuming after frame N").
    RunError open(SimRun& run, const OutputOptions& options, std::vector<std::string>& notes);

    // The first frame still to save: run.first() for a new run (its initial state), else the
    // frame after the one resumed from.
    int nextFrame() const { return mNext; }

    // Writes the frame's object files and caches, its state and stats, and (at most once a
    // second, and after the first frame) run.json with status "running".
    RunError saveFrame(const solver::FrameStats& stats);
    // Adds a failed frame's stats (its files are not written) and writes run.json with status
    // `status`: "failed" (numerically), or "trouble" (refused by gale sim --strict).
    void saveFailedFrame(const solver::FrameStats& stats, const std::string& status = "failed");
    // Writes run.json with status "ok"; its text in `runText`.
    RunError finish(std::string& runText);

    const std::string& runJsonPath() const { return mRunPath; }

private:
    RunError writeRun(const std::string& status, std::string* text);
    RunError writeObjects(int frame, double time);

    SimRun* mRun = nullptr;
    OutputOptions mOptions;
    std::string mRunPath;
    std::vector<std::string> mFrames; // frameJson of every frame saved so far
    std::vector<io::MddWriter> mCaches;
    int mNext = 0;
    bool mRunWritten = false;
    std::chrono::steady_clock::time_point mLastRunWrite;
};

} // namespace gale::run
