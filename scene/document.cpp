// The scene document (document.h): the parsed TOML tree of a scene file with its text, the
// loader's own --set applier over every section, the schema's file keys made absolute, and
// toml++'s writer.
#include "scene/document.h"

#include "scene/sections.h"
#include "scene/toml_reader.h"
#include "scene/toml_util.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

namespace gale::scene {

namespace fs = std::filesystem;

// The scene's [[list]] sections, whose entries --set names by name or index.
const std::vector<std::string> kListSections = {"gust", "field", "cloth", "hair", "collider"};

struct SceneDocument::Impl {
    std::string path, text;
    toml::table root;
};

SceneDocument::SceneDocument() : m(std::make_unique<Impl>()) {}
SceneDocument::~SceneDocument() = default;
SceneDocument::SceneDocument(SceneDocument&&) noexcept = default;
SceneDocument& SceneDocument::operator=(SceneDocument&&) noexcept = default;

bool SceneDocument::read(const std::string& path, std::vector<SceneError>& errors) {
    m->path = path;
    return readSceneFile(path, m->text, m->root, errors);
}

bool SceneDocument::parse(const std::string& path, const std::string& text,
                          std::vector<SceneError>& errors) {
    m->path = path;
    m->text = text;
    return parseSceneText(path, m->text, m->root, errors);
}

const std::string& SceneDocument::path() const {
    return m->path;
}
const std::string& SceneDocument::text() const {
    return m->text;
}

bool SceneDocument::applySets(const std::vector<std::string>& sets,
                              std::vector<SceneError>& errors) {
    const size_t before = errors.size();
    TomlReader reader(m->path, m->text, errors);
    SetSections sections;
    sections.tables = {"scene", "windicator", "solver"};
    sections.lists = kListSections;
    sections.pathsNote = "scene paths look like windicator.speed, scene.fps, gust.NAME.strength, "
                         "field.NAME.params.PARAM, cloth.NAME.drag or solver.max_halvings";
    reader.applySets(m->root, sets, sections);
    return errors.size() == before;
}

std::string SceneDocument::canonicalSetKey(const std::string& set) const {
    const std::string key = trimText(set.substr(0, set.find('=')));
    std::vector<std::string> parts = splitText(key, '.');
    if (parts.size() < 3) return key;
    const std::string& head = parts[0];
    if (std::find(kListSections.begin(), kListSections.end(), head) == kListSections.end())
        return key;
    const toml::array* list = m->root.get(head) ? m->root.get(head)->as_array() : nullptr;
    if (!list) return key;
    for (size_t i = 0; i < list->size(); ++i) {
        const toml::table* t = list->get(i)->as_table();
        if (!t) continue;
        const std::string name = listEntryName(*t, head, i);
        if ((!name.empty() && name == parts[1]) || parts[1] == std::to_string(i)) {
            parts[1] = std::to_string(i);
            std::string out = parts[0];
            for (size_t k = 1; k < parts.size(); ++k) out += "." + parts[k];
            return out;
        }
    }
    return key;
}

namespace {

// Makes a relative file name under `key` of `t` absolute against `baseDir`.
void absolutise(toml::table& t, const char* key, const fs::path& baseDir) {
    toml::node* n = t.get(key);
    if (!n || !n->is_string()) return;
    const std::string name = n->value<std::string>().value_or("");
    if (name.empty() || fs::path(name).is_absolute()) return;
    t.insert_or_assign(key, (baseDir / name).lexically_normal().string());
}

template <class Fn>
void eachEntry(toml::table& root, const char* section, Fn&& fn) {
    if (toml::array* list = root.get(section) ? root.get(section)->as_array() : nullptr)
        for (toml::node& n : *list)
            if (toml::table* t = n.as_table()) fn(*t);
}

// The file keys inside a cloth's or hair's inline tables: painted maps `{ expr = "file.se" }`
// (not keyframes) and `attach = { mesh = "body.#.obj", ... }`.
void absolutiseInline(toml::table& body, const fs::path& baseDir) {
    for (auto&& [k, v] : body)
        if (toml::table* sub = v.as_table()) {
            if (sub->contains("expr") && !sub->contains("keys")) absolutise(*sub, "expr", baseDir);
            if (k.str() == "attach") absolutise(*sub, "mesh", baseDir);
        }
}

// Byte offset of a toml++ position (1-based line and column; columns count code points).
size_t byteOffset(const std::string& text, const toml::source_position& p) {
    size_t i = 0;
    for (uint32_t l = 1; l < p.line && i != std::string::npos; ++l) {
        i = text.find('\n', i);
        if (i != std::string::npos) ++i;
    }
    if (i == std::string::npos) return text.size();
    for (uint32_t c = 1; c < p.column && i < text.size(); ++c) {
        ++i;
        while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
    }
    return std::min(i, text.size());
}

} // namespace

void SceneDocument::absolutisePaths() {
    std::error_code ec;
    const fs::path base = fs::absolute(fs::path(m->path), ec).parent_path();
    toml::table& root = m->root;
    eachEntry(root, "field", [&](toml::table& t) { absolutise(t, "expr", base); });
    eachEntry(root, "cloth", [&](toml::table& t) {
        absolutise(t, "mesh", base);
        absolutise(t, "rest_mesh", base);
        absolutiseInline(t, base);
    });
    eachEntry(root, "hair", [&](toml::table& t) {
        absolutise(t, "strands", base);
        absolutiseInline(t, base);
    });
    eachEntry(root, "collider", [&](toml::table& t) { absolutise(t, "mesh", base); });
}

std::string SceneDocument::write(const std::string& header) const {
    std::ostringstream text;
    std::istringstream lines(header);
    for (std::string line; std::getline(lines, line);) text << "# " << line << '\n';
    text << '\n'
         << toml::toml_formatter(m->root, toml::toml_formatter::default_flags |
                                              toml::format_flags::relaxed_float_precision)
         << '\n';
    return text.str();
}

namespace {

// Calls fn(path) for every string value of the tree, as a path relative to `base` (strings of
// 1000 bytes or more are not file names).
template <class Fn>
void eachPathString(const toml::node& root, const fs::path& base, Fn&& fn) {
    auto walk = [&](const toml::node& n, auto&& self) -> void {
        if (const auto* s = n.as_string()) {
            if (s->get().size() < 1000) fn(s->get(), base / s->get());
        } else if (const auto* t = n.as_table()) {
            for (const auto& kv : *t) self(kv.second, self);
        } else if (const auto* a = n.as_array()) {
            for (const auto& e : *a) self(e, self);
        }
    };
    walk(root, walk);
}

} // namespace

std::vector<std::string> SceneDocument::namedFiles() const {
    std::vector<std::string> out;
    eachPathString(m->root, fs::path(m->path).parent_path(),
                   [&](const std::string&, const fs::path& p) {
                       std::error_code ec;
                       if (fs::is_regular_file(p, ec)) out.push_back(p.string());
                   });
    return out;
}

std::vector<std::string> SceneDocument::otherPaths() const {
    std::vector<std::string> out;
    eachPathString(m->root, fs::path(m->path).parent_path(),
                   [&](const std::string& s, const fs::path& p) {
                       std::error_code ec;
                       if (!s.empty() && !fs::is_regular_file(p, ec))
                           out.push_back(p.lexically_normal().string());
                   });
    return out;
}

std::optional<SourceSpan> SceneDocument::fieldParamLiteral(size_t field,
                                                           const std::string& name) const {
    const toml::array* fields = m->root["field"].as_array();
    const toml::table* ft =
        fields && field < fields->size() ? (*fields)[field].as_table() : nullptr;
    const toml::table* pt = ft ? (*ft)["params"].as_table() : nullptr;
    const toml::node* v = pt ? pt->get(name) : nullptr;
    if (!v || !(v->is_number() || v->is_array())) return std::nullopt;
    const toml::source_region& src = v->source();
    SourceSpan span;
    span.line = static_cast<int>(src.begin.line);
    span.col = static_cast<int>(src.begin.column);
    span.begin = byteOffset(m->text, src.begin);
    span.end = byteOffset(m->text, src.end);
    return span;
}

std::string SceneDocument::colliderMesh(size_t index) const {
    const toml::array* list = m->root["collider"].as_array();
    const toml::table* t = list && index < list->size() ? (*list)[index].as_table() : nullptr;
    return t ? (*t)["mesh"].value<std::string>().value_or("") : std::string();
}

} // namespace gale::scene
