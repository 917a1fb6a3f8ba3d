// Loading a scene for simulation and stepping it (run/sim_run.h): the part of a run both front
// ends share, with no files written and nothing printed.
#include "run/sim_run.h"

#include "fields/expression_field.h"
#include "run/sim_json.h"
#include "scene/load.h"
#include "scene/scene_checks.h"

#include "io/frame_pattern.h"
#include "solver/collider/moving_collider.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace gale::run {

namespace {

// FNV-1a, 64 bits: a digest of inputs, not a security hash.
struct Digest {
    uint64_t h = 1469598103934665603ull;
    void add(const std::string& s) {
        for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
        h = (h ^ 0xff) * 1099511628211ull; // a separator: "ab","c" differs from "a","bc"
    }
    // A file's bytes (small text files: the scene, expressions).
    void addBytes(const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        add(path);
        add(in ? std::string(std::istreambuf_iterator<char>(in), {}) : std::string("<unreadable>"));
    }
    // A file's size and modification time (meshes, which may be large), or of every frame file
    // of a sequence's folder with the same extension.
    void addStamp(const std::string& path) {
        namespace fs = std::filesystem;
        add(path);
        std::error_code ec;
        if (!io::hasFrameToken(fs::path(path).filename().string())) {
            add(std::to_string(fs::file_size(path, ec)) + "@" +
                std::to_string(fs::last_write_time(path, ec).time_since_epoch().count()));
            return;
        }
        std::vector<std::string> names;
        for (fs::directory_iterator it(fs::path(path).parent_path(), ec), end; !ec && it != end;
             it.increment(ec))
            if (it->path().extension() == fs::path(path).extension())
                names.push_back(it->path().string());
        std::sort(names.begin(), names.end());
        for (const std::string& n : names) addStamp(n);
    }
    std::string text() const {
        char buf[32];
        std::snprintf(buf, sizeof buf, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
        return buf;
    }
};

std::string digestInputs(const scene::SimScene& sc, const std::vector<std::string>& sets) {
    Digest d;
    d.addBytes(sc.wind.path);
    for (const std::string& s : sets) d.add(s);
    for (const fields::FieldEntry& f : sc.wind.fields)
        if (!f.exprPath.empty()) d.addBytes(f.exprPath);
    for (const scene::ClothSpec& c : sc.cloths) {
        for (const scene::PaintedSpec* p : {&c.lift, &c.drag})
            if (!p->exprPath.empty()) d.addBytes(p->exprPath);
        for (const std::string* m : {&c.meshPath, &c.restMeshPath, &c.attachMesh})
            if (!m->empty()) d.addStamp(*m);
    }
    for (const scene::HairSpec& h : sc.hairs) {
        for (const scene::PaintedSpec* p : {&h.dragNormal, &h.dragTangent})
            if (!p->exprPath.empty()) d.addBytes(p->exprPath);
        for (const std::string* m : {&h.strandsPath, &h.attachMesh})
            if (!m->empty()) d.addStamp(*m);
    }
    for (const solver::Collider& c : sc.colliders)
        if (c.moving) d.addStamp(c.moving->mesh().path());
    return d.text();
}

} // namespace

RunError SimRun::load(const SimSetup& s, std::string& report) {
    RunError err;
    std::vector<scene::SceneError> errors;
    auto sceneErrors = [&](const std::vector<scene::SceneError>& es) {
        err.kind = RunError::Input;
        for (const scene::SceneError& e : es) {
            err.rendered += e.render() + '\n';
            if (e.io) err.kind = RunError::Io;
        }
        return err;
    };
    mScene = scene::SimScene();
    if (!gale::scene::loadSimScene(s.scene, mScene, errors, s.sets)) return sceneErrors(errors);
    std::string fieldReport;
    fields::FieldPtr wind = fields::buildSceneField(mScene.wind, runtime::Precision::Float,
                                                    fieldReport, s.color, s.allowPaths);
    report += fieldReport;
    if (!wind) {
        err.kind = RunError::Input;
        return err;
    }
    std::vector<std::unique_ptr<solver::Body>> bodies;
    std::vector<std::string> warnings;
    mFirst = s.hasFrames ? s.first : mScene.wind.settings.frameStart;
    mLast = s.hasFrames ? s.last : mScene.wind.settings.frameEnd;
    // The pre-roll ends where the shot (or an earlier --frames range) starts; a range that starts
    // mid-shot simulates from there too. Attachments bind against their bodies where the
    // simulation starts: the run-up's first frame (the bodies' rest pose under a pre-roll).
    const int shotStart = std::min(mFirst, mScene.wind.settings.frameStart);
    mRunUpFrom = shotStart - mScene.wind.settings.preroll;
    if (!scene::buildShotBodies(mScene, shotStart, bodies, errors, warnings, s.allowPaths))
        return sceneErrors(errors);
    mWarnings.clear();
    for (const std::string& w : warnings) {
        report += "gale: warning: " + w + '\n';
        mWarnings.push_back(w);
    }
    if (bodies.empty()) {
        err.kind = RunError::Input;
        err.message = s.scene + ": the scene has no [[cloth]] or [[hair]] to simulate";
        return err;
    }
    mSettings = settingsJson(mScene, bodies, mFirst, mLast, s.threads, s.sets);
    mInputs = digestInputs(mScene, s.sets);
    for (const scene::SceneError& w : scene::runWarnings(mScene, bodies, mFirst, mLast)) {
        report += w.render() + '\n';
        // As the bodies' warnings: "file:line:col: message", without the source line.
        mWarnings.push_back(w.location() + ": " + w.message);
    }

    mWorld = std::make_unique<solver::World>(scene::worldSettings(mScene, s.threads));
    mWorld->setWind(wind);
    for (auto& b : bodies) mWorld->addBody(std::move(b));
    for (const solver::Collider& c : mScene.colliders) mWorld->addCollider(c);
    return err;
}

const std::string& SimRun::outputFormat(size_t i) const {
    return i < mScene.cloths.size() ? mScene.cloths[i].output
                                    : mScene.hairs[i - mScene.cloths.size()].output;
}

bool SimRun::runUp(const std::function<void(const solver::FrameStats&)>& each,
                   solver::FrameStats& failed) {
    for (int f = mRunUpFrom + 1; f <= mFirst; ++f) {
        const solver::FrameStats stats = mWorld->advanceFrame(f);
        if (each) each(stats);
        if (stats.failed) {
            failed = stats;
            return false;
        }
    }
    return true;
}

solver::FrameStats SimRun::initialFrame() const {
    return initialStats(*mWorld, mFirst, mScene.wind.settings.frameTime(mFirst));
}

} // namespace gale::run
