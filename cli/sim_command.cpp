// `gale sim SCENE.toml`: runs the scene's cloth and hair in its wind, writing one OBJ/PLY per
// object and frame (atomically), the solver state per frame for --resume, and run.json with the
// resolved settings and per-frame statistics. Exit 4 when the run failed numerically.
#include "cli/commands.h"
#include "cli/common.h"

#include "io/atomic_file.h"
#include "io/pointset.h"
#include "fields/expression_field.h"
#include "scene/load.h"
#include "solver/scene.h"

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

namespace gale::cli {

namespace {

namespace fs = std::filesystem;
using solver::Body;

std::string num(double v) { return std::isfinite(v) ? io::formatNumber(v) : "null"; }

std::string vec(const std::vector<double>& v) {
    std::string s = "[";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
    return s + "]";
}

// A parameter as JSON: its value at `t`, and whether it is keyframed.
std::string paramJson(const fields::Param& p, double t) {
    std::string s = p.width() == 1 ? num(p.scalarAt(t)) : vec(p.at(t));
    return p.isKeyed() ? "{\"at_start\": " + s + ", \"keyed\": true}" : s;
}

const char* solverName(solver::LinearSolverKind k) { return k == solver::LinearSolverKind::Direct ? "direct" : "pcg"; }

std::string stepJson(const solver::StepOptions& s) {
    return "\"linear_solver\": \"" + std::string(solverName(s.linearSolver)) +
           "\", \"cg_tolerance\": " + num(s.cgTolerance) +
           ", \"cg_max_iterations\": " + std::to_string(s.cgMaxIterations) +
           ", \"preconditioner\": \"" +
           (s.preconditioner == solver::Preconditioner::Multigrid ? "multigrid" : "jacobi") +
           "\", \"newton_iterations\": " + std::to_string(s.newtonIterations) +
           ", \"newton_tolerance\": " + num(s.newtonTolerance);
}

// The settings as resolved (after --set), for run.json and to check that --resume continues
// the same run.
std::string settingsJson(const solver::SimScene& sc, const std::vector<std::unique_ptr<Body>>& bodies, int first,
                         int last, int threads) {
    const fields::SceneSettings& s = sc.wind.settings;
    const double t0 = first / s.fps;
    std::ostringstream o;
    o << "{\"scene\": " << jsonString(sc.wind.path) << ", \"fps\": " << num(s.fps) << ", \"frames\": [" << first
      << ", " << last << "], \"substeps\": " << s.substeps << ", \"gravity\": " << vec(s.gravity)
      << ", \"air_density\": " << num(s.airDensity) << ", \"threads\": " << threads
      << ", \"solver\": {\"max_halvings\": " << sc.solver.maxHalvings << ", \"over_stretch\": "
      << num(sc.solver.overStretch) << ", \"velocity_jump\": " << num(sc.solver.velocityJump) << "}";
    o << ", \"fields\": [";
    for (size_t i = 0; i < sc.wind.fields.size(); ++i) o << (i ? ", " : "") << jsonString(sc.wind.fields[i].name);
    o << "], \"objects\": [";
    size_t bi = 0;
    for (const solver::ClothSpec& c : sc.cloths) {
        const Body* b = bi < bodies.size() ? bodies[bi++].get() : nullptr;
        const solver::ClothMaterial& m = c.material;
        o << (bi > 1 ? ", " : "") << "{\"name\": " << jsonString(c.name) << ", \"kind\": \"cloth\", \"geometry\": "
          << (c.meshPath.empty() ? "\"grid\"" : jsonString(c.meshPath)) << ", \"vertices\": " << (b ? b->vertexCount() : 0)
          << ", \"pinned\": " << (b ? b->pinnedVertices().size() : 0) << ", \"density\": " << num(m.density)
          << ", \"stretch\": " << paramJson(m.stretch, t0) << ", \"shear\": " << paramJson(m.shear, t0)
          << ", \"bend\": " << paramJson(m.bend, t0) << ", \"damping\": " << paramJson(m.damping, t0)
          << ", \"lift\": " << paramJson(c.lift.value, t0) << ", \"lift_painted\": "
          << (c.lift.map.empty() && c.lift.exprPath.empty() && c.lift.source.empty() ? "false" : "true")
          << ", \"drag\": " << paramJson(c.drag.value, t0) << ", \"drag_painted\": "
          << (c.drag.map.empty() && c.drag.exprPath.empty() && c.drag.source.empty() ? "false" : "true")
          << ", \"aero_model\": \"" << (m.aeroModel == solver::AeroModel::Frozen ? "frozen" : "smooth-lift")
          << "\", \"aero_jacobian\": \"" << (c.step.aeroJacobian == solver::AeroJacobian::Paper ? "paper" : "projected")
          << "\", " << stepJson(c.step) << ", \"output\": \"" << c.output << "\"}";
    }
    for (const solver::HairSpec& h : sc.hairs) {
        const Body* b = bi < bodies.size() ? bodies[bi++].get() : nullptr;
        const solver::HairMaterial& m = h.material;
        o << (bi > 1 ? ", " : "") << "{\"name\": " << jsonString(h.name) << ", \"kind\": \"hair\", \"geometry\": "
          << (h.strandsPath.empty() ? "\"grid\"" : jsonString(h.strandsPath)) << ", \"vertices\": "
          << (b ? b->vertexCount() : 0) << ", \"radius\": " << num(m.radius) << ", \"density\": " << num(m.density)
          << ", \"stretch\": " << paramJson(m.stretch, t0) << ", \"bend\": " << paramJson(m.bend, t0)
          << ", \"damping\": " << paramJson(m.damping, t0) << ", \"drag_normal\": " << paramJson(h.dragNormal.value, t0)
          << ", \"drag_tangent\": " << paramJson(h.dragTangent.value, t0)
          << ", \"root_pinned\": " << (m.rootPinned ? "true" : "false") << ", " << stepJson(h.step)
          << ", \"output\": \"" << h.output << "\"}";
    }
    o << "], \"colliders\": [";
    for (size_t i = 0; i < sc.colliders.size(); ++i) {
        const solver::Collider& c = sc.colliders[i];
        const char* type = c.shape == solver::ColliderShape::Plane ? "plane"
                           : c.shape == solver::ColliderShape::Sphere ? "sphere"
                           : c.shape == solver::ColliderShape::Mesh   ? "mesh" : "capsule";
        o << (i ? ", " : "") << "{\"name\": " << jsonString(c.name) << ", \"type\": \"" << type
          << "\", \"radius\": " << num(c.radius) << ", \"thickness\": " << num(c.thickness)
          << ", \"friction\": " << num(c.friction) << "}";
    }
    o << "]}";
    return o.str();
}

std::string frameJson(const solver::FrameStats& f) {
    std::ostringstream o;
    o << "{\"frame\": " << f.frame << ", \"time\": " << num(f.time) << ", \"wall_seconds\": " << num(f.wallSeconds)
      << ", \"failed\": " << (f.failed ? "true" : "false") << ", \"objects\": [";
    for (size_t i = 0; i < f.bodies.size(); ++i) {
        const solver::BodyFrameStats& b = f.bodies[i];
        o << (i ? ", " : "") << "{\"name\": " << jsonString(b.name)
          << ", \"substeps\": " << b.substeps << ", \"rejected_substeps\": " << b.rejected << ", \"recovered_substeps\": " << b.recovered << ", \"newton_retries\": " << b.newtonRetries
          << ", \"deepest_halving\": " << b.deepestHalving
          << ", \"solver_iterations\": " << b.iterations
          << ", \"max_iterations\": " << b.maxIterations
          << ", \"max_residual\": " << num(b.maxResidual)
          << ", \"newton_iterations\": " << b.newtonIterations
          << ", \"max_newton_iterations\": " << b.maxNewtonIterations
          << ", \"max_newton_residual\": " << num(b.maxNewtonResidual)
          << ", \"line_search_cuts\": " << b.lineSearchCuts
          << ", \"newton_unconverged\": " << b.newtonStalled
          << ", \"max_speed\": " << num(b.maxSpeed) << ", \"max_stretch\": " << num(b.maxStretch)
          << ", \"energy\": {\"kinetic\": " << num(b.kinetic) << ", \"elastic\": " << num(b.elastic)
          << ", \"potential\": " << num(b.potential)
          << ", \"total\": " << num(b.kinetic + b.elastic + b.potential)
          << "}, \"wind_non_finite\": " << b.windNonFinite
          << ", \"clamped_jacobians\": " << b.clampedJacobians << ", \"contacts\": " << b.contacts
          << ", \"failed\": " << (b.failed ? "true" : "false") << ", \"events\": [";
        for (size_t e = 0; e < b.events.size(); ++e) o << (e ? ", " : "") << jsonString(b.events[e]);
        o << "]}";
    }
    o << "]}";
    return o.str();
}

// The frame's stats of the initial state (no substeps taken).
solver::FrameStats initialStats(const solver::World& w, int frame, double fps) {
    solver::FrameStats f;
    f.frame = frame;
    f.time = frame / fps;
    for (const auto& b : w.bodies()) {
        solver::BodyFrameStats s;
        s.name = b->name();
        s.maxStretch = b->maxEdgeStretch();
        s.kinetic = b->kineticEnergy();
        s.potential = b->potentialEnergy(w.settings().gravity);
        s.elastic = const_cast<Body&>(*b).elasticEnergy(f.time);
        f.bodies.push_back(s);
    }
    return f;
}

std::string frameFile(const std::string& dir, const std::string& object, int frame, const std::string& ext) {
    char buf[32];
    std::snprintf(buf, sizeof buf, ".%04d.", frame);
    return (fs::path(dir) / (object + buf + ext)).string();
}

std::string stateFile(const std::string& dir, int frame, const char* ext) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%04d.%s", frame, ext);
    return (fs::path(dir) / ".state" / buf).string();
}

bool readFile(const std::string& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

int writeBytes(const std::string& path, const std::string& bytes) {
    if (io::IoError e = io::writeBytesAtomic(path, bytes)) {
        printError(e.render());
        return kExitIo;
    }
    return kExitOk;
}

// Writes every object's shape for `frame`.
int writeFrame(const solver::SimScene& sc, const solver::World& w, const std::string& dir, int frame) {
    size_t bi = 0;
    auto formatOf = [&](size_t i) {
        return i < sc.cloths.size() ? sc.cloths[i].output : sc.hairs[i - sc.cloths.size()].output;
    };
    for (const auto& b : w.bodies()) {
        const std::string format = formatOf(bi++);
        const std::string path = frameFile(dir, b->name(), frame, format);
        if (format == "ply") {
            if (io::IoError e = io::writePointsFile(path, solver::bodyPointSet(*b), io::PointFormat::Ply)) {
                printError(e.render());
                return kExitIo;
            }
        } else if (int rc = writeBytes(path, solver::bodyObjText(*b))) {
            return rc;
        }
    }
    return kExitOk;
}

// Takes an exclusive lock on OUTDIR/.state/lock for the rest of the process (the kernel drops it
// when the process ends, even killed), so two runs never write one folder at once: a wedge
// re-run while the simulations of a killed wedge still run, two farm tasks on one variant.
int lockOutput(const std::string& dir) {
    const std::string path = (fs::path(dir) / ".state" / "lock").string();
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
        printError(path + ": cannot create the lock file: " + std::strerror(errno));
        return kExitIo;
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        char buf[32] = {};
        const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
        const std::string pid = n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string();
        if (err != EWOULDBLOCK) return kExitOk; // no locks on this file system: run unguarded
        ::close(fd);
        printError(dir + " is being written by another gale sim" + (pid.empty() ? std::string() : " (pid " + pid + ")") +
                   "; wait for it to finish or stop it, then run again (with --resume to continue its frames)");
        return kExitIo;
    }
    const std::string pid = std::to_string(static_cast<long>(::getpid()));
    // The pid only names the holder in the message above; the lock holds without it.
    const bool noted = ::pwrite(fd, pid.data(), pid.size(), 0) == static_cast<ssize_t>(pid.size()) &&
                       ::ftruncate(fd, static_cast<off_t>(pid.size())) == 0;
    (void)noted;
    return kExitOk; // fd stays open (and locked) until the process ends
}

// Removes the temporary files a killed run left (a frame, run.json or state being written).
void removeStaleTemps(const std::string& dir, const solver::World& w) {
    std::vector<std::string> names;
    for (const auto& b : w.bodies()) names.push_back(b->name() + ".");
    auto endsWith = [](const std::string& s, const char* tail) {
        const size_t n = std::strlen(tail);
        return s.size() >= n && s.compare(s.size() - n, n, tail) == 0;
    };
    io::removeStaleTempFiles(dir, [&](const std::string& target) {
        if (target == "run.json") return true;
        if (!endsWith(target, ".obj") && !endsWith(target, ".ply")) return false;
        for (const std::string& n : names)
            if (target.compare(0, n.size(), n) == 0) return true;
        return false;
    });
    io::removeStaleTempFiles((fs::path(dir) / ".state").string(), [](const std::string&) { return true; });
}

class Progress {
public:
    explicit Progress(int total) : mTotal(total), mOn(isatty(2) != 0), mStart(std::chrono::steady_clock::now()) {}
    void update(int done, int frame) {
        if (!mOn) return;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - mStart).count();
        const double eta = done > 0 ? elapsed / done * (mTotal - done) : 0.0;
        std::fprintf(stderr, "\rgale sim: frame %d  %d/%d (%3d%%)  %.2f s/frame  ETA %.0f s   ", frame, done, mTotal,
                     mTotal ? 100 * done / mTotal : 100, done ? elapsed / done : 0.0, eta);
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
    int first = 0, last = 0;
    const bool frameRange = !o.frames.empty();
    if (frameRange && !parseFrames(o.frames, first, last)) {
        printError("--frames must be A:B with whole numbers A <= B, at most " +
                       std::to_string(kMaxFrames) + " frames, not '" + o.frames + "'");
        return kExitUsage;
    }

    // The scene: wind and solver sections, then the field and the bodies.
    solver::SimScene scene;
    std::vector<fields::SceneError> errors;
    const bool loaded = gale::scene::loadSimScene(o.scene, scene, errors, o.sets);
    auto report = [&](const std::vector<fields::SceneError>& es) {
        bool io = false;
        for (const fields::SceneError& e : es) {
            std::cerr << e.render() << '\n';
            io = io || e.io;
        }
        return io ? kExitIo : kExitInput;
    };
    if (!loaded) return errors.empty() ? kExitInput : report(errors);
    std::string fieldReport;
    fields::FieldPtr wind = fields::buildSceneField(scene.wind, runtime::Precision::Float, fieldReport, useColor(),
                                                    o.allowPaths);
    if (!fieldReport.empty()) std::cerr << fieldReport << std::flush;
    if (!wind) return kExitInput;
    std::vector<std::unique_ptr<Body>> bodies;
    std::vector<std::string> warnings;
    if (!solver::buildBodies(scene, bodies, errors, warnings, o.allowPaths)) return report(errors);
    for (const std::string& w : warnings) std::cerr << "gale: warning: " << w << '\n';
    if (bodies.empty()) {
        printError(o.scene + ": the scene has no [[cloth]] or [[hair]] to simulate");
        return kExitInput;
    }
    if (!frameRange) {
        first = scene.wind.settings.frameStart;
        last = scene.wind.settings.frameEnd;
    }
    const std::string settings = settingsJson(scene, bodies, first, last, o.threads);

    solver::World world(solver::worldSettings(scene, o.threads));
    world.setWind(wind);
    for (auto& b : bodies) world.addBody(std::move(b));
    for (const solver::Collider& c : scene.colliders) world.addCollider(c);

    std::error_code ec;
    fs::create_directories(fs::path(o.output) / ".state", ec);
    if (ec) {
        printError(o.output + ": cannot create the output folder: " + ec.message());
        return kExitIo;
    }
    if (int rc = lockOutput(o.output)) return rc;
    removeStaleTemps(o.output, world);

    // --resume: the last frame whose state and stats were saved, by this same run.
    std::vector<std::string> frames;
    int start = first;
    if (o.resume) {
        std::string saved;
        if (readFile((fs::path(o.output) / ".state" / "settings.json").string(), saved) && saved != settings) {
            printError(o.output + ": the saved run has different settings (scene, --set or --frames changed); "
                                  "run without --resume to start over");
            return kExitInput;
        }
        int resumeAt = -1;
        for (int f = last; f >= first && resumeAt < 0; --f) {
            std::string st, js;
            if (readFile(stateFile(o.output, f, "bin"), st) && readFile(stateFile(o.output, f, "json"), js)) {
                std::string error;
                if (!world.loadState(st, error)) {
                    // Damaged (a crash of the machine rather than of gale): an earlier frame's
                    // state gives the same frames, only later.
                    std::cerr << "gale: warning: " << stateFile(o.output, f, "bin") << ": " << error
                              << "; resuming from an earlier frame\n";
                    continue;
                }
                resumeAt = f;
            }
        }
        if (resumeAt >= 0) {
            for (int f = first; f <= resumeAt; ++f) {
                std::string js;
                if (!readFile(stateFile(o.output, f, "json"), js)) {
                    printError(stateFile(o.output, f, "json") + ": missing; run without --resume to start over");
                    return kExitIo;
                }
                frames.push_back(js);
            }
            start = resumeAt + 1;
            std::cerr << "gale: resuming after frame " << resumeAt << '\n';
        }
    }
    if (start == first) {
        // Starting over: the states of an earlier run must not be resumed with this run's frames.
        std::vector<fs::path> old;
        for (fs::directory_iterator it(fs::path(o.output) / ".state", ec), end; !ec && it != end; it.increment(ec))
            if (it->path().filename() != "lock") old.push_back(it->path());
        for (const fs::path& p : old) fs::remove(p, ec);
    }
    if (int rc = writeBytes((fs::path(o.output) / ".state" / "settings.json").string(), settings)) return rc;

    auto writeRun = [&](const std::string& status) {
        std::string run = "{\"status\": \"" + status + "\", \"settings\": " + settings + ", \"frames\": [";
        for (size_t i = 0; i < frames.size(); ++i) run += (i ? ",\n  " : "\n  ") + frames[i];
        run += "\n]}\n";
        return std::make_pair(writeBytes((fs::path(o.output) / "run.json").string(), run), run);
    };
    // run.json holds every frame so far, so rewriting it after each frame costs O(frames²)
    // bytes over a run: while running it is rewritten at most once a second (and after the
    // first frame); --resume reads the per-frame .state files, never run.json.
    auto lastRunWrite = std::chrono::steady_clock::now();
    bool runWritten = false;
    auto saveFrame = [&](const solver::FrameStats& fsStats) -> int {
        if (int rc = writeFrame(scene, world, o.output, fsStats.frame)) return rc;
        const std::string js = frameJson(fsStats);
        if (int rc = writeBytes(stateFile(o.output, fsStats.frame, "bin"), world.saveState())) return rc;
        if (int rc = writeBytes(stateFile(o.output, fsStats.frame, "json"), js)) return rc;
        frames.push_back(js);
        const auto now = std::chrono::steady_clock::now();
        if (runWritten && now - lastRunWrite < std::chrono::seconds(1)) return kExitOk;
        runWritten = true;
        lastRunWrite = now;
        return writeRun("running").first;
    };

    Progress progress(last - first + 1);
    if (start == first) {
        if (int rc = saveFrame(initialStats(world, first, scene.wind.settings.fps))) return rc;
        start = first + 1;
    }
    int done = start - first;
    for (int f = start; f <= last; ++f) {
        progress.update(done, f);
        const solver::FrameStats stats = world.advanceFrame(f);
        for (const solver::BodyFrameStats& b : stats.bodies) {
            const size_t shown = std::min<size_t>(b.events.size(), 3);
            for (size_t e = 0; e < shown; ++e) {
                std::string line = "gale: frame " + std::to_string(f) + ": " + b.name + ": " + b.events[e];
                if (e + 1 == shown && b.events.size() > shown)
                    line += " (and " + std::to_string(b.events.size() - shown) + " more in run.json)";
                progress.message(line);
            }
        }
        if (stats.failed) {
            frames.push_back(frameJson(stats));
            writeRun("failed");
            progress.finish();
            printError("frame " + std::to_string(f) + ": the run failed numerically (non-finite state that halving "
                       "the substep could not fix); frames up to " + std::to_string(f - 1) +
                       " are written, details in " + (fs::path(o.output) / "run.json").string());
            return kExitNumeric;
        }
        if (int rc = saveFrame(stats)) return rc;
        ++done;
    }
    progress.update(done, last);
    progress.finish();
    const auto [rc, run] = writeRun("ok");
    if (rc) return rc;
    if (o.json) std::cout << run << std::flush;
    return kExitOk;
}

Command addSimCommand(CLI::App& app) {
    auto o = std::make_shared<SimOptions>();
    CLI::App* sub = app.add_subcommand(
        "sim", "Simulate the scene's cloth and hair in its wind: writes OUTDIR/<object>.<frame>.obj|ply per "
               "frame, OUTDIR/run.json (settings as resolved, per-frame stats) and the solver state per frame "
               "for --resume; one run at a time per OUTDIR (a second is refused, exit 3). Exit 4 when the run "
               "failed numerically.");
    sub->add_option("scene", o->scene, "Scene file (.toml) with [[cloth]] and/or [[hair]]")
        ->type_name("SCENE")
        ->required();
    sub->add_option("-o,--output", o->output, "Output folder (default: sim)")->type_name("OUTDIR");
    sub->add_option("--frames", o->frames, "Frames A to B (inclusive) instead of the scene's; frame A is the "
                                           "initial state at t = A / fps")
        ->type_name("A:B");
    sub->add_option("--set", o->sets,
                    "Override a scene key by its dotted path (cloth.cape.drag=0.8, windicator.speed=12, "
                    "collider.0.radius=0.3, solver.max_halvings=4). Repeatable")
        ->type_name("KEY=VALUE")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    addAllowPathOption(*sub, o->allowPaths);
    sub->add_flag("--resume", o->resume, "Continue after the last complete frame in OUTDIR (gives the same "
                                         "frames as an uninterrupted run)");
    sub->add_option("--threads", o->threads, "Threads (0: all; default 1); results do not depend on it")
        ->type_name("N");
    sub->add_flag("--json", o->json, "Print run.json's content to stdout at the end");
    return {sub, [o] { return runSim(*o); }};
}

} // namespace gale::cli
