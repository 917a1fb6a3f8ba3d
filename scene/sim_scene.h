// The bodies' part of a scene — [[cloth]], [[hair]], [[collider]] and [solver] — as the scene
// loader (scene/load.h) reads it from the same TOML file as the wind, and turned into bodies
// here: meshes and strands loaded, painted maps evaluated, pins resolved.
#pragma once

#include <climits>

#include "fields/scene.h"
#include "scene/error.h"
#include "io/pointset.h"
#include "solver/bodies/cloth.h"
#include "solver/bodies/hair.h"
#include "solver/world/world.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace gale::scene {

// A per-vertex coefficient as written: a value (number or keys) times an optional map — a
// PLY vertex property, or an expression over $P (rest position), $u, $v, $id.
struct PaintedSpec {
    fields::Param value{1.0};
    std::string map;      // vertex property name ("" for none)
    std::string exprPath; // expression file, resolved against the scene's folder
    std::string source;   // inline expression
    int line = 0, col = 0; // where it was written
};

// Pinned vertices: a list, a painted map (> 0.5 pins), a box, or any union of them, moved by
// an optional keyframed rotation about a pivot and a keyframed translation (body.h, PinSet).
struct PinSpec {
    std::vector<int> vertices;
    std::string map;
    bool hasBox = false;
    double box[6] = {0, 0, 0, 0, 0, 0};
    fields::Param translate{std::vector<double>{0.0, 0.0, 0.0}};
    solver::PinRotation rotate;
    double stiffness = 0.0; // attach: N/m per vertex, a soft attachment (0: hard)
    int line = 0, col = 0;
    // The `--set KEY=VALUE` that gave the table or its mesh, when one did: problems found later
    // (the mesh cannot be read, the selection is empty) are said there, not at the scene's line.
    std::string origin;
};

// An error (or, with `warning`, a warning) at a pins or attach key: its `--set` when one gave
// it, else its line and column in `file`.
SceneError specError(const std::string& file, const PinSpec& spec, std::string message,
                     bool warning = false);

struct ClothSpec {
    std::string name;
    std::string meshPath; // resolved; empty for a generated grid
    int meshLine = 0, meshCol = 0; // where mesh was written (0: by --set, meshOrigin)
    std::string meshOrigin;        // "--set cloth.NAME.mesh=..." when it was given there
    double gridSize[2] = {1.0, 1.0};
    int gridRes[2] = {16, 16};
    solver::Vec3 gridOrigin = solver::Vec3::Zero();
    std::string gridAxes = "xy"; // the plane of the grid: u along the first axis, v the second
    // Bending rest angles: "mesh" (the loaded mesh's, or rest_mesh's) | "flat"; "" — the
    // default: "mesh" for a loaded mesh, "flat" for a grid.
    std::string restShape;
    std::string restMeshPath; // resolved; optional rest (sewing) shape, same topology as mesh
    int restLine = 0, restCol = 0; // where rest_mesh was written
    solver::ClothMaterial material;
    PaintedSpec lift, drag;
    bool hasPins = false;
    PinSpec pins;
    // attach = { mesh = "body.#.obj", box | vertices | map }: the selected vertices bound to the
    // body's surface at its first frame (PinSet::attach).
    bool hasAttach = false;
    PinSpec attach;
    std::string attachMesh; // resolved
    solver::StepOptions step;
    // self_collision / thickness (solver/bodies/body.h, CollisionSettings): cloth against itself and the other
    // cloth with it on; an explicit thickness also applies against colliders (the larger wins).
    solver::CollisionSettings collision;
    std::string output = "obj"; // obj | ply
    int line = 0, col = 0;
};

struct HairSpec {
    std::string name;
    std::string strandsPath; // resolved; empty for generated strands
    int strandsLine = 0, strandsCol = 0; // where strands was written (0: by --set)
    std::string strandsOrigin;           // "--set hair.NAME.strands=..." when given there
    double gridSize[2] = {0.1, 0.1};
    int gridCount[2] = {4, 4};
    double length = 0.3;
    int segments = 12;
    solver::Vec3 origin = solver::Vec3::Zero();
    solver::Vec3 direction = -solver::Vec3::UnitY();
    solver::HairMaterial material;
    PaintedSpec dragNormal, dragTangent;
    // attach = { mesh = "scalp.#.obj", box = [...] (optional) }: roots bound to the surface.
    bool hasAttach = false;
    PinSpec attach;
    std::string attachMesh; // resolved
    // collide_cloth: the strands' segments against the scene's colliding cloth (the cloth with
    // self_collision = true), continuous, in the cloth's collision pass.
    bool collideCloth = true;
    solver::StepOptions step;
    std::string output = "obj";
    int line = 0, col = 0;
    HairSpec() { step.linearSolver = solver::LinearSolverKind::Direct; } // a chain's system is banded
};

// [solver]: the robustness limits (defaults in world.h / body.h).
struct SolverSection {
    int maxHalvings = 6;
    double overStretch = 1.5;
    double velocityJump = 50.0;
    // The response to a substep in trouble (solver::WorldSettings::retry*, growBack,
    // strainLimitRetry; the defaults are WorldSettings').
    int retryNewton = solver::WorldSettings{}.retryNewtonIterations;
    double retryCgTolerance = solver::WorldSettings{}.retryCgTolerance;
    bool retryKeepCoarse = solver::WorldSettings{}.retryKeepCoarse;
    bool retryRepeat = solver::WorldSettings{}.retryRepeat;
    bool growBack = solver::WorldSettings{}.growBack;
    bool strainLimit = false;
    // When the length a linearised step's rotations add is projected out of every body's edges
    // (solver::StepOptions::rotationProjection): "off", "contact" or "always" (default).
    solver::RotationProjection rotationProjection = solver::StepOptions{}.rotationProjection;
    // Strain limit of every body's edges (× rest; 0: none; solver::StepOptions::stretchLimit).
    double stretchLimit = solver::StepOptions{}.stretchLimit;
};

struct SimScene {
    fields::Scene wind;
    SolverSection solver;
    std::vector<ClothSpec> cloths;
    std::vector<HairSpec> hairs;
    std::vector<solver::Collider> colliders;
    // Per collider: the rest pose its pre-roll eases from (a sequence's rest_mesh; empty: the
    // sequence's first file).
    std::vector<std::vector<double>> colliderRest;
    // Set by prerollSequences: the frame the pre-roll ends at (INT_MIN: no pre-roll) and the eased
    // sequences by their files (any spelling of the pattern), shared by the colliders and the
    // attachments that name them.
    int prerollTo = INT_MIN;
    std::map<std::string, std::shared_ptr<const solver::MeshSequence>> eased;
};

// scene.preroll: eases every mesh-sequence collider from its rest pose (held until frame
// toFrame − preroll) to its pose and velocity at `toFrame`, where the written frames start
// (solver::MeshSequence::eased); buildBodies eases attachment sequences the same way. Nothing
// without a pre-roll. False, with errors at the collider, when a rest pose does not fit.
bool prerollSequences(SimScene& scene, int toFrame, std::vector<SceneError>& errors);

// Loads meshes and strands, evaluates painted maps and pins, and makes the bodies. Problems
// (a missing mesh, an unknown map, an expression error) come back as errors at the place in
// the scene that named them; `warnings` gets notes such as degenerate-triangle counts. Files
// named in painted-map expressions resolve like the wind's: inside the scene's folder or one of
// `allowPaths` (--allow-path).
// Attachments bind against their body at the first simulated frame's time (the start state's:
// frameTime(firstFrame); INT_MIN: the scene's first frame), whatever range the sequence covers.
bool buildBodies(const SimScene& scene, std::vector<std::unique_ptr<solver::Body>>& bodies,
                 std::vector<SceneError>& errors, std::vector<std::string>& warnings,
                 const std::vector<std::string>& allowPaths = {}, int firstFrame = INT_MIN);

// The bodies of a run whose written frames start at `shotStart`, as `gale sim` makes them and
// `gale check` looks at them: prerollSequences to shotStart, then buildBodies bound at the
// run-up's first frame, shotStart − preroll (the bodies' rest pose under a pre-roll).
bool buildShotBodies(SimScene& scene, int shotStart,
                     std::vector<std::unique_ptr<solver::Body>>& bodies,
                     std::vector<SceneError>& errors, std::vector<std::string>& warnings,
                     const std::vector<std::string>& allowPaths = {});

// World settings of a scene (threads: 0 for all hardware threads).
solver::WorldSettings worldSettings(const SimScene& scene, int threads);

// A body's current shape for output: OBJ text (`v` lines, then `f` for cloth or `l` for
// strands), or a point set with faces (cloth) or a `strand` column (hair) for PLY.
std::string bodyObjText(const solver::Body& body);
io::PointSet bodyPointSet(const solver::Body& body);

} // namespace gale::scene
