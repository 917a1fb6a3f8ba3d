// `gale sim SCENE.toml`: runs the scene's cloth and hair in its wind (run/sim_run.h), writing
// one OBJ/PLY per object and frame, optional MDD caches, the solver state per frame for
// --resume, and run.json (run/sim_output.h); prints progress and picks the exit code (4 when the
// run failed numerically).
#include "cli/commands.h"
#include "cli/common.h"

#include "run/sim_output.h"
#include "run/sim_run.h"

#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace gale::cli {

namespace {

namespace fs = std::filesystem;

int show(const run::RunError& e) {
    if (!e.rendered.empty()) std::cerr << e.rendered;
    if (!e.message.empty()) printError(e.message);
    switch (e.kind) {
    case run::RunError::None:
        return kExitOk;
    case run::RunError::Io:
        return kExitIo;
    case run::RunError::Numeric:
        return kExitNumeric;
    case run::RunError::Input:
        break;
    }
    return kExitInput;
}

class Progress {
public:
    explicit Progress(int total)
        : mTotal(total), mOn(isatty(2) != 0), mStart(std::chrono::steady_clock::now()) {}
    void update(int done, int frame) {
        if (!mOn) return;
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - mStart).count();
        const double eta = done > 0 ? elapsed / done * (mTotal - done) : 0.0;
        std::fprintf(stderr, "\rgale sim: frame %d  %d/%d (%3d%%)  %.2f s/frame  ETA %.0f s   ",
                     frame, done, mTotal, mTotal ? 100 * done / mTotal : 100,
                     done ? elapsed / done : 0.0, eta);
        std::fflush(stderr);
    }
    void finish() {
        if (mOn) std::fprintf(stderr, "\n");
    }
    // A message line that does not tangle with the progress line.
    void message(const std::string& text) {
        std::fprintf(stderr, mOn ? "\r%-78s\n" : "%s\n", text.c_str());
    }

private:
    int mTotal;
    bool mOn;
    std::chrono::steady_clock::time_point mStart;
};

} // namespace

int runSim(const SimOptions& o) {
    if (o.threads < 0) {
        printError("--threads must not be negative");
        return kExitUsage;
    }
    if (!o.cache.empty() && o.cache != "mdd") {
        printError("--cache must be mdd (LightWave point caches, OUTDIR/<object>.mdd), not '" +
                   o.cache + "'");
        return kExitUsage;
    }
    run::SimSetup setup;
    setup.hasFrames = !o.frames.empty();
    if (setup.hasFrames && !parseFrames(o.frames, setup.first, setup.last)) {
        printError("--frames must be A:B with whole numbers A <= B, at most " +
                   std::to_string(kMaxFrames) + " frames, not '" + o.frames + "'");
        return kExitUsage;
    }
    setup.scene = o.scene;
    setup.sets = o.sets;
    setup.allowPaths = o.allowPaths;
    setup.threads = o.threads;
    setup.color = useColor();

    run::SimRun sim;
    std::string report;
    const run::RunError loaded = sim.load(setup, report);
    std::cerr << report << std::flush;
    if (loaded) return show(loaded);

    run::SimOutput out;
    std::vector<std::string> notes;
    const run::RunError opened = out.open(sim, {o.output, o.resume, o.cache == "mdd"}, notes);
    for (const std::string& n : notes) std::cerr << n << '\n';
    if (opened) return show(opened);

    const int first = sim.first(), last = sim.last();
    if (out.nextFrame() == first && sim.runUpFrames() > 0) {
        // A range that starts mid-shot starts from the simulated state there, not a teleport;
        // a pre-roll eases the bodies from their rest pose first.
        const int from = first - sim.runUpFrames();
        const int preroll = sim.scene().wind.settings.preroll;
        std::cerr << "gale: frames " << from << "-" << first << " are simulated first, frames "
                  << from << "-" << first - 1 << " not written";
        if (preroll > 0)
            std::cerr << " (" << preroll << " of pre-roll, the bodies eased from their rest pose)";
        std::cerr << ": frame " << first << " starts from a simulated state\n";
        Progress runUp(sim.runUpFrames());
        int step = 0;
        solver::FrameStats failed;
        auto shown = [&](const solver::FrameStats&) {
            ++step;
            runUp.update(step, from + step);
        };
        if (!sim.runUp(shown, failed)) {
            runUp.finish();
            printError("frame " + std::to_string(failed.frame) +
                       " (before the range): the run failed numerically (non-finite state that "
                       "halving the substep could not fix)");
            return kExitNumeric;
        }
        runUp.finish();
    }
    Progress progress(last - first + 1);
    if (out.nextFrame() == first)
        if (run::RunError e = out.saveFrame(sim.initialFrame())) return show(e);
    int done = out.nextFrame() - first;
    for (int f = out.nextFrame(); f <= last; ++f) {
        progress.update(done, f);
        const solver::FrameStats stats = sim.advance(f);
        bool trouble = false;
        for (const solver::BodyFrameStats& b : stats.bodies) {
            // (The frame-end trouble is in `events` too, shown below as warnings.)
            const size_t events = b.events.size() - b.trouble.size();
            const size_t shown = std::min<size_t>(events, 3);
            for (size_t e = 0; e < shown; ++e) {
                std::string line =
                    "gale: frame " + std::to_string(f) + ": " + b.name + ": " + b.events[e];
                if (e + 1 == shown && events > shown)
                    line += " (and " + std::to_string(events - shown) + " more in run.json)";
                progress.message(line);
            }
            for (const solver::FrameTrouble& t : b.trouble)
                progress.message("gale: warning: frame " + std::to_string(f) + ": " + b.name +
                                 ": " + t.text());
            trouble = trouble || !b.trouble.empty();
        }
        if (trouble && o.strict && !stats.failed) {
            out.saveFailedFrame(stats, "trouble");
            progress.finish();
            printError("frame " + std::to_string(f) +
                       " ends in trouble (over-stretched or inside a collider, above) and "
                       "--strict refuses it: frames up to " + std::to_string(f - 1) +
                       " are written, details in " + out.runJsonPath());
            return kExitNumeric;
        }
        if (stats.failed) {
            out.saveFailedFrame(stats);
            progress.finish();
            printError("frame " + std::to_string(f) +
                       ": the run failed numerically (non-finite state that halving "
                       "the substep could not fix); frames up to " +
                       std::to_string(f - 1) + " are written, details in " + out.runJsonPath());
            return kExitNumeric;
        }
        if (run::RunError e = out.saveFrame(stats)) return show(e);
        ++done;
    }
    progress.update(done, last);
    progress.finish();
    std::string runText;
    if (run::RunError e = out.finish(runText)) return show(e);
    if (o.json) std::cout << runText << std::flush;
    return kExitOk;
}

Command addSimCommand(CLI::App& app) {
    auto o = std::make_shared<SimOptions>();
    CLI::App* sub = app.add_subcommand("sim", "Simulate the scene's cloth and hair in its wind: "
                                              "writes OUTDIR/<object>.<frame>.obj|ply per "
                                              "frame, OUTDIR/run.json (settings as resolved, "
                                              "per-frame stats) and the solver state per frame "
                                              "for --resume; one run at a time per OUTDIR (a "
                                              "second is refused, exit 3). Exit 4 when the run "
                                              "failed numerically.");
    sub->add_option("scene", o->scene, "Scene file (.toml) with [[cloth]] and/or [[hair]]")
        ->type_name("SCENE")
        ->required();
    sub->add_option("-o,--output", o->output, "Output folder (default: sim)")->type_name("OUTDIR");
    sub->add_option("--frames", o->frames,
                    "Frames A to B (inclusive) instead of the scene's. Frame A is the initial "
                    "state; when A is after the scene's first frame, the frames before it are "
                    "simulated first (not written), so A starts from a simulated state")
        ->type_name("A:B");
    sub->add_option(
           "--set", o->sets,
           "Override a scene key by its dotted path (cloth.cape.drag=0.8, windicator.speed=12, "
           "collider.0.radius=0.3, solver.max_halvings=4). Repeatable")
        ->type_name("KEY=VALUE")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    addAllowPathOption(*sub, o->allowPaths);
    sub->add_flag("--resume", o->resume,
                  "Continue after the last complete frame in OUTDIR (gives the same "
                  "frames as an uninterrupted run)");
    sub->add_option("--threads", o->threads,
                    "Threads (0: all; default 1); results do not depend on it")
        ->type_name("N");
    sub->add_option("--cache", o->cache,
                    "Also write a point cache per object, streamed frame by frame: mdd "
                    "(OUTDIR/<object>.mdd, LightWave MDD, which Houdini, Blender, 3ds Max, "
                    "Modo and Cinema 4D play as one animated object; docs/dcc.md)")
        ->type_name("FORMAT");
    sub->add_flag("--json", o->json, "Print run.json's content to stdout at the end");
    sub->add_flag("--strict", o->strict,
                  "Exit 4 at the first frame that ends over-stretched (beyond [solver] "
                  "over_stretch) or with cloth inside a collider, before writing it (for farms "
                  "that must not render bad caches); without it such frames are written with a "
                  "warning");
    return {sub, [o] { return runSim(*o); }};
}

} // namespace gale::cli
