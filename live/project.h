// What `gale live` shows, loaded from disk: a scene (SCENE.toml) or one expression (FILE.se),
// compiled to a field, with its diagnostics, its editable literals (parameters and ramps, each
// at the file and line that holds its effective value), the files to watch, the cloth and hair
// rest meshes, the colliders and the view box. Reloaded whole on every change.
#pragma once

#include "fields/field.h"
#include "fields/scene.h"
#include "live/literals.h"
#include "live/sim_job.h"
#include "solver/collider/collider.h"
#include "viz/picture.h"
#include "viz/volume_marks.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gale::live {

// One problem as `gale check` prints it: file:line:col (0 when unknown) and the message; `text`
// is the full rendering (source line, caret, notes).
struct Diagnostic {
    std::string file;
    int line = 0, col = 0;
    std::string severity = "error";
    std::string message;
    std::string text;
};

// A parameter slider: the declaration (in `declaredIn`, an expression file) and where its
// effective value is written: the declaration itself, or the scene's `params = { name = v }`
// of the field that overrides it (then `literal` locates that value in the scene file).
struct LiveParam {
    std::string field;      // the [[field]] name ("" for a lone .se)
    std::string declaredIn; // the expression file
    std::string file;       // the file holding the effective literal
    ParamLiteral literal;   // name, value, range; begin/end/line within `file`
    bool editable = true;   // false: keyframed or computed, not one literal
    std::string text;       // the literal as read (an edit checks it is still there)
};

struct LiveRamp {
    int id = 0;
    std::string file;
    RampLiteral literal;
    std::string text; // the control points as read
};

struct ColliderShape {
    std::string name;
    std::string shape; // plane, sphere, capsule, mesh
    std::array<double, 3> a{}, b{}, normal{0.0, 1.0, 0.0};
    double radius = 0.0;
    viz::GeometryOverlay mesh; // mesh colliders: the mesh file's triangles
    bool moving = false;       // a mesh sequence: `mesh` is its pose at one time
};

class Project {
public:
    // `input`: a SCENE.toml or FILE.se; `allowPaths` as --allow-path.
    Project(std::string input, std::vector<std::string> allowPaths = {});

    // Reads and compiles everything. False when there were errors (diagnostics() says which);
    // the files to watch are known either way (at least the input).
    bool load();

    bool ok() const { return mField != nullptr; }
    const std::string& input() const { return mInput; }
    bool isScene() const { return mScene != nullptr; }
    // Every file the input names that exists: the input, expression files, meshes, strands.
    const std::vector<std::string>& files() const { return mFiles; }
    // Paths the input names that are not files yet (a `#` frame sequence such as
    // `body/body.#.obj`, a mesh still to be written): watched for, never served.
    const std::vector<std::string>& patterns() const { return mPatterns; }
    const std::vector<Diagnostic>& diagnostics() const { return mDiagnostics; }
    const std::vector<LiveParam>& params() const { return mParams; }
    const std::vector<LiveRamp>& ramps() const { return mRamps; }
    fields::FieldPtr field() const { return mField; }
    std::shared_ptr<const fields::Scene> scene() const { return mScene; }
    double fps() const { return mFps; }
    // scene.time_zero: frame F is at t = (F − timeZero) / fps (0 for a lone .se).
    double timeZero() const { return mTimeZero; }
    int frameStart() const { return mFrameStart; }
    int frameEnd() const { return mFrameEnd; }
    const std::vector<viz::GeometryOverlay>& restGeometry() const { return mRest; }
    const std::vector<ColliderShape>& colliders() const { return mColliders; }
    // The colliders as the solver places them at time t (s): keyframed planes, spheres and
    // capsules at their pose (solver::colliderPose), mesh sequences' vertices interpolated by
    // solver::MeshSequence::positionsAt, static meshes as loaded.
    std::vector<ColliderShape> collidersAt(double t) const;
    // The scene's cloth and hair as gale sim names their frame files.
    const std::vector<SimObject>& simObjects() const { return mObjects; }
    // Around the rest geometry and colliders (padded), else -2..2 on each axis.
    const viz::Box3& box() const { return mBox; }
    // The scene's overlays (windicator, gust bands, timeline) at time t; none for a .se.
    viz::SliceOverlays overlays(double t) const;

    // Sets parameter `name` (of `field` when several declare it; "" for the first) to `value`:
    // rewrites its literal in its file in place, atomically. False with `error` otherwise.
    bool setParam(const std::string& name, const std::string& field,
                  const std::vector<double>& value, std::string& error);
    // Replaces ramp `id`'s control points in its file.
    bool setRamp(int id, const std::vector<RampPoint>& points, std::string& error);

private:
    void loadExpressionFile();
    void loadSceneFile();
    void addFile(const std::string& path);
    void addPattern(const std::string& path);
    void computeBox();
    bool rewrite(const std::string& file, const std::function<bool(std::string&)>& edit,
                 std::string& error);

    std::string mInput;
    std::vector<std::string> mAllowPaths;
    std::vector<std::string> mFiles;
    std::vector<std::string> mPatterns;
    std::vector<Diagnostic> mDiagnostics;
    std::vector<LiveParam> mParams;
    std::vector<LiveRamp> mRamps;
    fields::FieldPtr mField;
    std::shared_ptr<const fields::Scene> mScene;
    double mFps = 24.0;
    double mTimeZero = 0.0;
    int mFrameStart = 1, mFrameEnd = 48;
    std::vector<viz::GeometryOverlay> mRest;
    std::vector<ColliderShape> mColliders;
    std::vector<solver::Collider> mSimColliders; // as loaded (mesh sequences shared)
    std::vector<SimObject> mObjects;
    viz::Box3 mBox;
};

} // namespace gale::live
