// Tests for a run frame by frame (run/sim_run.h, run/sim_output.h): load errors by kind, the
// stepping both front ends share, and the output folder: a run killed after some frames (a
// child process) and resumed writes the same frames, MDD cache and stats as an uninterrupted
// one; a second writer of a folder is refused while the first holds it.
#include "run/sim_json.h"
#include "run/sim_output.h"
#include "run/sim_run.h"

#include "io/mdd.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

using namespace gale;
namespace fs = std::filesystem;

namespace {

const char* kScene = R"([scene]
fps = 24
frames = [1, 8]
substeps = 2

[[field]]
name = "main"
source = "[3, 0, sin(4 * $t)]"

[[cloth]]
name = "c"
grid = { size = [0.4, 0.4], res = [6, 6], origin = [-0.2, 0.5, 0], axes = "xy" }
density = 0.1
stretch = 400.0
shear = 40.0
lift = 0.3
drag = 1.0
pins = { box = [-1, 0.49, -1, 1, 0.51, 1] }
)";

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string writeScene(const io::test::TempDir& dir, const std::string& text) {
    const std::string path = dir.file("scene.toml");
    std::ofstream(path) << text;
    return path;
}

run::SimSetup setup(const std::string& scene, std::vector<std::string> sets = {}) {
    run::SimSetup s;
    s.scene = scene;
    s.sets = std::move(sets);
    return s;
}

// Runs frames up to `stopAfter` (all when 0) into `out`; false on any error.
bool runTo(const std::string& scene, const std::string& out, bool resume, int stopAfter) {
    run::SimRun sim;
    std::string report;
    if (sim.load(setup(scene), report)) return false;
    run::SimOutput o;
    std::vector<std::string> notes;
    if (o.open(sim, {out, resume, true}, notes)) return false;
    if (o.nextFrame() == sim.first() && o.saveFrame(sim.initialFrame())) return false;
    for (int f = o.nextFrame(); f <= sim.last(); ++f) {
        if (stopAfter && f > stopAfter) return true;
        const solver::FrameStats st = sim.advance(f);
        if (st.failed || o.saveFrame(st)) return false;
    }
    std::string text;
    return !o.finish(text);
}

// The stats JSON without wall times (they differ from run to run).
std::string withoutWall(std::string s) {
    for (size_t at; (at = s.find("\"wall_seconds\": ")) != std::string::npos;) {
        const size_t end = s.find(',', at);
        s.erase(at, end - at + 1);
    }
    return s;
}

} // namespace

TEST_CASE("run: load errors come back by kind, never printed", "[run]") {
    io::test::TempDir dir;
    run::SimRun sim;
    std::string report;
    run::RunError e = sim.load(setup(dir.file("none.toml")), report);
    CHECK(e.kind == run::RunError::Io);
    CHECK(e.rendered.find("none.toml") != std::string::npos);

    const std::string scene = writeScene(dir, kScene);
    run::SimSetup bad = setup(scene, {"cloth.c.dragg=1"});
    e = sim.load(bad, report);
    CHECK(e.kind == run::RunError::Input);
    CHECK(e.rendered.find("did you mean 'drag'") != std::string::npos);

    std::ofstream(dir.file("wind.toml"))
        << "[scene]\nfps = 24\n\n[[field]]\nname = \"w\"\nsource = \"[1, 0, 0]\"\n";
    e = sim.load(setup(dir.file("wind.toml")), report);
    CHECK(e.kind == run::RunError::Input);
    CHECK(e.message.find("no [[cloth]] or [[hair]]") != std::string::npos);
}

TEST_CASE("run: stepping is deterministic and starts from the initial state at the first frame",
          "[run]") {
    io::test::TempDir dir;
    const std::string scene = writeScene(dir, kScene);
    run::SimRun a, b;
    std::string report;
    run::SimSetup s = setup(scene);
    s.hasFrames = true;
    s.first = 3;
    s.last = 6;
    REQUIRE_FALSE(a.load(s, report));
    REQUIRE_FALSE(b.load(s, report));
    CHECK(a.first() == 3);
    CHECK(a.last() == 6);
    const solver::FrameStats init = a.initialFrame();
    CHECK(init.frame == 3);
    CHECK(init.time == 3 / 24.0);
    CHECK(init.bodies.at(0).substeps == 0);
    const auto x0 = a.world().bodies()[0]->positions();
    for (int f = 4; f <= 6; ++f) {
        const solver::FrameStats sa = a.advance(f), sb = b.advance(f);
        CHECK(sa.time == Approx(f / 24.0).margin(1e-12));
        CHECK(withoutWall(run::frameJson(sa)) == withoutWall(run::frameJson(sb)));
    }
    CHECK(a.world().bodies()[0]->positions() == b.world().bodies()[0]->positions());
    CHECK((a.world().bodies()[0]->positions() - x0).cwiseAbs().maxCoeff() > 1e-4);
    CHECK(a.settings().find("\"frames\": [3, 6]") != std::string::npos);
}

TEST_CASE("run: killed after frame 4 and resumed, the output is the uninterrupted run's", "[run]") {
    io::test::TempDir dir;
    const std::string scene = writeScene(dir, kScene);
    const std::string full = dir.file("full"), part = dir.file("part");
    REQUIRE(runTo(scene, full, false, 0));

    // The interrupted run in a child process: its lock on the folder ends with it.
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(runTo(scene, part, false, 4) ? 0 : 1);
    int status = 0;
    ::waitpid(pid, &status, 0);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);
    CHECK(fs::exists(fs::path(part) / "c.0004.obj"));
    CHECK_FALSE(fs::exists(fs::path(part) / "c.0005.obj"));
    io::MddCache partial;
    REQUIRE_FALSE(io::readMddFile((fs::path(part) / "c.mdd").string(), partial));
    CHECK(partial.frames() == 4);

    run::SimRun sim;
    std::string report;
    REQUIRE_FALSE(sim.load(setup(scene), report));
    run::SimOutput o;
    std::vector<std::string> notes;
    REQUIRE_FALSE(o.open(sim, {part, true, true}, notes));
    CHECK(o.nextFrame() == 5);
    REQUIRE(notes.size() == 1);
    CHECK(notes[0] == "gale: resuming after frame 4");
    for (int f = 5; f <= 8; ++f) REQUIRE_FALSE(o.saveFrame(sim.advance(f)));
    std::string text;
    REQUIRE_FALSE(o.finish(text));

    for (int f = 1; f <= 8; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "c.%04d.obj", f);
        CHECK(slurp(fs::path(part) / name) == slurp(fs::path(full) / name));
    }
    CHECK(slurp(fs::path(part) / "c.mdd") == slurp(fs::path(full) / "c.mdd"));
    CHECK(withoutWall(slurp(fs::path(part) / "run.json")) ==
          withoutWall(slurp(fs::path(full) / "run.json")));

    // This process now holds `part`: a second writer is refused, naming the holder.
    run::SimRun other;
    REQUIRE_FALSE(other.load(setup(scene), report));
    run::SimOutput second;
    const run::RunError e = second.open(other, {part, true, false}, notes);
    CHECK(e.kind == run::RunError::Io);
    CHECK(e.message.find("being written by another gale sim (pid " + std::to_string(::getpid()) +
                         ")") != std::string::npos);
}
