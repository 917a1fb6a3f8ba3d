// The two halves of the scene loader, over one parsed file: the wind's sections
// (wind_sections.cpp) and the bodies' (body_sections.cpp). scene/load.cpp reads and parses the
// file once and runs them in that order. Internal to scene/: not part of the public API.
#pragma once

#include "scene/load.h"

#include <toml++/toml.h>

#include <string>
#include <vector>

namespace gale::scene {

// Reads `path` into `text` and parses it into `root`. False (with the error: an unreadable file,
// marked io, or the syntax error at its file:line:col) when either fails.
bool readSceneFile(const std::string& path, std::string& text, toml::table& root,
                   std::vector<SceneError>& errors);
// Parses `text` (the contents of `path`) into `root`; false with the syntax error at its
// file:line:col.
bool parseSceneText(const std::string& path, const std::string& text, toml::table& root,
                    std::vector<SceneError>& errors);

// [scene], [windicator], [[gust]], [[field]] (with the --set overrides of options.sets for
// them, applied to `root`), and any unknown top-level key that is not in
// options.foreignSections. Errors are sorted into file order. False when there were errors.
bool loadWindSections(const std::string& path, const std::string& text, toml::table& root,
                      fields::Scene& out, std::vector<SceneError>& errors,
                      const SceneLoadOptions& options);

// [[cloth]], [[hair]], [[collider]] and [solver], with the --set overrides of `sets` for them
// (the others are the wind's to apply and report). Errors are appended in the order found.
void loadBodySections(const std::string& path, const std::string& text, toml::table& root,
                      SimScene& out, std::vector<SceneError>& errors,
                      const std::vector<std::string>& sets);

} // namespace gale::scene
