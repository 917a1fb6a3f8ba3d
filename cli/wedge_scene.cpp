// The resolved scene of one `gale wedge` variant: the scene's TOML with the variant's overrides
// applied by dotted path (as `gale sim --set` applies them) and relative file names made absolute,
// written back with toml++ so the variant folder holds a scene that runs on its own.
#include "cli/wedge.h"

#include <toml++/toml.h>

#include <filesystem>
#include <functional>
#include <sstream>

namespace gale::cli {

namespace {

namespace fs = std::filesystem;

std::string trim(const std::string& s) {
    const size_t a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return "";
    const size_t b = s.find_last_not_of(" \t");
    return s.substr(a, b - a + 1);
}

// A --set value as a TOML node: TOML itself, else a comma list of numbers, else a bare string.
bool parseValue(const std::string& text, toml::table& doc) {
    for (const std::string& candidate : {text, "[" + text + "]"}) {
        try {
            doc = toml::parse("v = " + candidate);
            return doc.get("v") != nullptr;
        } catch (const toml::parse_error&) {
        }
    }
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\') quoted += '\\';
        quoted += c;
    }
    try {
        doc = toml::parse("v = " + quoted + "\"");
        return doc.get("v") != nullptr;
    } catch (const toml::parse_error&) {
        return false;
    }
}

bool applySet(toml::table& root, const std::string& set, std::string& error) {
    const size_t eq = set.find('=');
    const std::string key = trim(eq == std::string::npos ? set : set.substr(0, eq));
    const std::string text = eq == std::string::npos ? std::string() : trim(set.substr(eq + 1));
    std::vector<std::string> parts;
    for (size_t start = 0;;) {
        const size_t dot = key.find('.', start);
        parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    toml::table doc;
    if (key.empty() || text.empty() || !parseValue(text, doc)) {
        error = "'" + set + "': expected KEY=VALUE";
        return false;
    }
    const std::string& head = parts[0];
    toml::table* target = nullptr;
    size_t next = 1;
    if (head == "scene" || head == "windicator" || head == "solver") {
        if (!root.contains(head)) root.insert(head, toml::table{});
        target = root.get(head)->as_table();
    } else if (parts.size() >= 3) {
        toml::array* list = root.get(head) ? root.get(head)->as_array() : nullptr;
        for (size_t i = 0; list && !target && i < list->size(); ++i) {
            toml::table* t = list->get(i)->as_table();
            if (!t) continue;
            const std::string name = t->get("name") && t->get("name")->is_string()
                                         ? t->get("name")->value<std::string>().value_or("")
                                         : (head == "gust" ? std::string() : head + std::to_string(i));
            if (name == parts[1] || parts[1] == std::to_string(i)) target = t;
        }
        next = 2;
    }
    for (size_t i = next; target && i + 1 < parts.size(); ++i) {
        if (!target->contains(parts[i])) target->insert(parts[i], toml::table{});
        target = target->get(parts[i])->as_table();
    }
    if (!target || parts.size() < next + 1) {
        error = "'" + set + "': no such place in the scene";
        return false;
    }
    target->insert_or_assign(parts.back(), std::move(*doc.get("v")));
    return true;
}

// Makes a relative file name under `key` of `t` absolute against `baseDir`.
void absolutise(toml::table& t, const char* key, const fs::path& baseDir) {
    toml::node* n = t.get(key);
    if (!n || !n->is_string()) return;
    const std::string name = n->value<std::string>().value_or("");
    if (name.empty() || fs::path(name).is_absolute()) return;
    t.insert_or_assign(key, (baseDir / name).lexically_normal().string());
}

void absolutiseAll(toml::table& root, const fs::path& baseDir) {
    auto each = [&](const char* section, const std::function<void(toml::table&)>& fn) {
        if (toml::array* list = root.get(section) ? root.get(section)->as_array() : nullptr)
            for (toml::node& n : *list)
                if (toml::table* t = n.as_table()) fn(*t);
    };
    // Painted maps: { expr = "file.se", ... } as any key's value of a cloth or hair.
    auto painted = [&](toml::table& t) {
        for (auto&& [k, v] : t)
            if (toml::table* sub = v.as_table())
                if (sub->contains("expr") && !sub->contains("keys")) absolutise(*sub, "expr", baseDir);
    };
    each("field", [&](toml::table& t) { absolutise(t, "expr", baseDir); });
    each("cloth", [&](toml::table& t) {
        absolutise(t, "mesh", baseDir);
        painted(t);
    });
    each("hair", [&](toml::table& t) {
        absolutise(t, "strands", baseDir);
        painted(t);
    });
    each("collider", [&](toml::table& t) { absolutise(t, "mesh", baseDir); }); // type = "mesh"
}

} // namespace

bool resolveVariantScene(const std::string& scenePath, const std::vector<std::string>& sets,
                         const std::string& header, std::string& out, std::string& error) {
    toml::table root;
    try {
        root = toml::parse_file(scenePath);
    } catch (const toml::parse_error& e) {
        error = scenePath + ": " + std::string(e.description());
        return false;
    }
    for (const std::string& set : sets)
        if (!applySet(root, set, error)) return false;
    std::error_code ec;
    fs::path base = fs::absolute(fs::path(scenePath), ec).parent_path();
    absolutiseAll(root, base);
    std::ostringstream text;
    std::istringstream lines(header);
    for (std::string line; std::getline(lines, line);) text << "# " << line << '\n';
    // Decimals as typed (0.6, not 0.59999999999999998): 15 significant digits round-trip them.
    text << '\n'
         << toml::toml_formatter(root, toml::toml_formatter::default_flags | toml::format_flags::relaxed_float_precision)
         << '\n';
    out = text.str();
    return true;
}

} // namespace gale::cli
