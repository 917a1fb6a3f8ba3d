// A scene loaded for simulation and stepped frame by frame: the scene file read with its --set
// overrides, the wind field and bodies built, the world assembled. Both front ends drive it:
// `gale sim` (cli/) with the frame files of run/sim_output.h, and the Python module's
// Scene.simulate (python/), so both give the same frames.
#pragma once

#include "scene/sim_scene.h"
#include "solver/world/world.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gale::run {

// What went wrong, for the front end to show: `rendered` is printed as it is (scene errors at
// file:line:col, each line ending in '\n'), `message` is one sentence ("gale: " goes before it).
// `kind` picks the CLI's exit code (Input 1, Io 3, Numeric 4).
struct RunError {
    enum Kind { None, Input, Io, Numeric } kind = None;
    std::string rendered;
    std::string message;
    explicit operator bool() const { return kind != None; }
    std::string text() const { return rendered + message; } // both, for an exception's text
};

struct SimSetup {
    std::string scene;                   // path of the .toml
    std::vector<std::string> sets;       // KEY=VALUE overrides by dotted path
    std::vector<std::string> allowPaths; // folders expressions may read besides the scene's
    int threads = 1;                     // 0: all hardware threads; results do not depend on it
    bool hasFrames = false;              // frames first..last instead of the scene's range
    int first = 0, last = 0;
    bool color = false; // colour in the rendered field diagnostics
};

class SimRun {
public:
    // Loads the scene and builds the world. `report` receives what to show even on success
    // (the field's diagnostics, "gale: warning: ..." lines), in order, each ending in '\n'.
    RunError load(const SimSetup& setup, std::string& report);

    const scene::SimScene& scene() const { return mScene; }
    solver::World& world() { return *mWorld; }
    const solver::World& world() const { return *mWorld; }
    int first() const { return mFirst; }
    int last() const { return mLast; }
    double fps() const { return mScene.wind.settings.fps; }
    // run.json's "settings": the scene as resolved, for this frame range and thread count.
    const std::string& settings() const { return mSettings; }
    // The warnings load() reported (building the bodies, scene_checks.h), one line each as
    // "file:line:col: message" (run.json's "warnings").
    const std::vector<std::string>& warnings() const { return mWarnings; }
    // A digest of what the run reads besides its settings — the scene file's text, the --set
    // overrides, the expression files (their bytes), meshes, strands and attachment sequences
    // (their sizes and times) — so that --resume refuses a run whose inputs changed since.
    const std::string& inputsDigest() const { return mInputs; }
    // The output format ("obj" or "ply") of the world's body `i`.
    const std::string& outputFormat(size_t i) const;

    // The frames simulated before first() and not written (the run-up): a range that starts
    // after the scene's first frame is reached by simulating from there, so that it starts from a
    // simulated state — the cloth where the shot took it — never from the rest mesh teleported
    // to the bodies' pose at first(). 0 when first() is the scene's first frame (or before it).
    int runUpFrames() const { return mFirst - mRunUpFrom; }
    // Steps the world from the scene's first frame to first(), calling `each` after every frame
    // (for progress and events). False, with the frame's stats in `failed`, when a frame failed
    // numerically.
    bool runUp(const std::function<void(const solver::FrameStats&)>& each,
               solver::FrameStats& failed);

    // The stats of frame first(): the initial state, no substeps.
    solver::FrameStats initialFrame() const;
    // Advances the world from frame − 1 to `frame`.
    solver::FrameStats advance(int frame) { return mWorld->advanceFrame(frame); }

private:
    scene::SimScene mScene;
    std::unique_ptr<solver::World> mWorld;
    int mFirst = 0, mLast = 0;
    int mRunUpFrom = 0; // the frame the run-up starts at (its initial state)
    std::string mSettings;
    std::vector<std::string> mWarnings;
    std::string mInputs;
};

} // namespace gale::run
