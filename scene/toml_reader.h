// What both sections of the scene loader (wind_sections.cpp, body_sections.cpp) read a parsed
// scene file with: errors placed at file:line:col with the offending source line (or at the
// `--set` they came from), unknown keys with "did you mean", strings, and the one parser of
// `--set KEY=VALUE` overrides by dotted path. Internal to scene/: not part of the public API.
#pragma once

#include "fields/scene.h"
#include "scene/error.h"

#include <toml++/toml.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gale::scene {

// "a number" or "a vector of N numbers".
inline std::string widthText(int width) {
    return width == 1 ? std::string("a number")
                      : "a vector of " + std::to_string(width) + " numbers";
}

inline constexpr std::string_view kSetPrefix = "--set ";

// The `--set KEY=VALUE` a value came from (its source path, "--set ..."); "" for the scene file.
std::string setOrigin(const toml::source_region& where);

// What `--set` calls entry `index` of a [[head]] list: its name, else <head><index> (field0,
// cloth1, ...), except a gust, which has no default name ("": only its index).
std::string listEntryName(const toml::table& entry, const std::string& head, size_t index);

// The scene paths one section loader takes from `--set`.
struct SetSections {
    std::vector<std::string> tables; // [name] sections: name.KEY...
    std::vector<std::string> lists;  // [[name]] entries: name.NAME.KEY... or name.INDEX.KEY...
    // Heads left to the other loader: skipped without a word.
    std::vector<std::string> foreign;
    // Report sets that are not KEY=VALUE, and heads neither ours nor foreign (with "did you
    // mean" among `tables` and `lists`, and `pathsNote`); else skip them (the other loader
    // reports them).
    bool reportOthers = true;
    std::string pathsNote;
};

class TomlReader {
public:
    TomlReader(std::string path, const std::string& text, std::vector<SceneError>& errors);

    // At a toml++ source region: the scene's file:line:col and source line, or the `--set`
    // named by the region's path.
    SceneError& error(const toml::source_region& where, std::string message);
    SceneError& error(const toml::node& at, std::string message) {
        return error(at.source(), std::move(message));
    }
    // A problem of one `--set` (no position).
    SceneError& setError(const std::string& set, std::string message);

    // Applies the `sets` that `sections` takes to `root` (values as TOML, a comma list of
    // numbers or a bare string; parseSetValue), each reported at its --set when it fails.
    void applySets(toml::table& root, const std::vector<std::string>& sets,
                   const SetSections& sections);

    // Reports every key of `t` not in `allowed` ("did you mean", and the section's keys).
    void checkKeys(const toml::table& t, const std::vector<std::string>& allowed,
                   const std::string& section);
    bool string(const toml::node& n, const std::string& what, std::string& out);
    // A finite number.
    bool number(const toml::node& n, const std::string& what, double& out);
    // A whole number of at least `min`: an integer, or a float without a fraction below 1e15 in
    // magnitude (4.0, 1e3; larger ones do not fit a long long exactly).
    bool integer(const toml::node& n, const std::string& what, long long& out,
                 long long min = std::numeric_limits<long long>::min());
    // A finite number or a non-empty array of finite numbers (up to the language's widest
    // vector); false without a report (the caller words the error).
    bool vectorValue(const toml::node& n, std::vector<double>& out);
    // The one parser of keyframed curves, { keys = [[t0, v0], [t1, v1], ...], interp = "linear"
    // | "smooth" | "step" }: values of `width` numbers (0: any, the same for every key), scalar
    // values at least `min`; times distinct, keys sorted by time. Every problem is reported at
    // its key.
    std::optional<fields::Param> keyframes(const toml::table& t, const std::string& what, int width,
                                           double min = -HUGE_VAL);

protected:
    std::string lineText(int line) const;
    // Byte offset of a toml++ position (columns count code points).
    size_t offsetOf(const toml::source_position& p) const;

    std::string mPath;
    const std::string& mText;
    std::vector<size_t> mLineStarts;
    std::vector<SceneError>& mErrors;
};

} // namespace gale::scene
