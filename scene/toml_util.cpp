// Helpers of the TOML scene loaders (see scene_toml_util.h).
#include "scene/toml_util.h"

#include "lang/functions.h"

#include <sstream>

namespace gale::scene {

std::string trimText(std::string_view s) {
    const size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
    return a == std::string_view::npos ? std::string() : std::string(s.substr(a, b - a + 1));
}

std::vector<std::string> splitText(const std::string& s, char sep) {
    std::vector<std::string> parts;
    std::string part;
    std::stringstream in(s);
    while (std::getline(in, part, sep)) parts.push_back(part);
    if (!s.empty() && s.back() == sep) parts.push_back("");
    return parts;
}

std::string joinNames(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
}

std::string didYouMean(const std::string& name, const std::vector<std::string>& candidates) {
    std::vector<std::string_view> views(candidates.begin(), candidates.end());
    std::string_view close = lang::closestName(name, views);
    return close.empty() ? std::string() : "did you mean '" + std::string(close) + "'?";
}

bool isTomlNumber(const toml::node& n) { return n.is_integer() || n.is_floating_point(); }

const char* tomlTypeName(const toml::node& n) {
    switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
    }
}

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

bool assignAtPath(toml::table& target, const std::vector<std::string>& parts, size_t first, std::string& where,
                  toml::node&& value, std::string& error) {
    toml::table* t = &target;
    for (size_t i = first; i + 1 < parts.size(); ++i) {
        where += "." + parts[i];
        toml::node* child = t->get(parts[i]);
        if (!child) {
            t->insert(parts[i], toml::table{});
            child = t->get(parts[i]);
        }
        t = child->as_table();
        if (!t) {
            error = "'" + where + "' is " + tomlTypeName(*child) + ", not a table";
            return false;
        }
    }
    t->insert_or_assign(parts.back(), std::move(value));
    return true;
}

} // namespace gale::scene
