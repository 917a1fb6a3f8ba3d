// The scene loader's body sections: [[cloth]], [[hair]], [[collider]] and [solver], read from
// the parsed scene after the wind sections (scene/load.cpp). --set overrides are applied to the TOML tree by dotted
// path first; then every key is checked and converted, every problem reported at file:line:col.
#include "io/frame_pattern.h"
#include "scene/load.h"
#include "scene/sections.h"
#include "scene/toml_reader.h"
#include "scene/toml_util.h"
#include "solver/collider/mesh_collider.h"
#include "solver/collider/moving_collider.h"
#include "scene/sim_scene.h"

#include "lang/functions.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

namespace gale::scene {

using namespace gale::solver;

namespace {

// Where a key's value was written, for the errors the build gives later (a mesh that cannot be
// read): its line and column in the scene file, or (line 0) the --set that gave it.
void keyPlace(const toml::node& n, int& line, int& col, std::string& origin) {
    origin = setOrigin(n.source());
    line = origin.empty() ? static_cast<int>(n.source().begin.line) : 0;
    col = origin.empty() ? static_cast<int>(n.source().begin.column) : 0;
}

// Generated cloth and hair grids: at most this many vertices (a million already takes the
// implicit solver minutes a frame and gigabytes).
constexpr long long kMaxGridVertices = 1LL << 20;

// The keys of the step options (Loader::stepOptions), shared by cloth and hair.
std::vector<std::string> withStepKeys(std::vector<std::string> keys) {
    for (const char* k : {"pins", "linear_solver", "preconditioner", "multigrid", "cg_tolerance", "cg_max_iterations",
                          "newton_iterations", "newton_tolerance", "output"})
        keys.push_back(k);
    return keys;
}
const std::vector<std::string> kClothKeys =
    withStepKeys({"name", "mesh", "grid", "density", "stretch", "shear", "bend", "damping", "lift",
                  "drag", "aero_model", "aero_jacobian", "rest_shape", "rest_mesh", "attach",
                  "self_collision", "thickness"});
const std::vector<std::string> kHairKeys = withStepKeys(
    {"name", "strands", "grid", "radius", "density", "stretch", "bend", "damping", "drag_normal",
     "drag_tangent", "root_pinned", "rest_shape", "attach", "collide_cloth"});
const std::vector<std::string> kColliderKeys = {
    "name", "type",      "center",   "radius", "point", "normal",   "a",
    "b",    "thickness", "friction", "mesh",   "voxel", "rest_mesh"};
const std::vector<std::string> kSolverKeys = {
    "max_halvings",       "over_stretch",        "velocity_jump", "retry_newton",
    "retry_cg_tolerance", "retry_keep_coarse",   "retry_repeat",  "grow_back",
    "retry_strain_limit", "rotation_projection", "stretch_limit"};

class Loader : public TomlReader {
public:
    Loader(std::string path, const std::string& text, std::vector<SceneError>& errors)
        : TomlReader(std::move(path), text, errors) {}

    void applySets(toml::table& root, const std::vector<std::string>& sets);
    void load(const toml::table& root, const std::string& baseDir, SimScene& out);

private:
    bool number(const toml::node& n, const std::string& what, double& out, double min, bool strictMin);
    bool choice(const toml::node& n, const std::string& what, const std::vector<std::string>& options,
                std::string& out);
    // choice() among the names of `values` (name(value), the names run.json writes).
    template <class E>
    bool named(const toml::node& n, const std::string& what, std::initializer_list<E> values,
               const char* (*name)(E), E& out) {
        std::vector<std::string> options;
        for (E e : values) options.push_back(name(e));
        std::string v;
        if (!choice(n, what, options, v)) return false;
        for (E e : values)
            if (v == name(e)) out = e;
        return true;
    }
    bool boolean(const toml::node& n, const std::string& what, bool& out);
    bool vec3(const toml::node& n, const std::string& what, Vec3& out);
    bool numbers(const toml::node& n, const std::string& what, size_t count, std::vector<double>& out);
    std::optional<fields::Param> param(const toml::node& n, const std::string& what, int width, double min);
    bool painted(const toml::node& n, const std::string& what, const std::string& baseDir, PaintedSpec& out);
    bool pins(const toml::node& n, const std::string& what, PinSpec& out, bool attachKeys = false);
    bool attach(const toml::node& n, const std::string& what, const std::string& baseDir, bool needSelection,
                PinSpec& out, std::string& meshPath);
    void stepOptions(const toml::table& t, const std::string& what, StepOptions& s, std::string& output);

    void loadCloth(const toml::table& t, size_t index, const std::string& baseDir, ClothSpec& c);
    void loadHair(const toml::table& t, size_t index, const std::string& baseDir, HairSpec& h);
    void loadCollider(const toml::table& t, size_t index, const fields::SceneSettings& settings,
                      std::vector<double>& rest, Collider& c);
    void loadSolver(const toml::table& t, SolverSection& s);
};


// ---- --set ------------------------------------------------------------------------------------

void Loader::applySets(toml::table& root, const std::vector<std::string>& sets) {
    SetSections sections;
    sections.tables = {"solver"};
    sections.lists = {"cloth", "hair", "collider"};
    sections.reportOthers = false; // the wind's loader reports malformed sets and unknown heads
    TomlReader::applySets(root, sets, sections);
}

// ---- values -----------------------------------------------------------------------------------

// attach.stiffness's largest value (N/m per vertex; see its reader).
constexpr double kMaxAttachStiffness = 1e12;

bool Loader::number(const toml::node& n, const std::string& what, double& out, double min, bool strictMin) {
    if (!isTomlNumber(n)) {
        error(n, what + " must be a number, not " + tomlTypeName(n));
        return false;
    }
    const double v = n.value<double>().value_or(0.0);
    if (!std::isfinite(v)) {
        error(n, what + " must be a finite number");
        return false;
    }
    if (strictMin ? !(v > min) : !(v >= min)) {
        error(n, what + " must be " + (strictMin ? "greater than " : "at least ") +
                     io::formatNumber(min) + ", not " + io::formatNumber(v));
        return false;
    }
    out = v;
    return true;
}

bool Loader::choice(const toml::node& n, const std::string& what, const std::vector<std::string>& options,
                    std::string& out) {
    std::string v;
    if (!string(n, what, v)) return false;
    if (std::find(options.begin(), options.end(), v) == options.end()) {
        std::string list;
        for (const std::string& o : options) list += (list.empty() ? "\"" : ", \"") + o + "\"";
        SceneError& e = error(n, "unknown " + what + " '" + v + "' (use " + list + ")");
        const std::string hint = didYouMean(v, options);
        if (!hint.empty()) e.notes.push_back(hint);
        return false;
    }
    out = v;
    return true;
}

bool Loader::boolean(const toml::node& n, const std::string& what, bool& out) {
    if (!n.is_boolean()) {
        error(n, what + " must be true or false, not " + tomlTypeName(n));
        return false;
    }
    out = n.value<bool>().value_or(false);
    return true;
}

bool Loader::numbers(const toml::node& n, const std::string& what, size_t count, std::vector<double>& out) {
    out.clear();
    const toml::array* a = n.as_array();
    bool ok = a && a->size() == count;
    if (ok)
        for (const toml::node& e : *a) {
            if (!isTomlNumber(e) || !std::isfinite(e.value<double>().value_or(NAN))) {
                ok = false;
                break;
            }
            out.push_back(e.value<double>().value_or(0.0));
        }
    if (!ok) error(n, what + " must be an array of " + std::to_string(count) + " numbers");
    return ok;
}

bool Loader::vec3(const toml::node& n, const std::string& what, Vec3& out) {
    std::vector<double> v;
    if (!numbers(n, what, 3, v)) return false;
    out = Vec3(v[0], v[1], v[2]);
    return true;
}

std::optional<fields::Param> Loader::param(const toml::node& n, const std::string& what, int width, double min) {
    if (const toml::table* t = n.as_table()) return keyframes(*t, what, width, min);
    if (width == 1) {
        double v = 0.0;
        if (!isTomlNumber(n)) {
            error(n, what + " must be a number or a keyframed curve { keys = [[t0, v0], [t1, v1]] }, not " +
                         tomlTypeName(n));
            return std::nullopt;
        }
        if (!number(n, what, v, min, false)) return std::nullopt;
        return fields::Param(v);
    }
    std::vector<double> v;
    if (!numbers(n, what, static_cast<size_t>(width), v)) return std::nullopt;
    return fields::Param(std::move(v));
}

bool Loader::painted(const toml::node& n, const std::string& what, const std::string& baseDir, PaintedSpec& out) {
    out.line = static_cast<int>(n.source().begin.line);
    out.col = static_cast<int>(n.source().begin.column);
    const toml::table* t = n.as_table();
    if (!t || t->contains("keys")) {
        std::optional<fields::Param> p = param(n, what, 1, 0.0);
        if (!p) return false;
        out.value = *p;
        return true;
    }
    // { map = "prop" | expr = "file.se" | source = "...", scale = value }
    checkKeys(*t, {"map", "expr", "source", "scale"}, "the painted map of " + what);
    bool ok = true;
    int kinds = 0;
    if (const toml::node* m = t->get("map")) {
        ok = string(*m, what + ": map", out.map) && ok;
        ++kinds;
    }
    if (const toml::node* e = t->get("expr")) {
        std::string file;
        if (string(*e, what + ": expr", file))
            out.exprPath = (std::filesystem::path(baseDir) / file).lexically_normal().string();
        else
            ok = false;
        ++kinds;
    }
    if (const toml::node* s = t->get("source")) {
        ok = string(*s, what + ": source", out.source) && ok;
        ++kinds;
    }
    if (kinds != 1) {
        error(n, what + ": a painted map needs exactly one of map = \"vertex property\", "
                        "expr = \"file.se\" or source = \"expression\"");
        return false;
    }
    out.value = fields::Param(1.0);
    if (const toml::node* s = t->get("scale")) {
        std::optional<fields::Param> p = param(*s, what + ": scale", 1, 0.0);
        if (p)
            out.value = *p;
        else
            ok = false;
    }
    return ok;
}

bool Loader::pins(const toml::node& n, const std::string& what, PinSpec& out, bool attachKeys) {
    out.line = static_cast<int>(n.source().begin.line);
    out.col = static_cast<int>(n.source().begin.column);
    const toml::table* t = n.as_table();
    if (!t) {
        error(n, what + " must be a table: { vertices = [...] }, { map = \"pin\" } or "
                        "{ box = [x0, y0, z0, x1, y1, z1] }, not " + tomlTypeName(n));
        return false;
    }
    if (attachKeys)
        checkKeys(*t, {"mesh", "vertices", "map", "box", "stiffness"}, what);
    else
        checkKeys(*t, {"vertices", "map", "box", "translate", "rotate"}, what);
    bool ok = true;
    if (const toml::node* v = t->get("vertices")) {
        const toml::array* a = v->as_array();
        if (!a) {
            error(*v, what + ": vertices must be an array of vertex indices");
            ok = false;
        } else {
            for (const toml::node& e : *a) {
                long long idx = 0;
                if (integer(e, what + ": a vertex index", idx, 0))
                    out.vertices.push_back(static_cast<int>(idx));
                else
                    ok = false;
            }
        }
    }
    if (const toml::node* m = t->get("map")) ok = string(*m, what + ": map", out.map) && ok;
    if (const toml::node* b = t->get("box")) {
        std::vector<double> v;
        if (numbers(*b, what + ": box", 6, v)) {
            out.hasBox = true;
            for (int k = 0; k < 6; ++k) out.box[k] = v[k];
        } else {
            ok = false;
        }
    }
    if (!t->get("vertices") && !t->get("map") && !t->get("box")) {
        error(n, what + " needs vertices = [...], map = \"property\" or box = [x0, y0, z0, x1, y1, z1]");
        ok = false;
    }
    if (const toml::node* tr = t->get("translate")) {
        std::optional<fields::Param> p = param(*tr, what + ": translate", 3, -1e300);
        if (p)
            out.translate = *p;
        else
            ok = false;
    }
    // rotate = { pivot = [x, y, z], axis = [x, y, z], angle = degrees | { keys = [[t, deg], ...] } }
    if (const toml::node* r = t->get("rotate")) {
        const toml::table* rt = r->as_table();
        if (!rt) {
            error(*r, what + ": rotate must be a table { pivot = [x, y, z], axis = [x, y, z], angle = degrees or keys }, not " +
                          tomlTypeName(*r));
            return false;
        }
        checkKeys(*rt, {"pivot", "axis", "angle"}, what + " rotate");
        out.rotate.active = true;
        if (const toml::node* n = rt->get("pivot")) ok = vec3(*n, what + ": rotate pivot", out.rotate.pivot) && ok;
        if (const toml::node* n = rt->get("axis")) {
            if (vec3(*n, what + ": rotate axis", out.rotate.axis)) {
                if (!(out.rotate.axis.norm() > 0.0)) {
                    error(*n, what + ": rotate axis must not be zero");
                    ok = false;
                }
            } else {
                ok = false;
            }
        }
        if (const toml::node* n = rt->get("angle")) {
            std::optional<fields::Param> p = param(*n, what + ": rotate angle (degrees)", 1, -1e300);
            if (p)
                out.rotate.angle = *p;
            else
                ok = false;
        } else {
            error(*r, what + ": rotate needs angle = degrees or { keys = [[t0, deg0], [t1, deg1]] }");
            ok = false;
        }
    }
    return ok;
}

// attach = { mesh = "body.#.obj", vertices | map | box }: the selection keys of pins.
bool Loader::attach(const toml::node& n, const std::string& what, const std::string& baseDir, bool needSelection,
                    PinSpec& out, std::string& meshPath) {
    out.line = static_cast<int>(n.source().begin.line);
    out.col = static_cast<int>(n.source().begin.column);
    const toml::table* t = n.as_table();
    if (!t) {
        error(n, what + " must be a table { mesh = \"body.#.obj\", box = [x0, y0, z0, x1, y1, z1] }, not " +
                     tomlTypeName(n));
        return false;
    }
    bool ok = true;
    const toml::node* m = t->get("mesh");
    for (const toml::node* from : {m, &n}) // the mesh's --set, else the table's
        if (from && out.origin.empty()) out.origin = setOrigin(from->source());
    std::string file;
    if (!m) {
        error(n, what + " needs mesh = \"file\" (the body to attach to: OBJ/PLY, or a '#' sequence)");
        ok = false;
    } else if (string(*m, what + ": mesh", file)) {
        meshPath = std::filesystem::path(file).is_absolute()
                       ? file
                       : (std::filesystem::path(baseDir) / file).lexically_normal().string();
    } else {
        ok = false;
    }
    // stiffness (N/m per vertex): a soft attachment, a zero-length spring to the bound point.
    if (const toml::node* k = t->get("stiffness")) {
        // Above 10¹² N/m a spring differs from the hard attachment by nothing but rounding (and
        // h²k would leave the solver's single-precision range): leave the key out for that.
        const bool read =
            number(*k, what + ": stiffness (N/m per vertex; leave it out for a hard attachment)",
                   out.stiffness, 0.0, true);
        if (read && out.stiffness > kMaxAttachStiffness)
            error(*k, what + ": stiffness " + io::formatNumber(out.stiffness) +
                          " N/m is beyond 1e12: a spring that stiff is a hard attachment; leave "
                          "stiffness out for one");
        ok = read && out.stiffness <= kMaxAttachStiffness && ok;
    }
    if (!t->get("vertices") && !t->get("map") && !t->get("box")) {
        checkKeys(*t, {"mesh", "vertices", "map", "box", "stiffness"}, what);
        if (needSelection) {
            error(n, what + " needs vertices = [...], map = \"property\" or box = [x0, y0, z0, x1, y1, z1]");
            ok = false;
        }
        return ok;
    }
    const int line = out.line, col = out.col;
    ok = pins(n, what, out, true) && ok; // the selection keys, read as for pins
    out.line = line;
    out.col = col;
    return ok;
}

void Loader::stepOptions(const toml::table& t, const std::string& what, StepOptions& s, std::string& output) {
    if (const toml::node* n = t.get("linear_solver")) {
        std::string v;
        if (choice(*n, "linear_solver", {"pcg", "direct"}, v))
            s.linearSolver = v == "direct" ? LinearSolverKind::Direct : LinearSolverKind::Pcg;
    }
    if (const toml::node* n = t.get("preconditioner")) {
        std::string v;
        if (choice(*n, "preconditioner", {"multigrid", "jacobi"}, v))
            s.preconditioner = v == "jacobi" ? Preconditioner::BlockJacobi : Preconditioner::Multigrid;
    }
    if (const toml::node* n = t.get("multigrid"))
        named(*n, "multigrid",
              {MultigridKind::Automatic, MultigridKind::Plain, MultigridKind::Smoothed,
               MultigridKind::SmoothedRotations},
              multigridKindName, s.multigrid);
    if (const toml::node* n = t.get("cg_tolerance")) number(*n, what + ": cg_tolerance", s.cgTolerance, 0.0, true);
    if (const toml::node* n = t.get("cg_max_iterations")) {
        long long v = 0;
        if (integer(*n, what + ": cg_max_iterations", v, 1)) s.cgMaxIterations = static_cast<int>(std::min(v, 1000000LL));
    }
    if (const toml::node* n = t.get("newton_iterations")) {
        long long v = 0;
        if (integer(*n, what + ": newton_iterations", v, 0))
            s.newtonIterations = static_cast<int>(std::min(v, 50LL));
    }
    if (const toml::node* n = t.get("newton_tolerance"))
        number(*n, what + ": newton_tolerance", s.newtonTolerance, 0.0, true);
    if (const toml::node* n = t.get("output")) choice(*n, "output format", {"obj", "ply"}, output);
}

// ---- sections -------------------------------------------------------------------------------

void Loader::loadCloth(const toml::table& t, size_t index, const std::string& baseDir, ClothSpec& c) {
    c.line = static_cast<int>(t.source().begin.line);
    c.col = static_cast<int>(t.source().begin.column);
    c.name = "cloth" + std::to_string(index);
    if (const toml::node* n = t.get("name")) string(*n, "[[cloth]] name", c.name);
    const std::string what = "[[cloth]] '" + c.name + "'";
    checkKeys(t, kClothKeys, "[[cloth]]");
    const toml::node* mesh = t.get("mesh");
    const toml::node* grid = t.get("grid");
    if ((mesh != nullptr) == (grid != nullptr)) {
        error(t, what + " needs exactly one of mesh = \"file.obj|ply\" or grid = { size = [w, h], res = [nx, ny] }");
    } else if (mesh) {
        std::string file;
        if (string(*mesh, what + ": mesh", file))
            c.meshPath = (std::filesystem::path(baseDir) / file).lexically_normal().string();
        keyPlace(*mesh, c.meshLine, c.meshCol, c.meshOrigin);
    } else if (const toml::table* g = grid->as_table()) {
        checkKeys(*g, {"size", "res", "origin", "axes"}, what + " grid");
        std::vector<double> v;
        if (const toml::node* s = g->get("size"))
            if (numbers(*s, what + ": grid size", 2, v)) {
                if (!(v[0] > 0 && v[1] > 0))
                    error(*s, what + ": grid size must be positive");
                c.gridSize[0] = v[0];
                c.gridSize[1] = v[1];
            }
        if (const toml::node* r = g->get("res")) {
            const toml::array* a = r->as_array();
            if (!a || a->size() != 2) {
                error(*r, what + ": grid res must be [nx, ny] (vertices along each side)");
            } else {
                long long total = 1, widest = 0;
                for (int k = 0; k < 2; ++k) {
                    long long x = 0;
                    if (integer(*a->get(k), what + ": grid res", x, 2)) c.gridRes[k] = static_cast<int>(std::min(x, 4096LL));
                    total *= std::min(x, 1LL << 30);
                    widest = std::max(widest, x);
                }
                // Limits, not a silent clamp: a larger grid would take hours and tens of GB.
                if (widest > 4096)
                    error(*r, what + ": grid res must be at most 4096 vertices along each side");
                else if (total > kMaxGridVertices)
                    error(*r, what + ": grid res gives " + std::to_string(total) + " vertices, more than the limit of " +
                                  std::to_string(kMaxGridVertices) + " (1024 x 1024)");
            }
        }
        if (const toml::node* o = g->get("origin")) vec3(*o, what + ": grid origin", c.gridOrigin);
        if (const toml::node* a = g->get("axes")) choice(*a, "grid axes", {"xy", "xz", "zy", "yz", "zx", "yx"}, c.gridAxes);
    } else {
        error(*grid, what + ": grid must be a table { size = [w, h], res = [nx, ny] }, not " + tomlTypeName(*grid));
    }
    if (const toml::node* n = t.get("density")) number(*n, what + ": density (kg/m²)", c.material.density, 0.0, true);
    auto p = [&](const char* key, fields::Param& out, const std::string& unit) {
        if (const toml::node* n = t.get(key))
            if (auto v = param(*n, what + ": " + key + unit, 1, 0.0)) out = *v;
    };
    p("stretch", c.material.stretch, " (N/m)");
    p("shear", c.material.shear, " (N/m)");
    p("bend", c.material.bend, " (N·m)");
    p("damping", c.material.damping, " (s)");
    c.lift.value = fields::Param(0.3);
    c.drag.value = fields::Param(1.0);
    if (const toml::node* n = t.get("lift")) painted(*n, what + ": lift", baseDir, c.lift);
    if (const toml::node* n = t.get("drag")) painted(*n, what + ": drag", baseDir, c.drag);
    if (const toml::node* n = t.get("aero_model")) {
        std::string v;
        if (choice(*n, "aero_model", {"frozen", "smooth-lift"}, v))
            c.material.aeroModel = v == "frozen" ? AeroModel::Frozen : AeroModel::SmoothLift;
    }
    if (const toml::node* n = t.get("aero_jacobian"))
        named(*n, "aero_jacobian",
              {AeroJacobian::Bounded, AeroJacobian::Projected, AeroJacobian::Paper},
              aeroJacobianName, c.step.aeroJacobian);
    if (const toml::node* n = t.get("pins")) c.hasPins = pins(*n, what + " pins", c.pins);
    if (const toml::node* n = t.get("attach"))
        c.hasAttach = attach(*n, what + " attach", baseDir, true, c.attach, c.attachMesh);
    if (const toml::node* n = t.get("rest_shape")) choice(*n, "rest_shape", {"mesh", "flat"}, c.restShape);
    if (const toml::node* n = t.get("self_collision"))
        boolean(*n, what + ": self_collision", c.collision.self);
    if (const toml::node* n = t.get("thickness"))
        c.collision.thicknessForColliders =
            number(*n, what + ": thickness (m)", c.collision.thickness, 0.0, true);
    if (const toml::node* n = t.get("rest_mesh")) {
        std::string file;
        c.restLine = static_cast<int>(n->source().begin.line);
        c.restCol = static_cast<int>(n->source().begin.column);
        if (!mesh)
            error(*n, what + ": rest_mesh needs mesh = \"file\" (the rest shape of a loaded mesh; a grid is flat)");
        else if (string(*n, what + ": rest_mesh", file))
            c.restMeshPath = (std::filesystem::path(baseDir) / file).lexically_normal().string();
    }
    stepOptions(t, what, c.step, c.output);
}

void Loader::loadHair(const toml::table& t, size_t index, const std::string& baseDir, HairSpec& h) {
    h.line = static_cast<int>(t.source().begin.line);
    h.col = static_cast<int>(t.source().begin.column);
    h.name = "hair" + std::to_string(index);
    if (const toml::node* n = t.get("name")) string(*n, "[[hair]] name", h.name);
    const std::string what = "[[hair]] '" + h.name + "'";
    checkKeys(t, kHairKeys, "[[hair]]");
    const toml::node* strands = t.get("strands");
    const toml::node* grid = t.get("grid");
    if ((strands != nullptr) == (grid != nullptr)) {
        error(t, what + " needs exactly one of strands = \"file.ply\" or grid = { size = [w, d], count = [nu, nv], "
                        "length = L, segments = n }");
    } else if (strands) {
        std::string file;
        if (string(*strands, what + ": strands", file))
            h.strandsPath = (std::filesystem::path(baseDir) / file).lexically_normal().string();
        keyPlace(*strands, h.strandsLine, h.strandsCol, h.strandsOrigin);
    } else if (const toml::table* g = grid->as_table()) {
        checkKeys(*g, {"size", "count", "length", "segments", "origin", "direction"}, what + " grid");
        std::vector<double> v;
        if (const toml::node* s = g->get("size"))
            if (numbers(*s, what + ": grid size", 2, v)) {
                h.gridSize[0] = v[0];
                h.gridSize[1] = v[1];
            }
        if (const toml::node* r = g->get("count")) {
            const toml::array* a = r->as_array();
            if (!a || a->size() != 2) {
                error(*r, what + ": grid count must be [nu, nv] (strands along each side)");
            } else {
                for (int k = 0; k < 2; ++k) {
                    long long x = 0;
                    if (integer(*a->get(k), what + ": grid count", x, 1)) h.gridCount[k] = static_cast<int>(std::min(x, 4096LL));
                    if (x > 4096) {
                        error(*r, what + ": grid count must be at most 4096 strands along each side");
                        break;
                    }
                }
            }
        }
        if (const toml::node* n = g->get("length")) number(*n, what + ": grid length (m)", h.length, 0.0, true);
        if (const toml::node* n = g->get("segments")) {
            long long x = 0;
            if (integer(*n, what + ": grid segments", x, 1)) h.segments = static_cast<int>(std::min(x, 100000LL));
            if (x > 100000) error(*n, what + ": grid segments must be at most 100000");
        }
        // A limit, not a silent clamp: strands x (segments + 1) vertices.
        const long long vertices = static_cast<long long>(h.gridCount[0]) * h.gridCount[1] * (h.segments + 1LL);
        if (vertices > kMaxGridVertices)
            error(*grid, what + ": the strand grid would have " + std::to_string(vertices) +
                             " vertices, more than the limit of " + std::to_string(kMaxGridVertices) +
                             ": use fewer strands or segments");
        if (const toml::node* o = g->get("origin")) vec3(*o, what + ": grid origin", h.origin);
        if (const toml::node* d = g->get("direction"))
            if (vec3(*d, what + ": grid direction", h.direction) && h.direction.norm() == 0.0)
                error(*d, what + ": grid direction must not be zero");
    } else {
        error(*grid, what + ": grid must be a table, not " + tomlTypeName(*grid));
    }
    if (const toml::node* n = t.get("radius")) number(*n, what + ": radius (m)", h.material.radius, 0.0, true);
    if (const toml::node* n = t.get("density")) number(*n, what + ": density (kg/m³)", h.material.density, 0.0, true);
    auto p = [&](const char* key, fields::Param& out, const std::string& unit) {
        if (const toml::node* n = t.get(key))
            if (auto v = param(*n, what + ": " + key + unit, 1, 0.0)) out = *v;
    };
    p("stretch", h.material.stretch, " (EA, N)");
    p("bend", h.material.bend, " (EI, N·m²)");
    p("damping", h.material.damping, " (s)");
    h.dragNormal.value = fields::Param(1.2);
    h.dragTangent.value = fields::Param(0.05);
    if (const toml::node* n = t.get("drag_normal")) painted(*n, what + ": drag_normal", baseDir, h.dragNormal);
    if (const toml::node* n = t.get("drag_tangent")) painted(*n, what + ": drag_tangent", baseDir, h.dragTangent);
    if (const toml::node* n = t.get("root_pinned")) boolean(*n, what + ": root_pinned", h.material.rootPinned);
    // Bending rest shape: the strand's own polyline (a curl; the default for loaded strands) or
    // straight (the default for generated ones, which are straight anyway).
    h.material.curledRest = strands != nullptr;
    if (const toml::node* n = t.get("rest_shape")) {
        std::string v;
        if (choice(*n, "rest_shape", {"strand", "straight"}, v)) h.material.curledRest = v == "strand";
    }
    if (const toml::node* n = t.get("attach"))
        h.hasAttach = attach(*n, what + " attach", baseDir, false, h.attach, h.attachMesh);
    if (const toml::node* n = t.get("collide_cloth"))
        boolean(*n, what + ": collide_cloth", h.collideCloth);
    if (const toml::node* n = t.get("pins"))
        error(*n, what + ": strands are pinned at their roots (root_pinned = true); pins maps are for cloth");
    stepOptions(t, what, h.step, h.output);
}

void Loader::loadCollider(const toml::table& t, size_t index, const fields::SceneSettings& settings,
                          std::vector<double>& rest, Collider& c) {
    c.name = "collider" + std::to_string(index);
    c.line = static_cast<int>(t.source().begin.line);
    c.col = static_cast<int>(t.source().begin.column);
    if (const toml::node* n = t.get("name")) string(*n, "[[collider]] name", c.name);
    const std::string what = "[[collider]] '" + c.name + "'";
    checkKeys(t, kColliderKeys, "[[collider]]");
    std::string type;
    const toml::node* tn = t.get("type");
    if (!tn) {
        error(t, what + " needs type = \"plane\" | \"sphere\" | \"capsule\" | \"mesh\"");
        return;
    }
    if (!choice(*tn, "collider type", {"plane", "sphere", "capsule", "mesh"}, type)) return;
    c.shape = type == "plane"    ? ColliderShape::Plane
              : type == "sphere" ? ColliderShape::Sphere
              : type == "mesh"   ? ColliderShape::Mesh
                                 : ColliderShape::Capsule;
    const std::vector<std::string> need = type == "plane"    ? std::vector<std::string>{"point", "normal"}
                                          : type == "sphere" ? std::vector<std::string>{"center", "radius"}
                                          : type == "mesh"   ? std::vector<std::string>{"mesh"}
                                                             : std::vector<std::string>{"a", "b", "radius"};
    std::vector<std::string> allowed = {"name", "type", "thickness", "friction"};
    if (type == "mesh") allowed.insert(allowed.end(), {"voxel", "rest_mesh"});
    allowed.insert(allowed.end(), need.begin(), need.end());
    for (auto&& [key, node] : t) {
        const std::string k(key.str());
        if (std::find(allowed.begin(), allowed.end(), k) == allowed.end() &&
            std::find(kColliderKeys.begin(), kColliderKeys.end(), k) != kColliderKeys.end())
            error(key.source(), "'" + k + "' does not apply to a " + type + " collider (it takes " + joinNames(need) + ")");
    }
    for (const std::string& k : need)
        if (!t.get(k)) error(t, what + ": a " + type + " collider needs '" + k + "'");
    auto vecParam = [&](const char* key, fields::Param& out) {
        if (const toml::node* n = t.get(key))
            if (auto v = param(*n, what + ": " + key, 3, -1e300)) out = *v;
    };
    vecParam("point", c.a);
    vecParam("center", c.a);
    vecParam("a", c.a);
    vecParam("b", c.b);
    vecParam("normal", c.normal);
    if (const toml::node* n = t.get("radius")) number(*n, what + ": radius (m)", c.radius, 0.0, true);
    if (const toml::node* n = t.get("thickness")) number(*n, what + ": thickness (m)", c.thickness, 0.0, false);
    if (const toml::node* n = t.get("friction")) number(*n, what + ": friction", c.friction, 0.0, false);
    // A mesh: its SDF (solver/collider/mesh_collider.h), the file relative to the scene.
    const toml::node* mesh = t.get("mesh");
    std::string file;
    double voxel = 0.01;
    if (type != "mesh" || !mesh || !string(*mesh, what + ": mesh", file)) return;
    if (const toml::node* n = t.get("voxel"))
        if (!number(*n, what + ": voxel (m)", voxel, 0.0, true)) return;
    // A file named in the collider: relative to the scene's folder.
    const auto sceneFile = [&](const std::string& name) {
        const std::filesystem::path p(name);
        return p.is_absolute() ? name
                               : (std::filesystem::path(mPath).parent_path() / p).lexically_normal().string();
    };
    const std::string path = sceneFile(file);
    std::string problem;
    if (io::hasFrameToken(path)) {
        // A per-frame sequence ('#' run, %04d or $F4): triangles, a refitted tree and continuous contact
        // (solver/collider/moving_collider.h) instead of an SDF rebuilt every frame.
        if (const toml::node* n = t.get("voxel"))
            error(*n, what +
                          ": 'voxel' does not apply to a mesh sequence (its contact is against "
                          "the triangles themselves; voxel sizes a static mesh's SDF): remove it");
        std::shared_ptr<const MeshSequence> seq = MeshSequence::load(path, settings.fps, problem, settings.timeZero);
        if (!seq) {
            error(*mesh, what + ": " + problem).io = isFileProblem(problem);
            return;
        }
        if (const toml::node* r = t.get("rest_mesh")) {
            // The rest (bind) pose the pre-roll eases the body from (scene.preroll).
            std::string restFile;
            if (!string(*r, what + ": rest_mesh", restFile)) return;
            TriMesh m;
            if (!loadMesh(sceneFile(restFile), m, problem)) {
                error(*r, what + ": rest_mesh: " + problem).io = isFileProblem(problem);
                return;
            }
            if (m.vertexCount() != seq->vertexCount() || m.triangles != seq->triangles()) {
                error(*r,
                      what + ": rest_mesh '" + restFile + "' has " +
                          std::to_string(m.vertexCount()) + " vertices and " +
                          std::to_string(m.triangles.size()) + " triangles, the sequence " +
                          std::to_string(seq->vertexCount()) + " and " +
                          std::to_string(seq->triangles().size()) +
                          ": the rest pose needs the sequence's topology (the same mesh, unposed)");
                return;
            }
            rest = std::move(m.positions);
        }
        c.moving = std::make_shared<MovingMeshContact>(std::move(seq));
        return;
    }
    // A static mesh: one file. When it cannot be read, that is the error (a name with another
    // program's frame token, body.<F>.obj, is said with gale's tokens), not a rest_mesh beside it.
    c.mesh = MeshCollider::load(path, voxel, problem);
    if (!c.mesh) {
        std::error_code ec;
        const bool missing = !std::filesystem::exists(path, ec);
        if (missing)
            problem += io::foreignTokenHint(std::filesystem::path(file).filename().string());
        error(*mesh, what + ": " + problem).io = missing || isFileProblem(problem);
        return;
    }
    if (const toml::node* r = t.get("rest_mesh"))
        error(*r, what +
                      ": rest_mesh is the rest pose of a mesh sequence ('#', %04d or $F4 in mesh); "
                      "a static mesh does not move");
}

void Loader::loadSolver(const toml::table& t, SolverSection& s) {
    checkKeys(t, kSolverKeys, "[solver]");
    if (const toml::node* n = t.get("max_halvings")) {
        long long v = 0;
        if (integer(*n, "[solver] max_halvings", v, 0)) s.maxHalvings = static_cast<int>(std::min(v, 20LL));
    }
    if (const toml::node* n = t.get("over_stretch")) number(*n, "[solver] over_stretch", s.overStretch, 1.0, true);
    if (const toml::node* n = t.get("velocity_jump")) number(*n, "[solver] velocity_jump (m/s)", s.velocityJump, 0.0, true);
    if (const toml::node* n = t.get("retry_newton")) {
        long long v = 0;
        if (integer(*n, "[solver] retry_newton", v, 0))
            s.retryNewton = static_cast<int>(std::min(v, 100LL));
    }
    if (const toml::node* n = t.get("retry_cg_tolerance")) {
        if (number(*n, "[solver] retry_cg_tolerance", s.retryCgTolerance, 0.0, false) &&
            s.retryCgTolerance >= 1.0)
            error(*n, "[solver] retry_cg_tolerance must be below 1 (a relative residual)");
    }
    if (const toml::node* n = t.get("retry_keep_coarse"))
        boolean(*n, "[solver] retry_keep_coarse", s.retryKeepCoarse);
    if (const toml::node* n = t.get("retry_repeat"))
        boolean(*n, "[solver] retry_repeat", s.retryRepeat);
    if (const toml::node* n = t.get("grow_back")) boolean(*n, "[solver] grow_back", s.growBack);
    if (const toml::node* n = t.get("retry_strain_limit"))
        boolean(*n, "[solver] retry_strain_limit", s.strainLimit);
    if (const toml::node* n = t.get("stretch_limit")) {
        // × rest length; 0 turns the limit off, else at least 1.
        if (number(*n, "[solver] stretch_limit", s.stretchLimit, 0.0, false) &&
            s.stretchLimit != 0.0 && s.stretchLimit < 1.0)
            error(*n, "[solver] stretch_limit must be 0 (no limit) or at least 1 (× rest length)");
    }
    if (const toml::node* n = t.get("rotation_projection")) {
        // "off", "contact" (the default) or "always"; false and true stand for off and always.
        using solver::RotationProjection;
        if (n->is_boolean())
            s.rotationProjection = n->value<bool>().value_or(false) ? RotationProjection::Always
                                                                    : RotationProjection::Off;
        else if (!n->is_string())
            error(*n, std::string("[solver] rotation_projection must be \"off\", \"contact\" or "
                                  "\"always\" (or false, true), not ") +
                          tomlTypeName(*n));
        else
            named(
                *n, "[solver] rotation_projection",
                {RotationProjection::Off, RotationProjection::Contact, RotationProjection::Always},
                rotationProjectionName, s.rotationProjection);
    }
}

void Loader::load(const toml::table& root, const std::string& baseDir, SimScene& out) {
    std::set<std::string> names;
    auto unique = [&](const std::string& name, const toml::node& at, const char* kind) {
        if (!names.insert(name).second)
            error(at, "two objects are named '" + name + "' (" + kind + "): object names must be unique, "
                                                                    "they name the output files");
    };
    auto list = [&](const char* key, auto&& each) {
        const toml::node* n = root.get(key);
        if (!n) return;
        const toml::array* a = n->as_array();
        if (!a || !a->is_array_of_tables()) {
            error(*n, std::string("'") + key + "' must be an array of tables: write [[" + key + "]] sections");
            return;
        }
        for (size_t i = 0; i < a->size(); ++i) each(*a->get(i)->as_table(), i);
    };
    list("cloth", [&](const toml::table& t, size_t i) {
        ClothSpec c;
        loadCloth(t, i, baseDir, c);
        unique(c.name, t, "cloth");
        out.cloths.push_back(std::move(c));
    });
    list("hair", [&](const toml::table& t, size_t i) {
        HairSpec h;
        loadHair(t, i, baseDir, h);
        unique(h.name, t, "hair");
        out.hairs.push_back(std::move(h));
    });
    list("collider", [&](const toml::table& t, size_t i) {
        Collider c;
        std::vector<double> rest;
        loadCollider(t, i, out.wind.settings, rest, c);
        out.colliders.push_back(std::move(c));
        out.colliderRest.push_back(std::move(rest));
    });
    if (const toml::node* n = root.get("solver")) {
        if (const toml::table* t = n->as_table())
            loadSolver(*t, out.solver);
        else
            error(*n, "'solver' must be a table: write a [solver] section");
    }
}

} // namespace

void loadBodySections(const std::string& path, const std::string& text, toml::table& root,
                      SimScene& out, std::vector<SceneError>& errors,
                      const std::vector<std::string>& sets) {
    Loader loader(path, text, errors);
    loader.applySets(root, sets);
    const std::string baseDir = std::filesystem::path(path).parent_path().string();
    loader.load(root, baseDir.empty() ? std::string(".") : baseDir, out);
}

} // namespace gale::scene
