// The resolved scene of one `gale wedge` variant: the scene document (scene/document.h) with
// the variant's overrides applied by dotted path (as `gale sim --set` applies them) and relative
// file names made absolute, written back so the variant folder holds a scene that runs on its own.
#include "cli/wedge/wedge.h"

#include "scene/document.h"

namespace gale::cli {

bool resolveVariantScene(const std::string& scenePath, const std::vector<std::string>& sets,
                         const std::string& header, std::string& out, std::string& error) {
    scene::SceneDocument doc;
    std::vector<scene::SceneError> errors;
    if (!doc.read(scenePath, errors) || !doc.applySets(sets, errors)) {
        error = errors.empty() ? scenePath + ": cannot resolve the scene" : errors.front().render();
        return false;
    }
    doc.absolutisePaths();
    out = doc.write(header);
    return true;
}

} // namespace gale::cli
