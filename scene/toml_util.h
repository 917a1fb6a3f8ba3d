// Small pieces shared by the scene loader's sections — the wind's (scene/wind_sections.cpp) and
// the bodies' (scene/body_sections.cpp): text helpers, names of TOML types, "did you mean", and how a
// `--set KEY=VALUE` override's value is read.
#pragma once

#include <toml++/toml.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gale::scene {

// `s` without leading and trailing blanks.
std::string trimText(std::string_view s);
// `s` cut at every `sep`; a trailing separator gives a last empty part.
std::vector<std::string> splitText(const std::string& s, char sep);
// "a, b, c".
std::string joinNames(const std::vector<std::string>& names);
// "did you mean 'x'?" for the candidate closest to `name`, or empty.
std::string didYouMean(const std::string& name, const std::vector<std::string>& candidates);

bool isTomlNumber(const toml::node& n);
// "a table", "an integer", ... for diagnostics.
const char* tomlTypeName(const toml::node& n);

// `text` as a TOML value (`12`, `[1, 0, 0]`, `{ keys = ... }`, `"text"`), else as a comma list
// of numbers (`1,0,0`), else as a bare string (`smooth`): a table whose key `v` holds it, or
// nullopt when none of those reads. `origin` names the source in toml++'s positions.
std::optional<toml::table> parseSetValue(const std::string& text, const std::string& origin);

// Sets parts[first .. end−1] below `target` to `value`, making the tables on the way; `where`
// (the dotted path so far) grows with the walk. False, with `error` set, when a part on the way
// is not a table.
bool assignAtPath(toml::table& target, const std::vector<std::string>& parts, size_t first, std::string& where,
                  toml::node&& value, std::string& error);

} // namespace gale::scene
