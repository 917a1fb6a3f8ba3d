// libFuzzer harness: bytes -> scene.toml in a private temp folder (beside wind.se, lift.se,
// mesh.obj, strands.csv) -> the wind and solver loaders, then the summed wind field (sampled at a
// few points) and the bodies when small. No simulation step is run.
#include "fields/expression_field.h"
#include "fields/scene.h"
#include "scene/load.h"
#include "scene/sim_scene.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace gale;

namespace {

// How many inputs got how far; printed at exit when GALE_FUZZ_STATS is set.
struct Stats {
    size_t inputs = 0, loaded = 0, small = 0, fields = 0, bodies = 0;
    ~Stats() {
        if (std::getenv("GALE_FUZZ_STATS"))
            std::fprintf(stderr, "fuzz_scene stats: %zu inputs, %zu loaded, %zu small, %zu with a wind field, %zu with bodies\n",
                         inputs, loaded, small, fields, bodies);
    }
} gStats;

// A folder of our own for the run: $TMPDIR (or /dev/shm, /tmp)/gale-fuzz-scene-PID.
const std::string& workDir() {
    static const std::string dir = [] {
        const char* base = std::getenv("TMPDIR");
        std::string root = base && *base ? base : std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
        std::string d = root + "/gale-fuzz-scene-" + std::to_string(getpid());
        std::filesystem::create_directories(d);
        // Files a fuzzed scene may name (the seeds do): an expression, a mesh, strands.
        std::ofstream(d + "/wind.se") << "$speed = 4; # 0, 10\n[$speed, 0, 0.5 * sin(3 * $t)] + 0.2 * vnoise($P)\n";
        std::ofstream(d + "/lift.se") << "0.5 + 0.5 * $u\n";
        std::ofstream(d + "/mesh.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                          "f 1/1 2/2 3/3 4/4\n";
        std::ofstream(d + "/strands.csv") << "x,y,z,strand\n0,0,0,0\n0,-0.1,0,0\n0,-0.2,0,0\n0.1,0,0,1\n0.1,-0.1,0,1\n";
        return d;
    }();
    return dir;
}

// Files the scene may name are read only when they are inside the work folder (so a fuzzed
// path such as /dev/zero cannot stall the run); only the files written above exist there.
bool inside(const std::string& path) { return path.empty() || path.rfind(workDir() + "/", 0) == 0; }

bool smallAndLocal(const scene::SimScene& s) {
    for (const fields::FieldEntry& f : s.wind.fields) {
        if (!inside(f.exprPath)) return false;
        // FFT turbulence builds grids up to 512^3: too big for a fuzzing run.
        if (f.source.find("fftturb") != std::string::npos || f.mask.find("fftturb") != std::string::npos)
            return false;
    }
    for (const scene::ClothSpec& c : s.cloths)
        if (!inside(c.meshPath) || !inside(c.lift.exprPath) || !inside(c.drag.exprPath) ||
            static_cast<long long>(c.gridRes[0]) * c.gridRes[1] > 4096)
            return false;
    for (const scene::HairSpec& h : s.hairs)
        if (!inside(h.strandsPath) || !inside(h.dragNormal.exprPath) || !inside(h.dragTangent.exprPath) ||
            static_cast<long long>(h.gridCount[0]) * h.gridCount[1] * (h.segments + 1) > 4096)
            return false;
    return true;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 65536) return 0;
    const std::string path = workDir() + "/scene.toml";
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    scene::SimScene scene;
    std::vector<scene::SceneError> errors;
    ++gStats.inputs;
    const bool loaded = gale::scene::loadSimScene(path, scene, errors);
    for (const scene::SceneError& e : errors) (void)e.render();
    if (loaded && !errors.empty()) __builtin_trap(); // success must not come with errors
    if (!loaded) {
        if (errors.empty()) __builtin_trap(); // a failure must say why
        return 0;
    }
    ++gStats.loaded;
    if (!smallAndLocal(scene)) return 0;
    ++gStats.small;

    // Every preset is a real expression; the scene's fields compile and sample.
    std::string report;
    fields::FieldPtr wind = fields::buildSceneField(scene.wind, runtime::Precision::Float, report);
    if (wind) {
        ++gStats.fields;
        const double positions[12] = {0, 0, 0, 1, 2, 3, -0.5, 0.25, 4, 1e3, -1e3, 7};
        double velocities[12] = {};
        fields::SampleTime when;
        when.time = 0.5;
        when.fps = scene.wind.settings.fps;
        wind->sample(positions, 4, when, velocities);
    }
    std::vector<std::unique_ptr<solver::Body>> bodies;
    std::vector<std::string> warnings;
    std::vector<scene::SceneError> buildErrors;
    if (!scene::buildBodies(scene, bodies, buildErrors, warnings) && buildErrors.empty()) __builtin_trap();
    if (!bodies.empty()) ++gStats.bodies;
    (void)scene::worldSettings(scene, 1);
    return 0;
}
