// From a loaded scene to bodies: meshes and strands read or generated, painted maps evaluated
// once at the rest shape (PLY properties or expressions over $P, $u, $v, $id), pins resolved;
// and the output geometry (OBJ text, PLY point sets) of a body's current shape.
#include "scene/sim_scene.h"

#include "solver/collider/moving_collider.h"
#include "solver/mesh/mesh_sequence.h"

#include "fields/expression_field.h"
#include "io/frame_pattern.h"
#include "lang/diagnostics.h"
#include "runtime/program.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>

namespace gale::scene {

namespace {
// An error at a key: the --set that gave it (`origin`), else its line and column in `file`.
SceneError keyError(const std::string& file, const std::string& origin, int line, int col,
                    std::string message) {
    if (origin.empty()) return sceneErrorAt(file, line, col, std::move(message));
    SceneError e;
    e.file = origin;
    e.message = std::move(message);
    return e;
}
} // namespace

SceneError specError(const std::string& file, const PinSpec& spec, std::string message,
                     bool warning) {
    SceneError e = keyError(file, spec.origin, spec.line, spec.col, std::move(message));
    e.warning = warning;
    return e;
}

using namespace gale::solver;

namespace {

SceneError sceneError(const SimScene& scene, int line, int col, std::string message) {
    return sceneErrorAt(scene.wind.path, line, col, std::move(message));
}

Vec3 axisOf(char c) {
    return c == 'x' ? Vec3::UnitX() : c == 'y' ? Vec3::UnitY() : Vec3::UnitZ();
}

// Evaluates a painted map: a vertex property, or an expression (file or inline) at the rest
// positions with $u, $v per vertex. Empty `values` when the spec has no map.
bool evaluateMap(const SimScene& scene, const PaintedSpec& spec, const std::string& what,
                 const std::vector<double>& positions, const std::vector<double>& u,
                 const std::vector<double>& v,
                 const std::map<std::string, std::vector<double>>& attributes,
                 std::vector<double>& values, std::vector<SceneError>& errors,
                 const std::vector<std::string>& allowPaths) {
    values.clear();
    const size_t n = positions.size() / 3;
    if (!spec.map.empty()) {
        auto it = attributes.find(spec.map);
        if (it == attributes.end()) {
            SceneError e =
                sceneError(scene, spec.line, spec.col,
                           what + ": the geometry has no vertex property '" + spec.map + "'");
            std::string names;
            for (const auto& a : attributes) names += (names.empty() ? "" : ", ") + a.first;
            e.notes.push_back(names.empty()
                                  ? "it has no extra vertex properties (a generated grid has none: "
                                    "paint with expr = \"file.se\" or source = \"...\")"
                                  : "its vertex properties: " + names);
            errors.push_back(std::move(e));
            return false;
        }
        values = it->second;
        return true;
    }
    if (spec.exprPath.empty() && spec.source.empty()) return true;
    lang::SourceFile source;
    if (!spec.exprPath.empty()) {
        // A folder (an empty `expr`, resolved to the scene's folder) opens but cannot be read:
        // libstdc++ then throws from the stream, so only regular files are read.
        std::error_code ec;
        std::ifstream in;
        if (std::filesystem::is_regular_file(spec.exprPath, ec))
            in.open(spec.exprPath, std::ios::binary);
        std::string text;
        bool ok = static_cast<bool>(in);
        if (ok) {
            std::ostringstream buf;
            buf << in.rdbuf();
            ok = !in.bad();
            text = buf.str();
        }
        if (!ok) {
            SceneError e = sceneError(scene, spec.line, spec.col,
                                              what + ": cannot read '" + spec.exprPath +
                                                  "' (give the path of an expression file)");
            e.io = true;
            errors.push_back(std::move(e));
            return false;
        }
        source = lang::SourceFile(spec.exprPath, std::move(text));
    } else {
        source = lang::SourceFile(scene.wind.path + " (" + what + ")", spec.source);
    }
    runtime::CompileSettings settings;
    settings.variables = runtime::standardVariables();
    settings.variables.push_back({"u", lang::Type::fp(1, lang::Lifetime::Varying)});
    settings.variables.push_back({"v", lang::Type::fp(1, lang::Lifetime::Varying)});
    settings.wantWidth = 1;
    // File names (sdf("body.obj", ...)) resolve against the map's file (the scene for inline
    // text) and stay inside the scene's folder, as in the wind's expressions.
    geometry::FileAccess files = geometry::fileAccessFor(
        spec.exprPath.empty() ? scene.wind.path : spec.exprPath, allowPaths);
    files.rootDir = scene.wind.baseDir.empty() ? "." : scene.wind.baseDir;
    settings.functions = fields::fieldFunctions(files);
    lang::DiagnosticSink sink;
    std::shared_ptr<const runtime::Program> program =
        runtime::Program::compile(source, settings, sink);
    if (!program) {
        SceneError e =
            sceneError(scene, spec.line, spec.col, what + ": the map expression has errors");
        std::string rendered = lang::renderDiagnostics(source, sink);
        while (!rendered.empty() && rendered.back() == '\n') rendered.pop_back();
        e.notes.push_back(rendered);
        errors.push_back(std::move(e));
        return false;
    }
    runtime::EvalRequest req;
    req.count = n;
    req.uniforms = {{"t", {0.0}, ""},
                    {"frame", {scene.wind.settings.timeZero}, ""},
                    {"fps", {scene.wind.settings.fps}, ""}};
    req.varyings = {
        {"P", 3, positions.data(), 3, 1}, {"u", 1, u.data(), 1, 1}, {"v", 1, v.data(), 1, 1}};
    values.assign(n, 0.0);
    runtime::EvalOutput<double> out;
    out.data = values.data();
    out.pointStride = 1;
    const runtime::EvalResult r = runtime::evaluate<double>(*program, req, out);
    if (!r.ok) {
        errors.push_back(sceneError(scene, spec.line, spec.col,
                                    what + ": the map expression could not run: " + r.error));
        return false;
    }
    size_t bad = 0;
    for (double& x : values)
        if (!std::isfinite(x) || x < 0.0) {
            x = std::isfinite(x) ? 0.0 : 0.0;
            ++bad;
        }
    if (bad) {
        errors.push_back(sceneError(scene, spec.line, spec.col,
                                    what + ": the map is negative or not finite at " +
                                        std::to_string(bad) +
                                        " vertices (coefficients must be ≥ 0)"));
        return false;
    }
    return true;
}

// The vertices a pins or attach table selects: indices, a painted map (> 0.5), a box (union).
bool selectVertices(const SimScene& scene, const PinSpec& spec, const std::string& what,
                    const std::vector<double>& positions,
                    const std::map<std::string, std::vector<double>>& attributes,
                    std::vector<int>& out, std::vector<SceneError>& errors) {
    bool ok = true;
    const size_t n = positions.size() / 3;
    for (int idx : spec.vertices) {
        if (idx < 0 || static_cast<size_t>(idx) >= n) {
            errors.push_back(sceneError(scene, spec.line, spec.col,
                                        what + ": vertex " + std::to_string(idx) +
                                            " is out of range (the mesh has " + std::to_string(n) +
                                            " vertices)"));
            ok = false;
            continue;
        }
        out.push_back(idx);
    }
    if (!spec.map.empty()) {
        auto it = attributes.find(spec.map);
        if (it == attributes.end()) {
            errors.push_back(
                sceneError(scene, spec.line, spec.col,
                           what + ": the mesh has no vertex property '" + spec.map + "'"));
            ok = false;
        } else {
            for (size_t i = 0; i < n; ++i)
                if (it->second[i] > 0.5) out.push_back(static_cast<int>(i));
        }
    }
    if (spec.hasBox) {
        const double* b = spec.box;
        for (size_t i = 0; i < n; ++i) {
            const Vec3 p = vec3At(positions.data(), i);
            if (p.x() >= std::min(b[0], b[3]) && p.x() <= std::max(b[0], b[3]) &&
                p.y() >= std::min(b[1], b[4]) && p.y() <= std::max(b[1], b[4]) &&
                p.z() >= std::min(b[2], b[5]) && p.z() <= std::max(b[2], b[5]))
                out.push_back(static_cast<int>(i));
        }
    }
    return ok;
}

// Sequences named by several keys (a collider and an attachment) are read once per build.
std::shared_ptr<const MeshSequence> loadSequence(const std::string& path,
                                                 const fields::SceneSettings& settings,
                                                 std::string& error) {
    static std::map<std::tuple<std::string, double, double>, std::weak_ptr<const MeshSequence>> cache;
    static std::mutex lock;
    std::lock_guard<std::mutex> g(lock);
    auto& slot = cache[{path, settings.fps, settings.timeZero}];
    if (auto s = slot.lock()) return s;
    std::shared_ptr<const MeshSequence> s =
        MeshSequence::load(path, settings.fps, error, settings.timeZero);
    slot = s;
    return s;
}

// One key for the spellings of one sequence (`body.#.obj`, `body.%04d.obj`, `body.$F4.obj`,
// and `body.$F.obj` or `%d` for frames of four digits; its folder relative or absolute, through
// links or not): the folder's canonical path and the name around the frame token. (Two
// sequences that differ only in their padding, body.7.obj and body.0007.obj, would share one:
// not a layout anyone writes.)
std::string sequenceKey(const std::string& path) {
    std::filesystem::path p = std::filesystem::path(path).lexically_normal();
    std::error_code ec;
    const std::filesystem::path dir = std::filesystem::weakly_canonical(p.parent_path(), ec);
    if (!ec && !dir.empty()) p = dir / p.filename();
    io::FramePattern fp;
    if (!io::parseFramePattern(p.filename().string(), fp)) return p.string();
    return (p.parent_path() / (fp.prefix + "<frame>" + fp.suffix)).string();
}

// An attachment's sequence: the collider's eased one of the same files, else loaded (and eased
// from its first file under a pre-roll).
std::shared_ptr<const MeshSequence> attachSequence(const SimScene& scene, const std::string& path,
                                                   std::string& error) {
    auto found = scene.eased.find(sequenceKey(path));
    if (found != scene.eased.end()) return found->second;
    std::shared_ptr<const MeshSequence> seq = loadSequence(path, scene.wind.settings, error);
    const fields::SceneSettings& s = scene.wind.settings;
    if (!seq || scene.prerollTo == INT_MIN || s.preroll <= 0) return seq;
    return seq->eased(seq->firstPositions(), s.frameTime(scene.prerollTo - s.preroll),
                      s.frameTime(scene.prerollTo), error);
}

} // namespace

bool prerollSequences(SimScene& scene, int toFrame, std::vector<SceneError>& errors) {
    const fields::SceneSettings& s = scene.wind.settings;
    if (s.preroll <= 0) return true;
    scene.prerollTo = toFrame;
    bool ok = true;
    for (size_t i = 0; i < scene.colliders.size(); ++i) {
        solver::Collider& c = scene.colliders[i];
        if (!c.moving) continue;
        const MeshSequence& seq = c.moving->mesh();
        const std::vector<double>& rest =
            i < scene.colliderRest.size() && !scene.colliderRest[i].empty() ? scene.colliderRest[i]
                                                                            : seq.firstPositions();
        std::string problem;
        std::shared_ptr<const MeshSequence> eased =
            seq.eased(rest, s.frameTime(toFrame - s.preroll), s.frameTime(toFrame), problem);
        if (!eased) {
            errors.push_back(sceneError(scene, c.line, c.col,
                                        "[[collider]] '" + c.name + "': pre-roll: " + problem));
            ok = false;
            continue;
        }
        scene.eased.emplace(sequenceKey(seq.path()), eased);
        c.moving = std::make_shared<solver::MovingMeshContact>(std::move(eased));
    }
    return ok;
}

bool buildShotBodies(SimScene& scene, int shotStart, std::vector<std::unique_ptr<Body>>& bodies,
                     std::vector<SceneError>& errors, std::vector<std::string>& warnings,
                     const std::vector<std::string>& allowPaths) {
    return prerollSequences(scene, shotStart, errors) &&
           buildBodies(scene, bodies, errors, warnings, allowPaths,
                       shotStart - scene.wind.settings.preroll);
}

WorldSettings worldSettings(const SimScene& scene, int threads) {
    WorldSettings ws;
    const fields::SceneSettings& s = scene.wind.settings;
    ws.fps = s.fps;
    ws.timeZero = s.timeZero;
    ws.substeps = s.substeps;
    ws.maxHalvings = scene.solver.maxHalvings;
    ws.retryNewtonIterations = scene.solver.retryNewton;
    ws.retryCgTolerance = scene.solver.retryCgTolerance;
    ws.retryKeepCoarse = scene.solver.retryKeepCoarse;
    ws.retryRepeat = scene.solver.retryRepeat;
    ws.growBack = scene.solver.growBack;
    ws.strainLimitRetry = scene.solver.strainLimit;
    if (s.gravity.size() >= 3) ws.gravity = Vec3(s.gravity[0], s.gravity[1], s.gravity[2]);
    ws.airDensity = s.airDensity;
    ws.threads = threads;
    return ws;
}

// C_L > C_D (at the start or at any key of either): the aerodynamic force then pushes the cloth
// across the flow against the air (the symmetric part of its Jacobian has the negative
// eigenvalue ½ρA (C_D − C_L)(v·n), docs/solver.md), a drift the model itself amplifies. A
// warning at the lift key's file:line:col; painted maps scale both and are not looked at.
std::string liftAboveDragWarning(const SimScene& scene, const ClothSpec& spec,
                                 const std::string& what) {
    std::vector<double> times = {0.0};
    for (const fields::Param* p : {&spec.lift.value, &spec.drag.value})
        if (p->isKeyed()) times.insert(times.end(), p->times().begin(), p->times().end());
    for (double t : times) {
        const double cl = spec.lift.value.scalarAt(t), cd = spec.drag.value.scalarAt(t);
        if (!(cl > cd)) continue;
        const int line = spec.lift.line > 0 ? spec.lift.line : spec.line;
        const int col = spec.lift.line > 0 ? spec.lift.col : spec.col;
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      "%s:%d:%d: %s: lift C_L = %.3g exceeds drag C_D = %.3g (at t = %.3g s)",
                      scene.wind.path.c_str(), line, col, what.c_str(), cl, cd, t);
        return std::string(buf) +
               ": the lift then pushes the cloth sideways against the air, an unstable drift the "
               "solver keeps bounded but does not damp (docs/solver.md); keep lift at or below "
               "drag "
               "for calm cloth";
    }
    return {};
}

bool buildBodies(const SimScene& scene, std::vector<std::unique_ptr<Body>>& bodies,
                 std::vector<SceneError>& errors, std::vector<std::string>& warnings,
                 const std::vector<std::string>& allowPaths, int firstFrame) {
    const double bindTime = scene.wind.settings.frameTime(
        firstFrame == INT_MIN ? scene.wind.settings.frameStart : firstFrame);
    const size_t before = errors.size();
    for (const ClothSpec& spec : scene.cloths) {
        const std::string what = "[[cloth]] '" + spec.name + "'";
        TriMesh mesh;
        std::vector<double> u, v;
        if (spec.meshPath.empty()) {
            const Vec3 au = axisOf(spec.gridAxes[0]), av = axisOf(spec.gridAxes[1]);
            mesh = makeGrid(spec.gridSize[0], spec.gridSize[1], spec.gridRes[0], spec.gridRes[1],
                            spec.gridOrigin, au, av);
            for (size_t i = 0; i < mesh.vertexCount(); ++i) {
                u.push_back(mesh.uv[2 * i] / spec.gridSize[0]);
                v.push_back(mesh.uv[2 * i + 1] / spec.gridSize[1]);
            }
        } else {
            std::string error;
            int dropped = 0;
            if (!loadMesh(spec.meshPath, mesh, error, &dropped)) {
                SceneError e = keyError(scene.wind.path, spec.meshOrigin, spec.meshLine,
                                        spec.meshCol, what + ": " + error);
                e.io = isFileProblem(error);
                errors.push_back(std::move(e));
                continue;
            }
            if (dropped)
                warnings.push_back(what + ": " + std::to_string(dropped) +
                                   " face(s) with bad indices were dropped");
            const bool hasUv = mesh.uv.size() == 2 * mesh.vertexCount();
            for (size_t i = 0; i < mesh.vertexCount(); ++i) {
                u.push_back(hasUv ? mesh.uv[2 * i] : 0.0);
                v.push_back(hasUv ? mesh.uv[2 * i + 1] : 0.0);
            }
        }
        // rest_mesh: rest lengths, areas and angles from it; the simulation starts from `mesh`.
        TriMesh restMesh;
        const bool hasRest = !spec.restMeshPath.empty();
        if (hasRest) {
            std::string error;
            const std::string where = what + " rest_mesh '" + spec.restMeshPath + "'";
            if (!loadMesh(spec.restMeshPath, restMesh, error)) {
                SceneError e =
                    sceneError(scene, spec.restLine, spec.restCol, where + ": " + error);
                e.io = isFileProblem(error);
                errors.push_back(std::move(e));
                continue;
            }
            if (restMesh.vertexCount() != mesh.vertexCount() ||
                restMesh.triangles != mesh.triangles) {
                errors.push_back(
                    sceneError(scene, spec.restLine, spec.restCol,
                               where + " does not have the topology of '" + spec.meshPath + "' (" +
                                   std::to_string(restMesh.vertexCount()) + " vertices and " +
                                   std::to_string(restMesh.triangles.size()) +
                                   " triangles against " + std::to_string(mesh.vertexCount()) +
                                   " and " + std::to_string(mesh.triangles.size()) +
                                   ", or the faces differ): a rest mesh must be the same mesh in "
                                   "another pose"));
                continue;
            }
            TriMesh r = mesh; // uv, attributes and faces of the simulated mesh, rest positions
            r.positions = restMesh.positions;
            restMesh = std::move(r);
        }
        const TriMesh& rest = hasRest ? restMesh : mesh;
        ClothMaterial mat = spec.material;
        mat.curvedRest = spec.restShape.empty() ? !spec.meshPath.empty() : spec.restShape == "mesh";
        mat.lift.value = spec.lift.value;
        mat.drag.value = spec.drag.value;
        bool ok = evaluateMap(scene, spec.lift, what + " lift", rest.positions, u, v,
                              mesh.attributes, mat.lift.map, errors, allowPaths);
        ok = evaluateMap(scene, spec.drag, what + " drag", rest.positions, u, v, mesh.attributes,
                         mat.drag.map, errors, allowPaths) &&
             ok;
        if (!ok) continue;
        VecX start;
        if (hasRest)
            start = Eigen::Map<const VecX>(mesh.positions.data(),
                                           static_cast<long>(mesh.positions.size()));
        auto cloth = std::make_unique<Cloth>(spec.name, rest, mat, hasRest ? &start : nullptr);
        cloth->options() = spec.step;
        cloth->collision() = spec.collision;
        cloth->limits().overStretch = scene.solver.overStretch;
        cloth->options().rotationProjection = scene.solver.rotationProjection;
        cloth->options().stretchLimit = scene.solver.stretchLimit;
        // Self-colliding cloth with no stretch_limit of its own: its solve's edges held 0.1 below
        // over_stretch, so that the self-collision pass after it, which may add a few per cent,
        // does not tip a frame over the limit (a 64² cape in 25 m/s gusts: 9 frames in trouble,
        // up to 1.58×; halving those passes instead cost 3.5× the run; docs/solver.md).
        if (spec.collision.self && scene.solver.stretchLimit == 0.0 &&
            scene.solver.overStretch - 0.1 >= 1.05)
            cloth->options().stretchLimit = scene.solver.overStretch - 0.1;
        cloth->limits().velocityJump = scene.solver.velocityJump;
        if (cloth->degenerateTriangles())
            warnings.push_back(what + ": " + std::to_string(cloth->degenerateTriangles()) +
                               " degenerate triangle(s) take no stretch force");
        if (std::string w = liftAboveDragWarning(scene, spec, what); !w.empty())
            warnings.push_back(w);
        if (spec.hasPins) {
            PinSet pins;
            pins.translate = spec.pins.translate;
            pins.rotate = spec.pins.rotate;
            ok = selectVertices(scene, spec.pins, what + " pins", mesh.positions, mesh.attributes,
                                pins.vertices, errors) &&
                 ok;
            cloth->addPins(pins);
        }
        if (spec.hasAttach) {
            PinSet att;
            std::string problem;
            att.attach = attachSequence(scene, spec.attachMesh, problem);
            att.bindTime = bindTime;
            att.stiffness = spec.attach.stiffness;
            if (!att.attach) {
                errors.push_back(
                    specError(scene.wind.path, spec.attach, what + " attach: " + problem));
                errors.back().io = isFileProblem(problem);
                ok = false;
            }
            ok = selectVertices(scene, spec.attach, what + " attach", mesh.positions,
                                mesh.attributes, att.vertices, errors) &&
                 ok;
            if (ok) cloth->addPins(att);
        }
        if (ok) bodies.push_back(std::move(cloth));
    }
    for (const HairSpec& spec : scene.hairs) {
        const std::string what = "[[hair]] '" + spec.name + "'";
        Strands strands;
        if (spec.strandsPath.empty()) {
            const Vec3 d = spec.direction.normalized();
            Vec3 a = d.cross(Vec3::UnitZ());
            if (a.norm() < 1e-6) a = d.cross(Vec3::UnitX());
            a.normalize();
            const Vec3 b = d.cross(a).normalized();
            strands =
                makeStrandGrid(spec.origin, spec.gridSize[0], spec.gridSize[1], spec.gridCount[0],
                               spec.gridCount[1], spec.length, spec.segments, a, b, d);
        } else {
            std::string error;
            if (!loadStrands(spec.strandsPath, strands, error)) {
                errors.push_back(keyError(scene.wind.path, spec.strandsOrigin, spec.strandsLine,
                                          spec.strandsCol, what + ": " + error));
                errors.back().io = isFileProblem(error);
                continue;
            }
        }
        // $u: arc-length fraction from the root; $v: strand index / (strands − 1).
        const size_t n = strands.vertexCount();
        std::vector<double> u(n, 0.0), v(n, 0.0);
        for (size_t s = 0; s < strands.strandCount(); ++s) {
            const int b = strands.offsets[s], e = strands.offsets[s + 1];
            double total = 0.0;
            std::vector<double> acc(e - b, 0.0);
            for (int i = b + 1; i < e; ++i) {
                total +=
                    (vec3At(strands.positions.data(), i) - vec3At(strands.positions.data(), i - 1))
                        .norm();
                acc[i - b] = total;
            }
            for (int i = b; i < e; ++i) {
                u[i] = total > 0 ? acc[i - b] / total : 0.0;
                v[i] = strands.strandCount() > 1
                           ? static_cast<double>(s) / (strands.strandCount() - 1)
                           : 0.0;
            }
        }
        HairMaterial mat = spec.material;
        mat.dragNormal.value = spec.dragNormal.value;
        mat.dragTangent.value = spec.dragTangent.value;
        bool ok = evaluateMap(scene, spec.dragNormal, what + " drag_normal", strands.positions, u,
                              v, strands.attributes, mat.dragNormal.map, errors, allowPaths);
        ok = evaluateMap(scene, spec.dragTangent, what + " drag_tangent", strands.positions, u, v,
                         strands.attributes, mat.dragTangent.map, errors, allowPaths) &&
             ok;
        if (!ok) continue;
        // attach: the selected roots (all without a selection) bound to the surface; the other
        // roots stay pinned where they are when root_pinned.
        PinSet att;
        std::vector<int> otherRoots;
        if (spec.hasAttach) {
            std::string problem;
            att.attach = attachSequence(scene, spec.attachMesh, problem);
            att.bindTime = bindTime;
            att.stiffness = spec.attach.stiffness;
            if (!att.attach) {
                errors.push_back(
                    specError(scene.wind.path, spec.attach, what + " attach: " + problem));
                errors.back().io = isFileProblem(problem);
                continue;
            }
            std::vector<int> chosen;
            const bool all =
                spec.attach.vertices.empty() && spec.attach.map.empty() && !spec.attach.hasBox;
            if (!all && !selectVertices(scene, spec.attach, what + " attach", strands.positions,
                                        strands.attributes, chosen, errors))
                continue;
            std::vector<uint8_t> isChosen(n, all ? 1 : 0);
            for (int c : chosen) isChosen[c] = 1;
            for (size_t s = 0; s < strands.strandCount(); ++s)
                (isChosen[strands.offsets[s]] ? att.vertices : otherRoots)
                    .push_back(strands.offsets[s]);
            if (!mat.rootPinned) otherRoots.clear();
            mat.rootPinned = false;
        }
        auto hair = std::make_unique<Hair>(spec.name, strands, mat);
        if (spec.hasAttach) {
            hair->addPins(att);
            PinSet rest;
            rest.vertices = otherRoots;
            if (!rest.vertices.empty()) hair->addPins(rest);
        }
        hair->options() = spec.step;
        hair->collision().self = spec.collideCloth;
        hair->limits().overStretch = scene.solver.overStretch;
        hair->options().rotationProjection = scene.solver.rotationProjection;
        hair->options().stretchLimit = scene.solver.stretchLimit;
        hair->limits().velocityJump = scene.solver.velocityJump;
        bodies.push_back(std::move(hair));
    }
    return errors.size() == before;
}

// std::to_chars with a precision prints as printf's %.9g does (C++17 [charconv.to.chars]),
// the same bytes at about a tenth of snprintf's cost (it was 13% of a light cloth's run).
std::string bodyObjText(const Body& body) {
    std::string out;
    out.reserve(body.vertexCount() * 40);
    out += "# gale " + std::string(body.kind()) + " '" + body.name() + "'\n";
    char buf[128];
    auto put = [&](char* p, double v) {
        return std::to_chars(p, buf + sizeof buf, v, std::chars_format::general, 9).ptr;
    };
    auto putInt = [&](char* p, long v) { return std::to_chars(p, buf + sizeof buf, v).ptr; };
    const VecX& x = body.positions();
    for (size_t i = 0; i < body.vertexCount(); ++i) {
        char* p = buf;
        *p++ = 'v';
        for (int k = 0; k < 3; ++k) {
            *p++ = ' ';
            p = put(p, x[3 * i + k]);
        }
        *p++ = '\n';
        out.append(buf, p);
    }
    if (const Cloth* c = dynamic_cast<const Cloth*>(&body)) {
        for (const auto& t : c->mesh().triangles) {
            char* p = buf;
            *p++ = 'f';
            for (int k = 0; k < 3; ++k) {
                *p++ = ' ';
                p = putInt(p, t[k] + 1L);
            }
            *p++ = '\n';
            out.append(buf, p);
        }
    } else if (const Hair* h = dynamic_cast<const Hair*>(&body)) {
        const Strands& s = h->strands();
        for (size_t k = 0; k < s.strandCount(); ++k) {
            out += "l";
            for (int i = s.offsets[k]; i < s.offsets[k + 1]; ++i)
                out += " " + std::to_string(i + 1);
            out += "\n";
        }
    }
    return out;
}

io::PointSet bodyPointSet(const Body& body) {
    io::PointSet ps;
    const VecX& x = body.positions();
    const VecX& v = body.velocities();
    const char* names[6] = {"x", "y", "z", "vx", "vy", "vz"};
    for (int c = 0; c < 6; ++c) {
        std::vector<double> col(body.vertexCount());
        const VecX& src = c < 3 ? x : v;
        for (size_t i = 0; i < body.vertexCount(); ++i) col[i] = src[3 * i + c % 3];
        ps.names.push_back(names[c]);
        ps.columns.push_back(std::move(col));
    }
    if (const Cloth* c = dynamic_cast<const Cloth*>(&body)) {
        for (const auto& t : c->mesh().triangles) ps.faces.push_back({t[0], t[1], t[2]});
    } else if (const Hair* h = dynamic_cast<const Hair*>(&body)) {
        std::vector<double> strand(body.vertexCount(), 0.0);
        const Strands& s = h->strands();
        for (size_t k = 0; k < s.strandCount(); ++k)
            for (int i = s.offsets[k]; i < s.offsets[k + 1]; ++i)
                strand[i] = static_cast<double>(k);
        ps.names.push_back("strand");
        ps.columns.push_back(std::move(strand));
    }
    return ps;
}

} // namespace gale::scene
