// Loading what `gale live` shows (project.h): the scene or expression compiled to a field,
// diagnostics as `gale check` prints them, parameters and ramps at the literal that holds their
// effective value, watched files, rest meshes and colliders; and in-place literal edits.
#include "live/project.h"

#include "fields/expression_field.h"
#include "io/atomic_file.h"
#include "lang/diagnostics.h"
#include "scene/document.h"
#include "scene/load.h"
#include "scene/sim_scene.h"
#include "solver/bodies/body.h"
#include "solver/collider/collider.h"
#include "solver/collider/moving_collider.h"
#include "solver/mesh/mesh_sequence.h"
#include "viz/overlays.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>

namespace gale::live {

namespace fs = std::filesystem;

namespace {

constexpr size_t kMaxFileBytes = 16u << 20;

bool readText(const std::string& path, std::string& out, std::string& error) {
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec) {
        error = path + ": cannot read: " + ec.message();
        return false;
    }
    if (size > kMaxFileBytes) {
        error = path + ": larger than 16 MB; not an expression or scene";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error = path + ": cannot read";
        return false;
    }
    std::ostringstream s;
    s << in.rdbuf();
    out = s.str();
    return true;
}

// The rendered diagnostics of buildSceneField (`file:line:col: error: message`, then source and
// caret lines, then notes) as one Diagnostic each.
void parseReport(const std::string& report, std::vector<Diagnostic>& out) {
    static const std::regex head(R"(^(.*?):(\d+):(\d+): (error|warning): (.*)$)");
    std::istringstream in(report);
    Diagnostic* current = nullptr;
    for (std::string line; std::getline(in, line);) {
        std::smatch m;
        if (std::regex_match(line, m, head)) {
            Diagnostic d;
            d.file = m[1];
            d.line = std::stoi(m[2]);
            d.col = std::stoi(m[3]);
            d.severity = m[4];
            d.message = m[5];
            d.text = line;
            out.push_back(std::move(d));
            current = &out.back();
        } else if (current) {
            current->text += "\n" + line;
        } else if (!line.empty()) {
            Diagnostic d;
            d.message = line;
            d.text = line;
            out.push_back(std::move(d));
        }
    }
}

void fromSink(const lang::SourceFile& file, const lang::DiagnosticSink& sink,
              std::vector<Diagnostic>& out) {
    for (const lang::Diagnostic& d : sink.diagnostics()) {
        Diagnostic o;
        o.file = file.name();
        const lang::LineCol lc = file.lineCol(d.span.begin);
        o.line = static_cast<int>(lc.line);
        o.col = static_cast<int>(lc.col);
        o.severity = d.severity == lang::Severity::Error     ? "error"
                     : d.severity == lang::Severity::Warning ? "warning"
                                                             : "note";
        o.message = d.message;
        o.text = lang::renderDiagnostic(file, d);
        while (!o.text.empty() && o.text.back() == '\n') o.text.pop_back();
        out.push_back(std::move(o));
    }
}

// String literals in an expression that name files beside it (sdf("body.obj"), vdb(...));
// those that name no file yet (a frame sequence `body/body.#.obj`, a mesh still to be written)
// go to `missing`.
std::vector<std::string> namedFiles(const std::string& text, const std::string& dir,
                                    std::vector<std::string>* missing = nullptr) {
    std::vector<std::string> out;
    static const std::regex str(R"re("([^"\\\n]{1,400})")re");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), str);
         it != std::sregex_iterator(); ++it) {
        const fs::path p = fs::path(dir) / (*it)[1].str();
        std::error_code ec;
        if (fs::is_regular_file(p, ec))
            out.push_back(p.lexically_normal().string());
        else if (missing)
            missing->push_back(p.lexically_normal().string());
    }
    return out;
}

// A string that could name a file gale reads: a '#' frame sequence or a known extension.
bool looksLikeFile(const fs::path& p) {
    static const std::set<std::string> exts = {".obj", ".ply",  ".se",  ".vdb", ".npy",
                                               ".csv", ".json", ".mdd", ".toml"};
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return p.filename().string().find('#') != std::string::npos || exts.count(ext);
}

// One collider at time t: its pose (solver::colliderPose, the solver's own placement) and, for
// a mesh sequence, its vertices at t (MeshSequence::positionsAt, as the contact code uses them).
ColliderShape colliderAt(const solver::Collider& c, double t) {
    const solver::ColliderPose pose = solver::colliderPose(c, t);
    ColliderShape s;
    s.name = c.name;
    s.shape = c.shape == solver::ColliderShape::Plane     ? "plane"
              : c.shape == solver::ColliderShape::Sphere  ? "sphere"
              : c.shape == solver::ColliderShape::Capsule ? "capsule"
                                                          : "mesh";
    s.a = {pose.a[0], pose.a[1], pose.a[2]};
    s.b = {pose.b[0], pose.b[1], pose.b[2]};
    s.normal = {pose.normal[0], pose.normal[1], pose.normal[2]};
    s.radius = pose.radius;
    if (c.moving) {
        const solver::MeshSequence& seq = c.moving->mesh();
        std::vector<double> x;
        seq.positionsAt(t, x);
        s.moving = seq.moving();
        s.mesh.label = c.name;
        s.mesh.points.resize(x.size() / 3);
        for (size_t v = 0; v < s.mesh.points.size(); ++v)
            s.mesh.points[v] = {x[3 * v], x[3 * v + 1], x[3 * v + 2]};
        for (const auto& tri : seq.triangles())
            s.mesh.triangles.push_back({tri[0], tri[1], tri[2]});
    }
    return s;
}

} // namespace

std::vector<ColliderShape> Project::collidersAt(double t) const {
    std::vector<ColliderShape> out;
    for (size_t i = 0; i < mSimColliders.size(); ++i) {
        const solver::Collider& c = mSimColliders[i];
        out.push_back(colliderAt(c, t));
        if (c.shape == solver::ColliderShape::Mesh && !c.moving && i < mColliders.size())
            out.back().mesh = mColliders[i].mesh;
    }
    return out;
}

Project::Project(std::string input, std::vector<std::string> allowPaths)
    : mInput(std::move(input)), mAllowPaths(std::move(allowPaths)) {}

void Project::addPattern(const std::string& path) {
    const fs::path p = fs::path(path).lexically_normal();
    if (looksLikeFile(p) &&
        std::find(mPatterns.begin(), mPatterns.end(), p.string()) == mPatterns.end())
        mPatterns.push_back(p.string());
}

void Project::addFile(const std::string& path) {
    const std::string p = fs::path(path).lexically_normal().string();
    if (std::find(mFiles.begin(), mFiles.end(), p) == mFiles.end()) mFiles.push_back(p);
}

bool Project::load() {
    mFiles.clear();
    mPatterns.clear();
    mDiagnostics.clear();
    mParams.clear();
    mRamps.clear();
    mField.reset();
    mScene.reset();
    mRest.clear();
    mColliders.clear();
    mSimColliders.clear();
    mObjects.clear();
    addFile(mInput);
    std::string ext = fs::path(mInput).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".toml")
        loadSceneFile();
    else
        loadExpressionFile();
    for (size_t i = 0; i < mRamps.size(); ++i) mRamps[i].id = static_cast<int>(i);
    computeBox();
    return ok();
}

void Project::loadExpressionFile() {
    std::string text, error;
    if (!readText(mInput, text, error)) {
        mDiagnostics.push_back({mInput, 0, 0, "error", error, mInput + ": error: " + error});
        return;
    }
    const lang::SourceFile file(mInput, text);
    const SourceLiterals lits = findLiterals(file);
    for (const ParamLiteral& p : lits.params)
        mParams.push_back({"", mInput, mInput, p, true, text.substr(p.begin, p.end - p.begin)});
    for (const RampLiteral& r : lits.ramps)
        mRamps.push_back({0, mInput, r, text.substr(r.begin, r.end - r.begin)});
    std::vector<std::string> missing;
    for (const std::string& f : namedFiles(text, fs::path(mInput).parent_path().string(), &missing))
        addFile(f);
    for (const std::string& m : missing) addPattern(m);
    fields::ExpressionFieldOptions options;
    options.files = geometry::fileAccessFor(mInput, mAllowPaths);
    lang::DiagnosticSink sink;
    auto field = fields::ExpressionField::compile(file, options, sink);
    fromSink(file, sink, mDiagnostics);
    if (field && !sink.hasErrors()) mField = field;
}

void Project::loadSceneFile() {
    gale::scene::SimScene sim;
    std::vector<gale::scene::SceneError> errors;
    std::string sceneText, error;
    if (!readText(mInput, sceneText, error)) {
        mDiagnostics.push_back({mInput, 0, 0, "error", error, mInput + ": error: " + error});
        return;
    }
    // Every string in the scene naming a file beside it is watched (expressions, meshes,
    // strands, collider meshes), and the field overrides' literals are located. A syntax error
    // is loadSimScene's to report at file:line:col.
    gale::scene::SceneDocument doc;
    std::vector<gale::scene::SceneError> syntax;
    const bool parsed = doc.parse(mInput, sceneText, syntax);
    const std::string baseDir = fs::path(mInput).parent_path().string();
    if (parsed) {
        for (const std::string& f : doc.namedFiles()) addFile(f);
        for (const std::string& p : doc.otherPaths()) addPattern(p); // (not there yet: watched for)
    }
    const bool loaded = gale::scene::loadSimScene(mInput, sim, errors);
    for (const gale::scene::SceneError& e : errors) {
        std::string text = e.render();
        while (!text.empty() && text.back() == '\n') text.pop_back();
        mDiagnostics.push_back({e.file, e.line, e.col, "error", e.message, text});
    }
    if (!loaded) return;
    auto scene = std::make_shared<fields::Scene>(sim.wind);
    mFps = scene->settings.fps > 0 ? scene->settings.fps : 24.0;
    mTimeZero = scene->settings.timeZero;
    mFrameStart = scene->settings.frameStart;
    mFrameEnd = scene->settings.frameEnd;
    mScene = scene;
    for (const gale::scene::ClothSpec& c : sim.cloths) mObjects.push_back({c.name, c.output});
    for (const gale::scene::HairSpec& h : sim.hairs) mObjects.push_back({h.name, h.output});

    // Parameters of each expression file, and the scene's overrides of them.
    for (size_t i = 0; i < scene->fields.size(); ++i) {
        const fields::FieldEntry& entry = scene->fields[i];
        if (entry.exprPath.empty()) continue;
        std::string text;
        if (!readText(entry.exprPath, text, error)) continue; // buildSceneField reports it
        const lang::SourceFile file(entry.exprPath, text);
        std::vector<std::string> missing;
        for (const std::string& f :
             namedFiles(text, fs::path(entry.exprPath).parent_path().string(), &missing))
            addFile(f);
        for (const std::string& m : missing) addPattern(m);
        const SourceLiterals lits = findLiterals(file);
        for (const ParamLiteral& p : lits.params) {
            LiveParam lp{entry.name, entry.exprPath, entry.exprPath,
                         p,          true,           text.substr(p.begin, p.end - p.begin)};
            auto over = entry.params.find(p.name);
            if (over != entry.params.end()) {
                lp.literal.value = over->second.at(0.0);
                lp.editable = false;
                // A constant number (or array of numbers) in `params = { name = ... }`.
                const std::optional<gale::scene::SourceSpan> span =
                    parsed && !over->second.isKeyed() ? doc.fieldParamLiteral(i, p.name)
                                                      : std::nullopt;
                if (span) {
                    lp.file = mInput;
                    lp.literal.line = span->line;
                    lp.literal.col = span->col;
                    lp.literal.begin = static_cast<uint32_t>(span->begin);
                    lp.literal.end = static_cast<uint32_t>(span->end);
                    lp.editable = lp.literal.end > lp.literal.begin;
                    lp.text = sceneText.substr(lp.literal.begin, lp.literal.end - lp.literal.begin);
                }
            }
            mParams.push_back(std::move(lp));
        }
        for (const RampLiteral& r : lits.ramps)
            mRamps.push_back({0, entry.exprPath, r, text.substr(r.begin, r.end - r.begin)});
    }
    std::string report;
    fields::FieldPtr field =
        fields::buildSceneField(*scene, runtime::Precision::Float, report, false, mAllowPaths);
    parseReport(report, mDiagnostics);
    mField = field;

    // Rest meshes of the cloth and hair, and the colliders at t = 0.
    std::vector<std::unique_ptr<solver::Body>> bodies;
    std::vector<gale::scene::SceneError> bodyErrors;
    std::vector<std::string> warnings;
    if (gale::scene::buildBodies(sim, bodies, bodyErrors, warnings, mAllowPaths)) {
        for (size_t b = 0; b < bodies.size(); ++b) {
            viz::GeometryOverlay g;
            std::istringstream obj(gale::scene::bodyObjText(*bodies[b]));
            viz::parseObjGeometry(obj, g);
            g.label = b < sim.cloths.size() ? sim.cloths[b].name
                      : b - sim.cloths.size() < sim.hairs.size()
                          ? sim.hairs[b - sim.cloths.size()].name
                          : "body";
            mRest.push_back(std::move(g));
        }
    } else {
        for (const gale::scene::SceneError& e : bodyErrors) {
            std::string text = e.render();
            while (!text.empty() && text.back() == '\n') text.pop_back();
            mDiagnostics.push_back({e.file, e.line, e.col, "error", e.message, text});
        }
    }
    mSimColliders = sim.colliders;
    for (size_t i = 0; i < sim.colliders.size(); ++i) {
        const solver::Collider& c = sim.colliders[i];
        ColliderShape s = colliderAt(c, 0.0);
        const std::string mesh = parsed ? doc.colliderMesh(i) : std::string();
        if (c.shape == solver::ColliderShape::Mesh && !c.moving && !mesh.empty()) {
            std::string err;
            viz::loadFrameGeometry((fs::path(baseDir) / mesh).string(), s.mesh, err);
        }
        mColliders.push_back(std::move(s));
    }
}

void Project::computeBox() {
    double lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
        lo[c] = std::numeric_limits<double>::infinity();
        hi[c] = -lo[c];
    }
    auto grow = [&](const std::array<double, 3>& p, double r) {
        for (int c = 0; c < 3; ++c)
            if (std::isfinite(p[c])) {
                lo[c] = std::min(lo[c], p[c] - r);
                hi[c] = std::max(hi[c], p[c] + r);
            }
    };
    for (const viz::GeometryOverlay& g : mRest)
        for (const auto& p : g.points) grow(p, 0.0);
    for (const ColliderShape& c : mColliders) {
        if (c.shape == "plane") continue;
        grow(c.a, c.radius);
        if (c.shape == "capsule") grow(c.b, c.radius);
        for (const auto& p : c.mesh.points) grow(p, 0.0);
    }
    // A mesh sequence anywhere along its motion (a walking body leaves its first pose).
    for (const solver::Collider& c : mSimColliders)
        if (c.moving && c.moving->mesh().moving()) {
            const solver::MeshSequence& seq = c.moving->mesh();
            const long n = static_cast<long>(seq.frameCount());
            std::vector<double> x;
            for (long k = 0; k < n; k += std::max(1L, n / 8)) {
                seq.positionsAt(seq.frameTime(static_cast<double>(seq.firstFrame() + k)), x);
                for (size_t i = 0; i + 2 < x.size(); i += 3) grow({x[i], x[i + 1], x[i + 2]}, 0.0);
            }
            seq.positionsAt(seq.frameTime(static_cast<double>(seq.lastFrame())), x);
            for (size_t i = 0; i + 2 < x.size(); i += 3) grow({x[i], x[i + 1], x[i + 2]}, 0.0);
        }
    if (!(hi[0] >= lo[0])) {
        mBox = viz::Box3{};
        mBox.lo = {-2, -2, -2};
        mBox.hi = {2, 2, 2};
        return;
    }
    // A cube around the objects, twice their largest extent (at least 2 m).
    double size = 0.0, mid[3];
    for (int c = 0; c < 3; ++c) {
        size = std::max(size, hi[c] - lo[c]);
        mid[c] = 0.5 * (lo[c] + hi[c]);
    }
    const double half = std::max(1.0, size);
    for (int c = 0; c < 3; ++c) {
        mBox.lo[c] = mid[c] - half;
        mBox.hi[c] = mid[c] + half;
    }
}

viz::SliceOverlays Project::overlays(double t) const {
    return mScene ? viz::sceneOverlays(*mScene, t) : viz::SliceOverlays{};
}

bool Project::rewrite(const std::string& file, const std::function<bool(std::string&)>& edit,
                      std::string& error) {
    if (std::find(mFiles.begin(), mFiles.end(), fs::path(file).lexically_normal().string()) ==
        mFiles.end()) {
        error = file + ": not one of the scene's files";
        return false;
    }
    std::string text;
    if (!readText(file, text, error)) return false;
    if (!edit(text)) return false;
    if (io::IoError e = io::writeBytesAtomic(file, text)) {
        error = e.render();
        return false;
    }
    return true;
}

bool Project::setParam(const std::string& name, const std::string& field,
                       const std::vector<double>& value, std::string& error) {
    for (LiveParam& p : mParams) {
        if (p.literal.name != name || (!field.empty() && p.field != field)) continue;
        if (!p.editable) {
            error = "$" + name + " is keyframed or computed in " + p.file + "; edit it there";
            return false;
        }
        // (The caller reloads after an edit: the literal's offsets are those of the file as read.)
        return rewrite(
            p.file,
            [&](std::string& text) {
                if (p.literal.end > text.size() ||
                    text.compare(p.literal.begin, p.literal.end - p.literal.begin, p.text) != 0) {
                    error = p.file + " changed since it was read; reload";
                    return false;
                }
                return rewriteParam(text, p.literal, value, error);
            },
            error);
    }
    error = "no parameter $" + name + (field.empty() ? std::string() : " in field '" + field + "'");
    return false;
}

bool Project::setRamp(int id, const std::vector<RampPoint>& points, std::string& error) {
    for (LiveRamp& r : mRamps) {
        if (r.id != id) continue;
        return rewrite(
            r.file,
            [&](std::string& text) {
                if (r.literal.end > text.size() ||
                    text.compare(r.literal.begin, r.literal.end - r.literal.begin, r.text) != 0) {
                    error = r.file + " changed since it was read; reload";
                    return false;
                }
                return rewriteRamp(text, r.literal, points, error);
            },
            error);
    }
    error = "no ramp " + std::to_string(id);
    return false;
}

} // namespace gale::live
