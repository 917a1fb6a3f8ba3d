// The scene loader's wind sections ([scene], [windicator], [[gust]], [[field]]) and the reading
// of a scene file with toml++ (only scene/ includes it: it is slow to compile): --set overrides applied to the TOML tree by dotted path, then every key checked
// and converted, with every problem reported at its file:line:col.
#include "scene/load.h"

#include "fields/expression_field.h"
#include "fields/presets.h"
#include "fields/scene.h"
#include "io/pointset.h"
#include "scene/sections.h"
#include "scene/toml_reader.h"
#include "scene/toml_util.h"
#include "lang/functions.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <sstream>

namespace gale::scene {

using namespace gale::fields;

namespace {

class Loader : public TomlReader {
public:
    Loader(const std::string& path, const std::string& text, std::vector<SceneError>& errors,
           const SceneLoadOptions& options)
        : TomlReader(path, text, errors), mOptions(options) {}

    void applySets(toml::table& root);
    void load(const toml::table& root, Scene& out);

private:
    std::optional<Param> param(const toml::node& n, const std::string& what, int width);
    void verbatimPosition(const toml::node& n, const std::string& value, int& line, int& col) const;

    void loadSettings(const toml::table& t, SceneSettings& s);
    void loadWindicator(const toml::table& t, Windicator& w);
    void loadGust(const toml::table& t, size_t index, Gust& g);
    void loadField(const toml::table& t, size_t index, const std::string& baseDir,
                   FieldEntry& f);
    void checkParams(const toml::table& params, const FieldEntry& f, const Scene& scene,
                     const toml::node* sourceNode);

    const SceneLoadOptions& mOptions;
};


// ---- --set KEY=VALUE ------------------------------------------------------------------------

void Loader::applySets(toml::table& root) {
    SetSections sections;
    sections.tables = {"scene", "windicator"};
    sections.lists = {"gust", "field"};
    sections.foreign = mOptions.foreignSections;
    sections.pathsNote = "scene paths look like windicator.speed, scene.fps, "
                         "gust.NAME.strength or field.NAME.params.PARAM";
    TomlReader::applySets(root, mOptions.sets, sections);
}

// ---- Values -----------------------------------------------------------------------------------

// A numeric parameter: a number, a vector, or a keyframed curve. `width` 0 accepts any width.
std::optional<Param> Loader::param(const toml::node& n, const std::string& what, int width) {
    if (const toml::table* t = n.as_table()) return keyframes(*t, what, width);
    std::vector<double> v;
    if (!vectorValue(n, v)) {
        error(n, what + " must be " +
                     (width ? widthText(width) : std::string("a number or a vector [x, y, z]")) +
                     " or a keyframed curve { keys = [[t0, v0], [t1, v1]], interp = \"linear\" }" +
                     (n.is_array() ? std::string(" (this array is empty, longer than 16 or holds "
                                                 "something other than numbers)")
                                   : ", not " + std::string(tomlTypeName(n))));
        return std::nullopt;
    }
    if (width && static_cast<int>(v.size()) != width) {
        error(n, what + " must be " + widthText(width) + ", not " +
                     std::to_string(v.size()) + " number" + (v.size() == 1 ? "" : "s"));
        return std::nullopt;
    }
    if (!n.is_array()) return Param(v[0]);
    return Param(std::move(v));
}

// Where a string's text starts in the scene when the TOML holds it verbatim (literal strings,
// or basic strings without escapes); line = 0 otherwise.
void Loader::verbatimPosition(const toml::node& n, const std::string& value, int& line,
                              int& col) const {
    line = col = 0;
    const toml::source_region& r = n.source();
    if (!setOrigin(r).empty()) return; // given by --set: not in the scene's text
    size_t at = offsetOf(r.begin);
    if (at == std::string::npos || at >= mText.size()) return;
    const char q = mText[at];
    if (q != '"' && q != '\'') return;
    const bool multi = mText.compare(at, 3, std::string(3, q)) == 0;
    at += multi ? 3 : 1;
    if (multi && at < mText.size() && mText[at] == '\n') ++at;
    else if (multi && mText.compare(at, 2, "\r\n") == 0) at += 2;
    if (mText.compare(at, value.size(), value) != 0) return;
    // The value must be followed by its closing quote (else it held an escape).
    if (mText.compare(at + value.size(), 1, std::string(1, q)) != 0) return;
    const size_t lineIndex =
        static_cast<size_t>(std::upper_bound(mLineStarts.begin(), mLineStarts.end(), at) -
                            mLineStarts.begin() - 1);
    line = static_cast<int>(lineIndex + 1);
    col = static_cast<int>(at - mLineStarts[lineIndex] + 1);
}

// ---- Sections ---------------------------------------------------------------------------------

void Loader::loadSettings(const toml::table& t, SceneSettings& s) {
    checkKeys(t, {"fps", "frames", "substeps", "gravity", "air_density", "time_zero", "preroll"},
              "[scene]");
    if (const toml::node* n = t.get("fps")) {
        double v = 0.0;
        if (number(*n, "scene.fps", v)) {
            if (v > 0.0)
                s.fps = v;
            else
                error(*n, "scene.fps must be positive");
        }
    }
    if (const toml::node* n = t.get("frames")) {
        const toml::array* a = n->as_array();
        long long first = 0, last = 0;
        if (!a || a->size() != 2) {
            error(*n, "scene.frames must be [first, last], e.g. [1, 48]");
        } else if (integer(*a->get(0), "scene.frames' first frame", first) &&
                   integer(*a->get(1), "scene.frames' last frame", last)) {
            if (last < first)
                error(*n, "scene.frames: the last frame (" + std::to_string(last) +
                              ") comes before the first (" + std::to_string(first) + ")");
            else if (first < -100000000 || last > 100000000) // (no llabs: LLONG_MIN)
                error(*n, "scene.frames: frame numbers must stay within +/-100000000");
            else {
                s.frameStart = static_cast<int>(first);
                s.frameEnd = static_cast<int>(last);
            }
        }
    }
    if (const toml::node* n = t.get("time_zero")) {
        double v = 0.0;
        if (number(*n, "scene.time_zero (the frame at which $t = 0)", v)) {
            if (std::fabs(v) <= 100000000.0)
                s.timeZero = v;
            else
                error(*n, "scene.time_zero must stay within +/-100000000 (a frame number)");
        }
    }
    if (const toml::node* n = t.get("preroll")) {
        long long v = 0;
        if (integer(*n, "scene.preroll (frames simulated before the first)", v)) {
            if (v >= 0 && v <= 100000)
                s.preroll = static_cast<int>(v);
            else
                error(*n,
                      "scene.preroll must be between 0 and 100000 frames (e.g. 24: one second at "
                      "24 fps)");
        }
    }
    if (const toml::node* n = t.get("substeps")) {
        long long v = 0;
        if (integer(*n, "scene.substeps", v)) {
            if (v >= 1 && v <= 10000)
                s.substeps = static_cast<int>(v);
            else
                error(*n, "scene.substeps must be between 1 and 10000");
        }
    }
    if (const toml::node* n = t.get("gravity")) {
        std::vector<double> g;
        if (!n->is_array() || !vectorValue(*n, g) || g.size() != 3)
            error(*n, "scene.gravity must be a vector of 3 numbers [x, y, z] (m/s^2)");
        else
            s.gravity = g;
    }
    if (const toml::node* n = t.get("air_density")) {
        double v = 0.0;
        if (number(*n, "scene.air_density", v)) {
            if (v >= 0.0)
                s.airDensity = v;
            else
                error(*n, "scene.air_density must not be negative (kg/m^3)");
        }
    }
}

void Loader::loadWindicator(const toml::table& t, Windicator& w) {
    checkKeys(t, {"direction", "speed"}, "[windicator]");
    if (const toml::node* n = t.get("direction")) {
        if (std::optional<Param> p = param(*n, "windicator.direction", 3)) {
            // Every value (constant or key) must have a direction.
            bool zero = false;
            if (p->isKeyed()) {
                for (const std::vector<double>& v : p->values())
                    zero = zero || (v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0);
            } else {
                const std::vector<double> v = p->at(0.0);
                zero = v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0;
            }
            if (zero)
                error(*n, "windicator.direction must not be the zero vector");
            else
                w.direction = std::move(*p);
        }
    }
    if (const toml::node* n = t.get("speed")) {
        if (std::optional<Param> p = param(*n, "windicator.speed", 1)) w.speed = std::move(*p);
    }
}

void Loader::loadGust(const toml::table& t, size_t index, Gust& g) {
    checkKeys(t, {"name", "start", "attack", "hold", "decay", "strength", "travel_speed"},
              "[[gust]]");
    const std::string label = "gust " + std::to_string(index);
    if (const toml::node* n = t.get("name")) string(*n, "gust.name", g.name);
    const std::string what = g.name.empty() ? label : "gust '" + g.name + "'";
    if (const toml::node* n = t.get("start")) number(*n, what + ": start", g.start);
    struct Duration {
        const char* key;
        double* value;
    };
    for (Duration d : {Duration{"attack", &g.attack}, Duration{"hold", &g.hold},
                       Duration{"decay", &g.decay}}) {
        const toml::node* n = t.get(d.key);
        double v = 0.0;
        if (!n || !number(*n, what + ": " + d.key, v)) continue;
        if (v < 0.0)
            error(*n, what + ": " + d.key + " must not be negative (seconds)");
        else
            *d.value = v;
    }
    if (const toml::node* n = t.get("strength")) {
        if (std::optional<Param> p = param(*n, what + ": strength", 1)) g.strength = std::move(*p);
    }
    if (const toml::node* n = t.get("travel_speed")) {
        double v = 0.0;
        if (number(*n, what + ": travel_speed", v)) {
            if (v > 0.0)
                g.travelSpeed = v;
            else
                error(*n, what + ": travel_speed must be positive (m/s)");
        }
    }
}

void Loader::loadField(const toml::table& t, size_t index, const std::string& baseDir,
                       FieldEntry& f) {
    checkKeys(t, {"name", "expr", "source", "preset", "params", "scale", "mask"}, "[[field]]");
    f.name = "field" + std::to_string(index);
    if (const toml::node* n = t.get("name")) {
        std::string name;
        if (string(*n, "field.name", name)) {
            if (name.empty() || name.find('.') != std::string::npos)
                error(*n, "a field's name must be non-empty and without dots (--set uses "
                          "field.NAME.KEY)");
            else
                f.name = name;
        }
    }
    const std::string what = "field '" + f.name + "'";
    const toml::node* expr = t.get("expr");
    const toml::node* source = t.get("source");
    const toml::node* preset = t.get("preset");
    const int given = (expr ? 1 : 0) + (source ? 1 : 0) + (preset ? 1 : 0);
    if (given == 0) {
        error(t, what + " needs its expression: expr = \"file.se\" (relative to the scene), "
                        "source = \"...\" (inline) or preset = \"wind\"");
    } else if (given > 1) {
        const toml::node* second = preset ? preset : source;
        error(*second, what + ": give only one of expr, source and preset");
    } else if (expr) {
        std::string path;
        if (string(*expr, what + ": expr", path)) {
            if (path.empty()) {
                error(*expr, what + ": expr must name a file");
            } else {
                std::filesystem::path p(path);
                f.exprPath = p.is_absolute() || baseDir.empty()
                                 ? path
                                 : (std::filesystem::path(baseDir) / p).lexically_normal().string();
            }
        }
    } else if (source) {
        if (string(*source, what + ": source", f.source))
            verbatimPosition(*source, f.source, f.sourceLine, f.sourceCol);
    } else if (preset) {
        std::string name;
        if (string(*preset, what + ": preset", name)) {
            if (findPreset(name)) {
                f.preset = name;
            } else {
                SceneError& e = error(*preset, "unknown preset '" + name + "'");
                std::vector<std::string> names;
                for (const Preset& p : presets()) names.emplace_back(p.name);
                std::string hint = didYouMean(name, names);
                if (!hint.empty()) e.notes.push_back(hint);
                e.notes.push_back("presets: " + presetNames());
            }
        }
    }
    if (const toml::node* n = t.get("params")) {
        const toml::table* params = n->as_table();
        if (!params) {
            error(*n, what + ": params must be a table, e.g. params = { speed = 8 }");
        } else {
            for (auto&& [key, value] : *params) {
                const std::string name(key.str());
                if (std::optional<Param> p = param(value, what + ": parameter '" + name + "'", 0))
                    f.params[name] = std::move(*p);
            }
        }
    }
    if (const toml::node* n = t.get("scale")) {
        if (std::optional<Param> p = param(*n, what + ": scale", 1)) f.scale = std::move(*p);
    }
    if (const toml::node* n = t.get("mask")) {
        if (string(*n, what + ": mask", f.mask)) {
            if (trimText(f.mask).empty())
                error(*n, what + ": mask must be an expression, e.g. mask = \"smoothstep($P[1], 0, 2)\"");
            else
                verbatimPosition(*n, f.mask, f.maskLine, f.maskCol);
        }
    }
}

// Overrides must name parameters the expression declares, with a fitting width.
void Loader::checkParams(const toml::table& params, const FieldEntry& f, const Scene& scene,
                         const toml::node* sourceNode) {
    lang::SourceFile source;
    std::string problem;
    if (!fieldSource(scene, f, source, problem)) {
        if (sourceNode) error(*sourceNode, "field '" + f.name + "': " + problem).io = true;
        return;
    }
    const std::vector<ParameterDecl> decls = findParameters(source);
    std::vector<std::string> names;
    for (const ParameterDecl& d : decls) names.push_back(d.name);
    const std::string of = f.preset.empty() ? (f.exprPath.empty() ? "its inline source" : f.exprPath)
                                            : "the " + f.preset + " preset";
    for (auto&& [key, value] : params) {
        const std::string name(key.str());
        auto decl = std::find_if(decls.begin(), decls.end(),
                                 [&](const ParameterDecl& d) { return d.name == name; });
        if (decl == decls.end()) {
            SceneError& e = error(key.source().begin.line ? key.source() : value.source(),
                                  "'" + name + "' is not a parameter of " + of);
            std::string hint = didYouMean(name, names);
            if (!hint.empty()) e.notes.push_back(hint);
            e.notes.push_back(names.empty() ? "it declares no parameters (a top-level `$name = "
                                              "value;  # min, max` statement declares one)"
                                            : "its parameters: " + joinNames(names));
            continue;
        }
        auto p = f.params.find(name);
        if (p == f.params.end()) continue; // already reported
        if (scene.windicator && f.preset == "wind" && (name == "speed" || name == "direction")) {
            // The preset reads getVar("windSpeed", $speed): the windicator would win silently.
            SceneError& e = error(key.source().begin.line ? key.source() : value.source(),
                                  "with a [windicator], the wind preset's '" + name +
                                      "' comes from it: set windicator." + name + " instead");
            e.notes.push_back("or copy the preset into a file (expr = \"my_wind.se\") to make it "
                              "ignore the windicator");
            continue;
        }
        const int want = static_cast<int>(decl->defaultValue.size());
        if (p->second.width() != want && p->second.width() != 1)
            error(value, "parameter '" + name + "' of " + of + " is " + widthText(want) +
                             ", not " + std::to_string(p->second.width()) + " numbers");
    }
}

void Loader::load(const toml::table& root, Scene& out) {
    const std::vector<std::string> sections = {"scene", "windicator", "gust", "field"};
    std::vector<std::string> known = sections;
    known.insert(known.end(), mOptions.foreignSections.begin(), mOptions.foreignSections.end());
    for (auto&& [key, node] : root) {
        const std::string name(key.str());
        if (std::find(known.begin(), known.end(), name) != known.end()) continue;
        SceneError& e = error(key.source().begin.line ? key.source() : node.source(),
                              "unknown scene section or key '" + name + "'");
        std::string hint = didYouMean(name, known);
        if (!hint.empty()) e.notes.push_back(hint);
        e.notes.push_back("a scene has [scene], [windicator], [[gust]] and [[field]] sections" +
                          std::string(mOptions.foreignSections.empty()
                                          ? ""
                                          : ", and " + joinNames(mOptions.foreignSections) +
                                                " for the solver"));
    }
    if (const toml::node* n = root.get("scene")) {
        if (const toml::table* t = n->as_table())
            loadSettings(*t, out.settings);
        else
            error(*n, "scene must be a table: write [scene]");
    }
    if (const toml::node* n = root.get("windicator")) {
        if (const toml::table* t = n->as_table()) {
            out.windicator = Windicator{};
            loadWindicator(*t, *out.windicator);
        } else {
            error(*n, "windicator must be a table: write [windicator]");
        }
    }
    // [[gust]] and [[field]]: arrays of tables.
    auto tables = [&](const char* section) -> std::vector<const toml::table*> {
        std::vector<const toml::table*> list;
        const toml::node* n = root.get(section);
        if (!n) return list;
        const toml::array* a = n->as_array();
        if (!a) {
            error(*n, std::string(section) + " must be an array of tables: write [[" + section +
                          "]] (once per " + section + ")");
            return list;
        }
        for (const toml::node& e : *a) {
            if (const toml::table* t = e.as_table())
                list.push_back(t);
            else
                error(e, std::string("each ") + section + " must be a table, not " + tomlTypeName(e));
        }
        return list;
    };
    std::set<std::string> gustNames;
    const std::vector<const toml::table*> gustTables = tables("gust");
    for (size_t i = 0; i < gustTables.size(); ++i) {
        Gust g;
        loadGust(*gustTables[i], i, g);
        if (!g.name.empty() && !gustNames.insert(g.name).second)
            error(*gustTables[i]->get("name"), "two gusts are named '" + g.name + "'");
        out.gusts.push_back(std::move(g));
    }
    std::set<std::string> fieldNames;
    const std::vector<const toml::table*> fieldTables = tables("field");
    out.fields.reserve(fieldTables.size());
    for (size_t i = 0; i < fieldTables.size(); ++i) {
        const size_t errorsBefore = mErrors.size();
        FieldEntry f;
        loadField(*fieldTables[i], i, out.baseDir, f);
        if (!fieldNames.insert(f.name).second) {
            const toml::node* n = fieldTables[i]->get("name");
            error(n ? static_cast<const toml::node&>(*n) : *fieldTables[i],
                  "two fields are named '" + f.name + "'");
        }
        // Parameter names can be checked once the expression is known.
        const toml::node* params = fieldTables[i]->get("params");
        if (mErrors.size() == errorsBefore && params && params->is_table()) {
            const toml::node* sourceNode = fieldTables[i]->get("expr");
            checkParams(*params->as_table(), f, out, sourceNode);
        } else if (mErrors.size() == errorsBefore && !f.exprPath.empty()) {
            // Still report an unreadable expression file at its key.
            lang::SourceFile source;
            std::string problem;
            if (!fieldSource(out, f, source, problem))
                error(*fieldTables[i]->get("expr"), "field '" + f.name + "': " + problem).io = true;
        }
        out.fields.push_back(std::move(f));
    }
}

} // namespace

bool readSceneFile(const std::string& path, std::string& text, toml::table& root,
                   std::vector<SceneError>& errors) {
    {
        std::error_code ec;
        errno = 0;
        std::ifstream in;
        if (!std::filesystem::is_directory(path, ec)) in.open(path, std::ios::binary);
        if (!in) {
            SceneError e;
            e.file = path;
            e.message = std::string("cannot read the scene: ") + std::strerror(errno ? errno : EISDIR);
            e.io = true;
            errors.push_back(std::move(e));
            return false;
        }
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    return parseSceneText(path, text, root, errors);
}

bool parseSceneText(const std::string& path, const std::string& text, toml::table& root,
                    std::vector<SceneError>& errors) {
    try {
        root = toml::parse(text, path);
    } catch (const toml::parse_error& e) {
        TomlReader reader(path, text, errors);
        SceneError& se = reader.error(e.source(), std::string(e.description()));
        se.file = path;
        return false;
    }
    return true;
}

bool loadWindSections(const std::string& path, const std::string& text, toml::table& root,
                      Scene& out, std::vector<SceneError>& errors, const SceneLoadOptions& options) {
    const size_t errorsBefore = errors.size();
    Loader loader(path, text, errors, options);
    loader.applySets(root);
    loader.load(root, out);
    // In file order (--set problems, which have no line, first), as a compiler reports.
    std::stable_sort(errors.begin() + static_cast<std::ptrdiff_t>(errorsBefore), errors.end(),
                     [](const SceneError& a, const SceneError& b) {
                         return a.line != b.line ? a.line < b.line : a.col < b.col;
                     });
    return errors.size() == errorsBefore;
}

} // namespace gale::scene
