// How the value of a `--set KEY=VALUE` override is read, shared by the wind loader
// (fields/scene_toml.cpp) and the solver's (solver/scene_toml.cpp).
#pragma once

#include <toml++/toml.h>

#include <optional>
#include <string>

namespace gale::fields {

// `text` as a TOML value (`12`, `[1, 0, 0]`, `{ keys = ... }`, `"text"`), else as a comma list
// of numbers (`1,0,0`), else as a bare string (`smooth`): a table whose key `v` holds it, or
// nullopt when none of those reads. `origin` names the source in toml++'s positions.
std::optional<toml::table> parseSetValue(const std::string& text, const std::string& origin);

} // namespace gale::fields
