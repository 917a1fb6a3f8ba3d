// The expression presets shipped inside the library (fields/presets/*.se, embedded at build
// time): readable, documented wind fields a scene selects with `[[field]] preset = "ripple"`.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace gale::fields {

struct Preset {
    std::string_view name; // file name without .se: "wind", "ripple", "volume_axis"
    std::string_view text; // the whole file
};

// Every embedded preset, sorted by name.
const std::vector<Preset>& presets();
// The preset called `name`, or null.
const Preset* findPreset(std::string_view name);
// "wind, ripple, volume_axis" — for error messages.
std::string presetNames();

} // namespace gale::fields
