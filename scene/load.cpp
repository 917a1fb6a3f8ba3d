// The scene loader's entry points: one read and one parse of the file, then the wind's sections
// and (for a whole scene) the bodies' over the same TOML tree.
#include "scene/load.h"

#include "scene/sections.h"

#include <filesystem>

namespace gale::scene {

namespace {

void startScene(const std::string& path, fields::Scene& out) {
    out = fields::Scene{};
    out.path = path;
    out.baseDir = std::filesystem::path(path).parent_path().string();
}

} // namespace

bool loadScene(const std::string& path, fields::Scene& out, std::vector<SceneError>& errors,
               const SceneLoadOptions& options) {
    startScene(path, out);
    std::string text;
    toml::table root;
    if (!readSceneFile(path, text, root, errors)) return false;
    return loadWindSections(path, text, root, out, errors, options);
}

bool loadSimScene(const std::string& path, SimScene& out,
                  std::vector<SceneError>& errors, const std::vector<std::string>& sets) {
    out = SimScene{};
    startScene(path, out.wind);
    SceneLoadOptions options;
    options.sets = sets;
    std::string text;
    toml::table root;
    if (!readSceneFile(path, text, root, errors)) return false;
    const bool windOk = loadWindSections(path, text, root, out.wind, errors, options);
    const size_t bodyErrors = errors.size();
    loadBodySections(path, text, root, out, errors, sets);
    return windOk && errors.size() == bodyErrors;
}

} // namespace gale::scene
