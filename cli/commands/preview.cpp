// Preview renders: `gale viz SCENE.toml --frames A:B` draws each simulated frame (cloth shaded,
// hair as strands) over the wind slice with the windicator and gust timeline, and
// `gale viz --contact-sheet WEDGEDIR` lays a wedge's variants out as labelled thumbnails.
#include "cli/commands/preview.h"

#include "cli/common.h"
#include "cli/wedge/wedge.h"
#include "fields/grid_sample.h"
#include "scene/document.h"
#include "scene/load.h"
#include "scene/sim_scene.h"
#include "solver/collider/moving_collider.h"
#include "viz/cairo_render.h"
#include "viz/overlays.h"
#include "viz/slice_marks.h"
#include "viz/strain.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

namespace gale::cli {

namespace {

// The --set overrides a run recorded in DIR/run.json (settings.sets), or none. A run.json that
// is there but cannot be read (truncated, not JSON) is said: the picture then shows the scene
// without the run's overrides.
std::vector<std::string> recordedSets(const std::string& dir) {
    const std::filesystem::path path = std::filesystem::path(dir) / "run.json";
    std::ifstream in(path);
    if (!in) return {};
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object()) {
        std::cerr << "gale: warning: " << path.string()
                  << " is not a run's JSON (truncated?): drawing the scene without the run's "
                     "--set overrides\n";
        return {};
    }
    std::vector<std::string> sets;
    if (j.is_object() && j.contains("settings") && j["settings"].contains("sets") &&
        j["settings"]["sets"].is_array())
        for (const auto& s : j["settings"]["sets"])
            if (s.is_string()) sets.push_back(s.get<std::string>());
    return sets;
}

namespace fs = std::filesystem;

std::string framedName(const std::string& dir, const std::string& object, long frame, const std::string& ext) {
    char buf[32];
    std::snprintf(buf, sizeof buf, ".%04ld.", frame);
    return (fs::path(dir) / (object + buf + ext)).string();
}

// ---- a small JSON reader for manifest.jsonl ----

struct Json {
    enum Type { Null, Bool, Number, String, Array, Object } type = Null;
    std::string text; // a string's value, or a number as written
    double number = 0.0;
    std::vector<Json> items;
    std::vector<std::pair<std::string, Json>> members;

    const Json* get(const std::string& key) const {
        for (const auto& m : members)
            if (m.first == key) return &m.second;
        return nullptr;
    }
    std::string str(const std::string& key) const {
        const Json* j = get(key);
        return j && j->type == String ? j->text : std::string();
    }
};

class JsonReader {
public:
    explicit JsonReader(const std::string& s) : mS(s) {}
    bool parse(Json& out) {
        const bool ok = value(out);
        space();
        return ok && mPos == mS.size();
    }

private:
    void space() {
        while (mPos < mS.size() && std::isspace(static_cast<unsigned char>(mS[mPos]))) ++mPos;
    }
    bool string(std::string& out) {
        if (mS[mPos] != '"') return false;
        ++mPos;
        while (mPos < mS.size() && mS[mPos] != '"') {
            char c = mS[mPos++];
            if (c == '\\' && mPos < mS.size()) {
                const char e = mS[mPos++];
                c = e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e;
                if (e == 'u') { // \u00XX (what jsonString writes for control characters)
                    if (mPos + 4 > mS.size()) return false;
                    c = static_cast<char>(std::stoi(mS.substr(mPos, 4), nullptr, 16));
                    mPos += 4;
                }
            }
            out += c;
        }
        if (mPos >= mS.size()) return false;
        ++mPos;
        return true;
    }
    bool value(Json& out) {
        space();
        if (mPos >= mS.size()) return false;
        const char c = mS[mPos];
        if (c == '{') {
            out.type = Json::Object;
            ++mPos;
            space();
            if (mPos < mS.size() && mS[mPos] == '}') return ++mPos, true;
            for (;;) {
                space();
                std::string key;
                if (mPos >= mS.size() || !string(key)) return false;
                space();
                if (mPos >= mS.size() || mS[mPos++] != ':') return false;
                Json v;
                if (!value(v)) return false;
                out.members.emplace_back(key, std::move(v));
                space();
                if (mPos < mS.size() && mS[mPos] == ',') {
                    ++mPos;
                    continue;
                }
                return mPos < mS.size() && mS[mPos++] == '}';
            }
        }
        if (c == '[') {
            out.type = Json::Array;
            ++mPos;
            space();
            if (mPos < mS.size() && mS[mPos] == ']') return ++mPos, true;
            for (;;) {
                Json v;
                if (!value(v)) return false;
                out.items.push_back(std::move(v));
                space();
                if (mPos < mS.size() && mS[mPos] == ',') {
                    ++mPos;
                    continue;
                }
                return mPos < mS.size() && mS[mPos++] == ']';
            }
        }
        if (c == '"') {
            out.type = Json::String;
            return string(out.text);
        }
        for (const char* word : {"true", "false", "null"})
            if (mS.compare(mPos, std::strlen(word), word) == 0) {
                out.type = word[0] == 'n' ? Json::Null : Json::Bool;
                out.number = word[0] == 't';
                mPos += std::strlen(word);
                return true;
            }
        const size_t start = mPos;
        while (mPos < mS.size() && std::string("+-0123456789.eE").find(mS[mPos]) != std::string::npos) ++mPos;
        if (mPos == start) return false;
        out.type = Json::Number;
        out.text = mS.substr(start, mPos - start);
        out.number = std::strtod(out.text.c_str(), nullptr);
        return true;
    }

    const std::string& mS;
    size_t mPos = 0;
};

std::string jsonText(const Json& j) {
    if (j.type == Json::String || j.type == Json::Number) return j.text;
    if (j.type == Json::Bool) return j.number != 0 ? "true" : "false";
    return "?";
}

bool boundsFromFlag(const std::string& text, std::array<double, 4>& b) {
    std::vector<double> v;
    std::string error;
    if (!parseNumbers(text, 4, "--bounds", v, error) || !(v[2] > v[0]) || !(v[3] > v[1])) {
        printError("--bounds '" + text + "': expected u0,v0,u1,v1 with u1 > u0 and v1 > v0" +
                   (error.empty() ? std::string() : " (" + error + ")"));
        return false;
    }
    b = {v[0], v[1], v[2], v[3]};
    return true;
}

} // namespace

bool parseFrameList(const std::string& text, std::vector<long>& out, std::string& error) {
    out.clear();
    if (text.find(',') != std::string::npos) {
        std::stringstream in(text);
        for (std::string part; std::getline(in, part, ',');) {
            long a = 0, b = 0;
            if (!parseFrameRange(part, a, b, error) || a != b) {
                error = "--frames '" + text + "': expected A:B, A:B:STEP or a list of frames (12,24,48)";
                return false;
            }
            out.push_back(a);
        }
        return !out.empty();
    }
    const size_t first = text.find(':'), second = first == std::string::npos ? first : text.find(':', first + 1);
    long a = 0, b = 0, step = 1;
    if (second != std::string::npos) {
        long s0 = 0, s1 = 0;
        if (!parseFrameRange(text.substr(0, second), a, b, error) ||
            !parseFrameRange(text.substr(second + 1), s0, s1, error) || s0 != s1 || s0 < 1) {
            error = "--frames '" + text + "': expected A:B:STEP with a positive STEP";
            return false;
        }
        step = s0;
    } else if (!parseFrameRange(text, a, b, error)) {
        return false;
    }
    if ((b - a) / step > 100000) {
        error = "--frames '" + text + "': more than 100000 frames";
        return false;
    }
    for (long f = a; f <= b; f += step) out.push_back(f);
    return true;
}

int runVizFrames(const VizOptions& o) {
    std::string error;
    if (!isSceneFile(o.source.file)) {
        printError("--frames draws a simulation: give the SCENE.toml it was run from");
        return kExitUsage;
    }
    std::vector<long> frames;
    int normal = 2, width = 0, height = 0;
    double planeValue = 0.0;
    viz::ImageFormat format;
    std::string probe;
    if (!parseFrameList(o.frames, frames, error) || !parsePlane(o.plane, normal, planeValue, error) ||
        !parseSize(o.size, width, height, error)) {
        printError(error);
        return kExitUsage;
    }
    if (!viz::imageFormatFromPath(o.output, format) ||
        !io::framePath(o.output, frames.front(), probe)) {
        printError("-o '" + o.output + "': with --frames, name a .png or .svg with one run of # for the frame "
                   "number (preview.#.png)");
        return kExitUsage;
    }
    int uAxis = 0, vAxis = 1;
    viz::planeAxes(normal, uAxis, vAxis);

    // The scene as the run used it: the run's own --set overrides (run.json) first, then any
    // given here.
    const std::string dir = o.sim.empty() ? "sim" : o.sim;
    SourceOptions source = o.source;
    const std::vector<std::string> runSets = recordedSets(dir);
    if (!runSets.empty()) {
        // Said as applied: a key given here again wins over the run's (it comes later). Keys
        // compare as the scene resolves them (cloth.cape.stretch is cloth.0.stretch).
        scene::SceneDocument doc;
        std::vector<scene::SceneError> ignored; // (an unreadable scene is said when it loads)
        const bool read = doc.read(o.source.file, ignored);
        const auto keyOf = [&](const std::string& set) {
            return read ? doc.canonicalSetKey(set) : set.substr(0, set.find('='));
        };
        std::string kept, replaced;
        for (const std::string& s : runSets) {
            const bool again =
                std::any_of(o.source.sets.begin(), o.source.sets.end(),
                            [&](const std::string& mine) { return keyOf(mine) == keyOf(s); });
            (again ? replaced : kept) += " --set " + s;
        }
        if (!kept.empty())
            std::cerr << "gale: drawing the scene with the run's overrides:" << kept << '\n';
        if (!replaced.empty())
            std::cerr << "gale: the run's" << replaced << " replaced by this command's --set\n";
        source.sets.insert(source.sets.begin(), runSets.begin(), runSets.end());
    }
    FieldInput input;
    if (int rc = loadFieldInput(source, o.fps, input)) return rc;
    scene::SimScene sim;
    std::vector<scene::SceneError> errors;
    if (!gale::scene::loadSimScene(source.file, sim, errors, source.sets)) {
        for (const scene::SceneError& e : errors) std::cerr << e.render() << '\n';
        return kExitInput;
    }
    std::vector<std::pair<std::string, std::string>> objects;
    for (const scene::ClothSpec& c : sim.cloths) objects.emplace_back(c.name, c.output);
    for (const scene::HairSpec& h : sim.hairs) objects.emplace_back(h.name, h.output);
    if (objects.empty()) {
        printError(o.source.file + ": the scene has no [[cloth]] or [[hair]] to draw");
        return kExitInput;
    }
    std::map<long, std::vector<viz::GeometryOverlay>> geometry;
    std::vector<const viz::GeometryOverlay*> all;
    for (long f : frames) {
        for (const auto& [name, ext] : objects) {
            viz::GeometryOverlay g;
            if (!viz::loadFrameGeometry(framedName(dir, name, f, ext), g, error)) {
                printError(error);
                return kExitIo;
            }
            g.label = name;
            geometry[f].push_back(std::move(g));
        }
    }
    if (o.strain) {
        // The rest shapes the solver starts from (as gale live's); each frame's strain against
        // them.
        std::vector<std::unique_ptr<solver::Body>> bodies;
        std::vector<std::string> warnings;
        if (!scene::buildBodies(sim, bodies, errors, warnings, o.source.allowPaths)) {
            for (const scene::SceneError& e : errors) std::cerr << e.render() << '\n';
            return kExitInput;
        }
        std::vector<viz::GeometryOverlay> rest(bodies.size());
        for (size_t k = 0; k < bodies.size(); ++k) {
            std::istringstream obj(scene::bodyObjText(*bodies[k]));
            viz::parseObjGeometry(obj, rest[k]);
        }
        for (auto& [f, gs] : geometry)
            for (size_t k = 0; k < gs.size() && k < rest.size(); ++k)
                gs[k].strain = viz::vertexStrain(rest[k], gs[k]);
    }
    // The moving bodies (mesh-sequence colliders) at each frame's time, as the solver saw them.
    for (const solver::Collider& c : sim.colliders) {
        if (!c.moving) continue;
        const solver::MeshSequence& seq = c.moving->mesh();
        for (long f : frames) {
            viz::GeometryOverlay g;
            g.label = c.name;
            g.body = true;
            std::vector<double> x;
            seq.positionsAt(input.frameTime(static_cast<double>(f)), x);
            for (size_t i = 0; i + 2 < x.size(); i += 3) g.points.push_back({x[i], x[i + 1], x[i + 2]});
            g.triangles = seq.triangles();
            geometry[f].push_back(std::move(g));
        }
    }
    for (auto& [f, gs] : geometry)
        for (const viz::GeometryOverlay& g : gs) all.push_back(&g);
    std::array<double, 4> b{};
    if (!o.bounds.empty() ? !boundsFromFlag(o.bounds, b) : !viz::geometryBounds(all, uAxis, vAxis, b)) {
        if (o.bounds.empty()) printError("the frames hold no finite points to frame; give --bounds");
        return kExitUsage;
    }

    for (long f : frames) {
        const double t = input.frameTime(static_cast<double>(f));
        viz::SliceOverlays overlays;
        if (input.scene) overlays = viz::sceneOverlays(*input.scene, t);
        overlays.geometry = geometry[f];
        viz::SliceLayout layout;
        if (!viz::layoutSlice(width, height, b[2] - b[0], b[3] - b[1], overlays.timeline.present,
                              layout)) {
            printError("--size " + o.size + " " +
                       viz::sliceTooSmall(width, height, b[2] - b[0], b[3] - b[1],
                                          overlays.timeline.present));
            return kExitUsage;
        }
        viz::Slice slice;
        slice.nu = layout.plotW;
        slice.nv = layout.plotH;
        slice.bounds = b;
        slice.uAxis = uAxis;
        slice.vAxis = vAxis;
        slice.normalAxis = normal;
        slice.planeValue = planeValue;
        if (!o.noField)
            if (int rc = sampleSlice(input, t, o.threads, slice)) return rc;
        viz::RenderSettings settings;
        settings.format = format;
        settings.title = input.name + "   \u00b7   frame " + std::to_string(f);
        settings.subtitle = "view along " + std::string(1, "xyz"[normal]) +
                            (o.noField ? std::string() : "   \u00b7   slice " + axisName(normal) + " = " +
                                                             formatValue(planeValue, false) + " m") +
                            "   \u00b7   t = " + shortNumber(t) + " s at " + shortNumber(input.fps) + " fps";
        settings.time = t;
        settings.style = o.style == "streamlines" ? viz::FlowStyle::Streamlines
                         : o.style == "none"      ? viz::FlowStyle::None
                                                  : viz::FlowStyle::Arrows;
        settings.speedMax = o.speedMax;
        settings.arrowSpacing = o.arrowSpacing;
        settings.fieldRaster = !o.noField;
        std::string path;
        io::framePath(o.output, f, path);
        if (io::IoError e = viz::renderSlice(path, layout, slice, overlays, settings)) {
            std::cerr << e.render() << '\n';
            return e.kind == io::IoError::Io ? kExitIo : kExitInput;
        }
    }
    return kExitOk;
}

int runContactSheet(const VizOptions& o) {
    std::string error;
    int normal = 2, cellW = 0, cellH = 0;
    double planeValue = 0.0;
    if (!parsePlane(o.plane, normal, planeValue, error)) {
        printError(error);
        return kExitUsage;
    }
    {
        const size_t x = o.cell.find_first_of("xX");
        std::vector<double> a, c;
        if (x == std::string::npos || !parseNumbers(o.cell.substr(0, x), 1, "--cell", a, error) ||
            !parseNumbers(o.cell.substr(x + 1), 1, "--cell", c, error) || a[0] < 48 || c[0] < 48 || a[0] > 2048 ||
            c[0] > 2048) {
            printError("--cell '" + o.cell + "': expected WxH in pixels, 48 to 2048 (240x240)");
            return kExitUsage;
        }
        cellW = static_cast<int>(a[0]);
        cellH = static_cast<int>(c[0]);
    }
    viz::ImageFormat format;
    if (!viz::imageFormatFromPath(o.output, format) || format != viz::ImageFormat::Png) {
        printError("-o '" + o.output + "': a contact sheet is a .png");
        return kExitUsage;
    }
    int uAxis = 0, vAxis = 1;
    viz::planeAxes(normal, uAxis, vAxis);

    const fs::path manifestPath = fs::path(o.contactSheet) / "manifest.jsonl";
    std::ifstream in(manifestPath);
    if (!in) {
        printError(manifestPath.string() + ": cannot read (is " + o.contactSheet + " a gale wedge output folder?)");
        return kExitIo;
    }
    std::vector<Json> variants;
    int lineNo = 0;
    for (std::string line; std::getline(in, line);) {
        ++lineNo;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        Json j;
        if (!JsonReader(line).parse(j) || j.type != Json::Object) {
            printError(manifestPath.string() + ":" + std::to_string(lineNo) + ": not a JSON object");
            return kExitInput;
        }
        variants.push_back(std::move(j));
    }
    if (variants.empty()) {
        printError(manifestPath.string() + ": no variants");
        return kExitInput;
    }
    std::vector<long> frames;
    if (!o.frames.empty()) {
        if (!parseFrameList(o.frames, frames, error)) {
            printError(error);
            return kExitUsage;
        }
    } else if (const Json* fr = variants[0].get("frames"); fr && fr->items.size() == 2) {
        const long a = static_cast<long>(fr->items[0].number), z = static_cast<long>(fr->items[1].number);
        frames = {a, a + (z - a) / 2, z};
        frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    }
    if (frames.empty() || frames.size() > 64) {
        printError("--frames: give between 1 and 64 frames for the sheet's columns");
        return kExitUsage;
    }

    viz::ContactSheet sheet;
    sheet.title = "gale wedge " + o.contactSheet + "   \u00b7   " + std::to_string(variants.size()) + " variants";
    sheet.cellW = cellW;
    sheet.cellH = cellH;
    for (long f : frames) sheet.columnHeadings.push_back("frame " + std::to_string(f));
    std::vector<std::string> keys;
    for (const auto& m : variants[0].get("values") ? variants[0].get("values")->members
                                                   : std::vector<std::pair<std::string, Json>>{})
        keys.push_back(m.first);
    const std::vector<std::string> shortNames = shortKeyNames(keys);
    std::vector<std::vector<std::vector<viz::GeometryOverlay>>> geometry(variants.size());
    std::vector<const viz::GeometryOverlay*> all;
    int missing = 0;
    for (size_t r = 0; r < variants.size(); ++r) {
        const Json& v = variants[r];
        std::string dir = v.str("path");
        if (dir.empty() || !fs::is_directory(dir)) dir = (fs::path(o.contactSheet) / v.str("folder")).string();
        std::vector<std::string> labels = {v.str("id") + (v.str("status") == "done" ? "" : "  (" + v.str("status") + ")")};
        if (const Json* values = v.get("values"))
            for (size_t k = 0; k < values->members.size(); ++k)
                labels.push_back((k < shortNames.size() ? shortNames[k] : values->members[k].first) + " = " +
                                 jsonText(values->members[k].second));
        sheet.rowLabels.push_back(labels);
        geometry[r].resize(frames.size());
        for (size_t c = 0; c < frames.size(); ++c) {
            if (const Json* objs = v.get("objects"))
                for (const Json& ob : objs->items) {
                    viz::GeometryOverlay g;
                    if (viz::loadFrameGeometry(
                            framedName(dir, ob.str("name"), frames[c], ob.str("format")), g,
                            error)) {
                        g.label = ob.str("name");
                        geometry[r][c].push_back(std::move(g));
                    } else {
                        ++missing;
                    }
                }
        }
    }
    for (auto& row : geometry)
        for (auto& cell : row)
            for (const viz::GeometryOverlay& g : cell) all.push_back(&g);
    if (all.empty()) {
        printError(o.contactSheet + ": none of the variants has those frames yet (run the wedge first)");
        return kExitIo;
    }
    if (missing > 0) std::cerr << "gale viz: " << missing << " frame file(s) missing; their thumbnails are empty\n";
    std::array<double, 4> b{};
    if (!o.bounds.empty() ? !boundsFromFlag(o.bounds, b) : !viz::geometryBounds(all, uAxis, vAxis, b)) {
        if (o.bounds.empty()) printError("the frames hold no finite points to frame; give --bounds");
        return kExitUsage;
    }
    for (size_t r = 0; r < variants.size(); ++r) {
        std::vector<viz::ContactCell> row;
        for (size_t c = 0; c < frames.size(); ++c) {
            viz::ContactCell cell;
            cell.slice.bounds = b;
            cell.slice.uAxis = uAxis;
            cell.slice.vAxis = vAxis;
            cell.slice.normalAxis = normal;
            cell.slice.planeValue = planeValue;
            cell.overlays.geometry = std::move(geometry[r][c]);
            cell.settings.compact = true;
            cell.settings.fieldRaster = false;
            row.push_back(std::move(cell));
        }
        sheet.rows.push_back(std::move(row));
    }
    if (io::IoError e = viz::renderContactSheet(o.output, sheet)) {
        std::cerr << e.render() << '\n';
        return e.kind == io::IoError::Io ? kExitIo : kExitInput;
    }
    return kExitOk;
}

} // namespace gale::cli
