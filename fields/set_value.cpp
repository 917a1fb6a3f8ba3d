// Reading a --set override's value (see set_value.h).
#include "fields/set_value.h"

namespace gale::fields {

std::optional<toml::table> parseSetValue(const std::string& text, const std::string& origin) {
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\') quoted += '\\';
        quoted += c;
    }
    quoted += '"';
    for (const std::string& candidate : {text, "[" + text + "]", quoted}) {
        try {
            toml::table doc = toml::parse("v = " + candidate, origin);
            if (doc.get("v")) return doc;
        } catch (const toml::parse_error&) {
        }
    }
    return std::nullopt;
}

} // namespace gale::fields
