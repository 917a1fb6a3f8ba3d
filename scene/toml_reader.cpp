// The scene loader's shared reading: errors at file:line:col, unknown keys, strings, and the one
// `--set KEY=VALUE` parser of both section loaders.
#include "scene/toml_reader.h"

#include "scene/toml_util.h"

#include "io/pointset.h"
#include "lang/types.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace gale::scene {

namespace {

bool contains(const std::vector<std::string>& list, const std::string& s) {
    return std::find(list.begin(), list.end(), s) != list.end();
}

} // namespace

TomlReader::TomlReader(std::string path, const std::string& text, std::vector<SceneError>& errors)
    : mPath(std::move(path)), mText(text), mErrors(errors) {
    size_t start = 0;
    for (;;) {
        mLineStarts.push_back(start);
        const size_t nl = text.find('\n', start);
        if (nl == std::string::npos) break;
        start = nl + 1;
    }
}

std::string setOrigin(const toml::source_region& where) {
    return where.path && where.path->compare(0, kSetPrefix.size(), kSetPrefix) == 0 ? *where.path
                                                                                    : std::string();
}

std::string listEntryName(const toml::table& entry, const std::string& head, size_t index) {
    if (const toml::node* n = entry.get("name"); n && n->is_string())
        return n->value<std::string>().value_or("");
    return head == "gust" ? std::string() : head + std::to_string(index);
}

SceneError& TomlReader::error(const toml::source_region& where, std::string message) {
    SceneError e;
    e.message = std::move(message);
    if (std::string origin = setOrigin(where); !origin.empty()) {
        e.file = std::move(origin);
    } else {
        e.file = mPath;
        e.line = static_cast<int>(where.begin.line);
        e.col = static_cast<int>(where.begin.column);
        e.sourceLine = lineText(e.line);
    }
    mErrors.push_back(std::move(e));
    return mErrors.back();
}

SceneError& TomlReader::setError(const std::string& set, std::string message) {
    SceneError e;
    e.file = std::string(kSetPrefix) + set;
    e.message = std::move(message);
    mErrors.push_back(std::move(e));
    return mErrors.back();
}

std::string TomlReader::lineText(int line) const {
    if (line <= 0 || static_cast<size_t>(line) > mLineStarts.size()) return {};
    const size_t a = mLineStarts[static_cast<size_t>(line - 1)];
    size_t b = mText.find('\n', a);
    if (b == std::string::npos) b = mText.size();
    if (b > a && mText[b - 1] == '\r') --b;
    return mText.substr(a, b - a);
}

size_t TomlReader::offsetOf(const toml::source_position& p) const {
    if (p.line == 0 || p.line > mLineStarts.size()) return std::string::npos;
    size_t i = mLineStarts[p.line - 1];
    for (uint32_t c = 1; c < p.column && i < mText.size(); ++c) {
        ++i;
        while (i < mText.size() && (static_cast<unsigned char>(mText[i]) & 0xC0) == 0x80) ++i;
    }
    return i;
}

void TomlReader::checkKeys(const toml::table& t, const std::vector<std::string>& allowed,
                           const std::string& section) {
    for (auto&& [key, node] : t) {
        const std::string name(key.str());
        if (contains(allowed, name)) continue;
        SceneError& e = error(key.source().begin.line ? key.source() : node.source(),
                              "unknown key '" + name + "' in " + section);
        const std::string hint = didYouMean(name, allowed);
        if (!hint.empty()) e.notes.push_back(hint);
        e.notes.push_back(section + " keys: " + joinNames(allowed));
    }
}

bool TomlReader::string(const toml::node& n, const std::string& what, std::string& out) {
    if (!n.is_string()) {
        error(n, what + " must be a string, not " + tomlTypeName(n));
        return false;
    }
    out = n.value<std::string>().value_or("");
    return true;
}

void TomlReader::applySets(toml::table& root, const std::vector<std::string>& sets,
                           const SetSections& sections) {
    for (const std::string& set : sets) {
        const size_t eq = set.find('=');
        const std::string key = trimText(eq == std::string::npos ? set : set.substr(0, eq));
        const std::string text = eq == std::string::npos ? std::string() : trimText(set.substr(eq + 1));
        const std::vector<std::string> parts = splitText(key, '.');
        if (eq == std::string::npos || key.empty() || text.empty() ||
            std::any_of(parts.begin(), parts.end(), [](const std::string& p) { return p.empty(); })) {
            if (sections.reportOthers)
                setError(set, "expected KEY=VALUE with a dotted scene path, e.g. windicator.speed=12, "
                              "field.main.params.speed=8 or scene.fps=30");
            continue;
        }
        const std::string& head = parts[0];
        if (contains(sections.foreign, head)) continue; // the other loader applies it
        const bool isTable = contains(sections.tables, head), isList = contains(sections.lists, head);
        if (!isTable && !isList && !sections.reportOthers) continue;

        // The value as TOML, else a comma list of numbers, else a bare string.
        std::optional<toml::table> parsed = parseSetValue(text, std::string(kSetPrefix) + set);
        if (!parsed) {
            setError(set, "cannot read the value '" + text + "'");
            continue;
        }
        toml::table doc = std::move(*parsed);

        toml::table* target = nullptr;
        size_t next = 1;
        std::string where = head;
        if (isTable) {
            if (!root.contains(head)) root.insert(head, toml::table{});
            target = root.get(head)->as_table();
            if (!target) {
                setError(set, "'" + head + "' in the scene is not a table");
                continue;
            }
        } else if (isList) {
            toml::array* list = root.get(head) ? root.get(head)->as_array() : nullptr;
            if (parts.size() < 3) {
                setError(set, "expected " + head + ".NAME.KEY (or " + head + ".INDEX.KEY, from 0)");
                continue;
            }
            std::vector<std::string> names;
            if (list) {
                for (size_t i = 0; i < list->size(); ++i) {
                    toml::table* t = list->get(i)->as_table();
                    if (!t) continue;
                    const std::string name = listEntryName(*t, head, i);
                    if (!name.empty()) names.push_back(name);
                    if (!target && (name == parts[1] || parts[1] == std::to_string(i))) target = t;
                }
            }
            if (!target) {
                SceneError& e =
                    setError(set, "the scene has no [[" + head + "]] named '" + parts[1] + "'");
                const std::string hint = didYouMean(parts[1], names);
                if (!hint.empty()) e.notes.push_back(hint);
                const size_t count = list ? list->size() : 0;
                e.notes.push_back("it has " + std::to_string(count) + " [[" + head + "]] entr" +
                                  (count == 1 ? "y" : "ies") +
                                  (names.empty() ? std::string() : " (" + joinNames(names) + ")") +
                                  "; name one, or give its index from 0");
                continue;
            }
            next = 2;
            where = head + "." + parts[1];
        } else {
            SceneError& e = setError(set, "unknown scene section '" + head + "'");
            std::vector<std::string> known = sections.tables;
            known.insert(known.end(), sections.lists.begin(), sections.lists.end());
            const std::string hint = didYouMean(head, known);
            if (!hint.empty()) e.notes.push_back(hint);
            if (!sections.pathsNote.empty()) e.notes.push_back(sections.pathsNote);
            continue;
        }
        std::string problem;
        if (!assignAtPath(*target, parts, next, where, std::move(*doc.get("v")), problem))
            setError(set, problem);
    }
}

// ---- values and keyframed curves ----

bool TomlReader::number(const toml::node& n, const std::string& what, double& out) {
    if (!isTomlNumber(n)) {
        error(n, what + " must be a number, not " + tomlTypeName(n));
        return false;
    }
    const double v = n.value<double>().value_or(0.0);
    if (!std::isfinite(v)) {
        error(n, what + " must be a finite number");
        return false;
    }
    out = v;
    return true;
}

bool TomlReader::integer(const toml::node& n, const std::string& what, long long& out,
                         long long min) {
    long long v = 0;
    if (n.is_integer()) {
        v = n.value<long long>().value_or(0);
    } else if (n.is_floating_point()) {
        double d = 0.0;
        if (!number(n, what, d)) return false;
        if (d != std::floor(d)) {
            error(n, what + " must be a whole number, not a fraction");
            return false;
        }
        // A fuzzed 41e300 was once converted as is: undefined behaviour.
        if (!(std::fabs(d) < 1e15)) {
            error(n, what + " must be a whole number below 1e15, not " + io::formatNumber(d));
            return false;
        }
        v = static_cast<long long>(d);
    } else {
        error(n, what + " must be a whole number, not " + tomlTypeName(n));
        return false;
    }
    if (v < min) {
        error(n, what + " must be at least " + std::to_string(min) + ", not " + std::to_string(v));
        return false;
    }
    out = v;
    return true;
}

bool TomlReader::vectorValue(const toml::node& n, std::vector<double>& out) {
    out.clear();
    if (isTomlNumber(n)) {
        out.push_back(n.value<double>().value_or(0.0));
        return std::isfinite(out[0]);
    }
    const toml::array* a = n.as_array();
    if (!a || a->empty() || a->size() > static_cast<size_t>(lang::kMaxWidth)) return false;
    for (const toml::node& e : *a) {
        if (!isTomlNumber(e)) return false;
        out.push_back(e.value<double>().value_or(0.0));
        if (!std::isfinite(out.back())) return false;
    }
    return true;
}

std::optional<fields::Param> TomlReader::keyframes(const toml::table& t, const std::string& what,
                                                   int width, double min) {
    checkKeys(t, {"keys", "interp"}, "the keyframed curve of " + what);
    fields::KeyInterp interp = fields::KeyInterp::Linear;
    bool ok = true;
    if (const toml::node* i = t.get("interp")) {
        std::string name;
        if (!string(*i, what + ": interp", name)) {
            ok = false;
        } else if (name == "linear") {
            interp = fields::KeyInterp::Linear;
        } else if (name == "smooth") {
            interp = fields::KeyInterp::Smooth;
        } else if (name == "step") {
            interp = fields::KeyInterp::Step;
        } else {
            SceneError& e = error(*i, "unknown interpolation '" + name + "' for " + what +
                                                  " (use \"linear\", \"smooth\" or \"step\")");
            std::string hint = didYouMean(name, {"linear", "smooth", "step"});
            if (!hint.empty()) e.notes.push_back(hint);
            ok = false;
        }
    }
    const toml::node* keysNode = t.get("keys");
    if (!keysNode) {
        error(t, what + ": a keyframed curve needs keys = [[t0, v0], [t1, v1], ...]");
        return std::nullopt;
    }
    const toml::array* keys = keysNode->as_array();
    if (!keys || keys->empty()) {
        error(*keysNode, what + ": keys must be a non-empty array of [time, value] pairs");
        return std::nullopt;
    }
    struct Key {
        double time;
        std::vector<double> value;
        const toml::node* node;
    };
    std::vector<Key> list;
    int keyWidth = width;
    for (const toml::node& k : *keys) {
        const toml::array* pair = k.as_array();
        double time = 0.0;
        std::vector<double> value;
        if (!pair || pair->size() != 2 || !isTomlNumber(*pair->get(0))) {
            error(k, what + ": each key must be [time, value] (time in seconds)");
            ok = false;
            continue;
        }
        if (!number(*pair->get(0), what + ": a key's time", time)) {
            ok = false;
            continue;
        }
        if (!vectorValue(*pair->get(1), value)) {
            error(*pair->get(1),
                  what + ": a key's value must be " +
                      (keyWidth ? widthText(keyWidth) : std::string("a number or a vector")));
            ok = false;
            continue;
        }
        if (keyWidth == 0) keyWidth = static_cast<int>(value.size());
        if (static_cast<int>(value.size()) != keyWidth) {
            error(*pair->get(1), what + ": a key's value must be " + widthText(keyWidth) +
                                     " like the " + (width ? "parameter" : "first key") + ", not " +
                                     std::to_string(value.size()) + " number" +
                                     (value.size() == 1 ? "" : "s"));
            ok = false;
            continue;
        }
        if (keyWidth == 1 && !(value[0] >= min)) {
            error(*pair->get(1), what + ": a key's value must be at least " +
                                     io::formatNumber(min) + ", not " + io::formatNumber(value[0]));
            ok = false;
            continue;
        }
        list.push_back({time, std::move(value), &k});
    }
    std::stable_sort(list.begin(), list.end(),
                     [](const Key& a, const Key& b) { return a.time < b.time; });
    for (size_t i = 1; i < list.size(); ++i) {
        if (list[i].time == list[i - 1].time) {
            error(*list[i].node, what + ": two keys at time " + io::formatNumber(list[i].time) +
                                     " (each key needs its own time)");
            ok = false;
        }
    }
    if (!ok) return std::nullopt;
    std::vector<double> times;
    std::vector<std::vector<double>> values;
    for (Key& k : list) {
        times.push_back(k.time);
        values.push_back(std::move(k.value));
    }
    return fields::Param::keyed(std::move(times), std::move(values), interp);
}

} // namespace gale::scene
