// Loading a scene for simulation and stepping it (run/sim_run.h): the part of a run both front
// ends share, with no files written and nothing printed.
#include "run/sim_run.h"

#include "fields/expression_field.h"
#include "run/sim_json.h"
#include "scene/load.h"
#include "scene/scene_checks.h"

namespace gale::run {

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
    if (!scene::buildBodies(mScene, bodies, errors, warnings, s.allowPaths))
        return sceneErrors(errors);
    for (const std::string& w : warnings) report += "gale: warning: " + w + '\n';
    if (bodies.empty()) {
        err.kind = RunError::Input;
        err.message = s.scene + ": the scene has no [[cloth]] or [[hair]] to simulate";
        return err;
    }
    mFirst = s.hasFrames ? s.first : mScene.wind.settings.frameStart;
    mLast = s.hasFrames ? s.last : mScene.wind.settings.frameEnd;
    mSettings = settingsJson(mScene, bodies, mFirst, mLast, s.threads);
    for (const scene::SceneError& w : scene::runWarnings(mScene, bodies, mFirst, mLast))
        report += w.render() + '\n';

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

solver::FrameStats SimRun::initialFrame() const {
    return initialStats(*mWorld, mFirst, mScene.wind.settings.frameTime(mFirst));
}

} // namespace gale::run
