// Look-up of the embedded expression presets (the table itself is generated at build time
// from fields/presets/*.se by presets/embed.cmake).
#include "fields/presets.h"

namespace gale::fields {

const Preset* findPreset(std::string_view name) {
    for (const Preset& p : presets())
        if (p.name == name) return &p;
    return nullptr;
}

std::string presetNames() {
    std::string out;
    for (const Preset& p : presets()) {
        if (!out.empty()) out += ", ";
        out += p.name;
    }
    return out;
}

} // namespace gale::fields
