// A run's settings and per-frame statistics as JSON (run/sim_json.h), written by hand so the
// text is the same byte for byte wherever it is produced (gale sim's run.json, Python's stats).
#include "run/sim_json.h"

#include "fields/scene.h"
#include "io/pointset.h"

#include <cmath>
#include <sstream>

namespace gale::run {

using io::jsonString;
using solver::Body;

namespace {

std::string num(double v) {
    return std::isfinite(v) ? io::formatNumber(v) : "null";
}

std::string vec(const std::vector<double>& v) {
    std::string s = "[";
    for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
    return s + "]";
}

// A parameter as JSON: its value at `t`, and whether it is keyframed.
std::string paramJson(const fields::Param& p, double t) {
    std::string s = p.width() == 1 ? num(p.scalarAt(t)) : vec(p.at(t));
    return p.isKeyed() ? "{\"at_start\": " + s + ", \"keyed\": true}" : s;
}

const char* solverName(solver::LinearSolverKind k) {
    return k == solver::LinearSolverKind::Direct ? "direct" : "pcg";
}

std::string stepJson(const solver::StepOptions& s) {
    return "\"linear_solver\": \"" + std::string(solverName(s.linearSolver)) +
           "\", \"cg_tolerance\": " + num(s.cgTolerance) +
           ", \"cg_max_iterations\": " + std::to_string(s.cgMaxIterations) +
           ", \"preconditioner\": \"" +
           (s.preconditioner == solver::Preconditioner::Multigrid ? "multigrid" : "jacobi") +
           "\", \"multigrid\": \"" + solver::multigridKindName(s.multigrid) +
           "\", \"newton_iterations\": " + std::to_string(s.newtonIterations) +
           ", \"newton_tolerance\": " + num(s.newtonTolerance);
}

} // namespace

std::string settingsJson(const scene::SimScene& sc,
                         const std::vector<std::unique_ptr<Body>>& bodies, int first, int last,
                         int threads, const std::vector<std::string>& sets) {
    const fields::SceneSettings& s = sc.wind.settings;
    const double t0 = s.frameTime(first);
    std::ostringstream o;
    o << "{\"scene\": " << jsonString(sc.wind.path) << ", \"sets\": [";
    for (size_t i = 0; i < sets.size(); ++i) o << (i ? ", " : "") << jsonString(sets[i]);
    o << "], \"fps\": " << num(s.fps) << ", \"time_zero\": " << num(s.timeZero) << ", \"frames\": ["
      << first << ", " << last << "], \"preroll\": " << s.preroll
      << ", \"substeps\": " << s.substeps << ", \"gravity\": " << vec(s.gravity)
      << ", \"air_density\": " << num(s.airDensity) << ", \"threads\": " << threads
      << ", \"solver\": {\"max_halvings\": " << sc.solver.maxHalvings
      << ", \"over_stretch\": " << num(sc.solver.overStretch)
      << ", \"velocity_jump\": " << num(sc.solver.velocityJump)
      << ", \"retry_newton\": " << sc.solver.retryNewton
      << ", \"retry_cg_tolerance\": " << num(sc.solver.retryCgTolerance)
      << ", \"retry_keep_coarse\": " << (sc.solver.retryKeepCoarse ? "true" : "false")
      << ", \"retry_repeat\": " << (sc.solver.retryRepeat ? "true" : "false")
      << ", \"grow_back\": " << (sc.solver.growBack ? "true" : "false")
      << ", \"retry_strain_limit\": " << (sc.solver.strainLimit ? "true" : "false")
      << ", \"rotation_projection\": "
      << jsonString(rotationProjectionName(sc.solver.rotationProjection))
      << ", \"stretch_limit\": " << num(sc.solver.stretchLimit) << "}";
    o << ", \"fields\": [";
    for (size_t i = 0; i < sc.wind.fields.size(); ++i)
        o << (i ? ", " : "") << jsonString(sc.wind.fields[i].name);
    o << "], \"objects\": [";
    // The vertices bound to a body's surface (hard or soft `attach`) and the attachment's
    // stiffness (N/m; 0: hard).
    const auto attachJson = [&](const Body* b) {
        size_t attached = 0;
        double stiffness = 0.0;
        if (b)
            for (const solver::PinSet& set : b->pinSets())
                if (set.attach) {
                    attached += set.vertices.size();
                    stiffness = set.stiffness;
                }
        return ", \"attached\": " + std::to_string(attached) +
               ", \"attach_stiffness\": " + num(stiffness);
    };
    size_t bi = 0;
    for (const scene::ClothSpec& c : sc.cloths) {
        const Body* b = bi < bodies.size() ? bodies[bi++].get() : nullptr;
        const solver::ClothMaterial& m = c.material;
        o << (bi > 1 ? ", " : "") << "{\"name\": " << jsonString(c.name)
          << ", \"kind\": \"cloth\", \"geometry\": "
          << (c.meshPath.empty() ? "\"grid\"" : jsonString(c.meshPath))
          << ", \"vertices\": " << (b ? b->vertexCount() : 0)
          << ", \"pinned\": " << (b ? b->pinnedVertices().size() : 0) << attachJson(b)
          << ", \"density\": " << num(m.density) << ", \"stretch\": " << paramJson(m.stretch, t0)
          << ", \"shear\": " << paramJson(m.shear, t0) << ", \"bend\": " << paramJson(m.bend, t0)
          << ", \"damping\": " << paramJson(m.damping, t0)
          << ", \"lift\": " << paramJson(c.lift.value, t0) << ", \"lift_painted\": "
          << (c.lift.map.empty() && c.lift.exprPath.empty() && c.lift.source.empty() ? "false"
                                                                                     : "true")
          << ", \"drag\": " << paramJson(c.drag.value, t0) << ", \"drag_painted\": "
          << (c.drag.map.empty() && c.drag.exprPath.empty() && c.drag.source.empty() ? "false"
                                                                                     : "true")
          << ", \"aero_model\": \""
          << (m.aeroModel == solver::AeroModel::Frozen ? "frozen" : "smooth-lift")
          << "\", \"aero_jacobian\": \"" << solver::aeroJacobianName(c.step.aeroJacobian) << "\", "
          << stepJson(c.step) << ", \"self_collision\": " << (c.collision.self ? "true" : "false")
          << ", \"thickness\": " << num(c.collision.thickness) << ", \"output\": \"" << c.output
          << "\"}";
    }
    for (const scene::HairSpec& h : sc.hairs) {
        const Body* b = bi < bodies.size() ? bodies[bi++].get() : nullptr;
        const solver::HairMaterial& m = h.material;
        o << (bi > 1 ? ", " : "") << "{\"name\": " << jsonString(h.name)
          << ", \"kind\": \"hair\", \"geometry\": "
          << (h.strandsPath.empty() ? "\"grid\"" : jsonString(h.strandsPath))
          << ", \"vertices\": " << (b ? b->vertexCount() : 0) << attachJson(b)
          << ", \"radius\": " << num(m.radius) << ", \"density\": " << num(m.density)
          << ", \"stretch\": " << paramJson(m.stretch, t0)
          << ", \"bend\": " << paramJson(m.bend, t0)
          << ", \"damping\": " << paramJson(m.damping, t0)
          << ", \"drag_normal\": " << paramJson(h.dragNormal.value, t0)
          << ", \"drag_tangent\": " << paramJson(h.dragTangent.value, t0)
          << ", \"root_pinned\": " << (m.rootPinned ? "true" : "false") << ", " << stepJson(h.step)
          << ", \"output\": \"" << h.output << "\"}";
    }
    o << "], \"colliders\": [";
    for (size_t i = 0; i < sc.colliders.size(); ++i) {
        const solver::Collider& c = sc.colliders[i];
        const char* type = c.shape == solver::ColliderShape::Plane    ? "plane"
                           : c.shape == solver::ColliderShape::Sphere ? "sphere"
                           : c.shape == solver::ColliderShape::Mesh   ? "mesh"
                                                                      : "capsule";
        o << (i ? ", " : "") << "{\"name\": " << jsonString(c.name) << ", \"type\": \"" << type
          << "\", \"radius\": " << num(c.radius) << ", \"thickness\": " << num(c.thickness)
          << ", \"friction\": " << num(c.friction) << "}";
    }
    o << "]}";
    return o.str();
}

std::string frameJson(const solver::FrameStats& f) {
    std::ostringstream o;
    o << "{\"frame\": " << f.frame << ", \"time\": " << num(f.time)
      << ", \"wall_seconds\": " << num(f.wallSeconds)
      << ", \"failed\": " << (f.failed ? "true" : "false") << ", \"objects\": [";
    for (size_t i = 0; i < f.bodies.size(); ++i) {
        const solver::BodyFrameStats& b = f.bodies[i];
        o << (i ? ", " : "") << "{\"name\": " << jsonString(b.name)
          << ", \"substeps\": " << b.substeps << ", \"rejected_substeps\": " << b.rejected
          << ", \"recovered_substeps\": " << b.recovered
          << ", \"newton_retries\": " << b.newtonRetries
          << ", \"deepest_halving\": " << b.deepestHalving
          << ", \"solver_iterations\": " << b.iterations
          << ", \"linear_solves\": " << b.linearSolves
          << ", \"max_iterations\": " << b.maxIterations
          << ", \"max_residual\": " << num(b.maxResidual)
          << ", \"newton_iterations\": " << b.newtonIterations
          << ", \"max_newton_iterations\": " << b.maxNewtonIterations
          << ", \"max_newton_residual\": " << num(b.maxNewtonResidual)
          << ", \"line_search_cuts\": " << b.lineSearchCuts
          << ", \"newton_unconverged\": " << b.newtonStalled
          << ", \"max_speed\": " << num(b.maxSpeed) << ", \"max_stretch\": " << num(b.maxStretch)
          << ", \"min_stretch\": " << num(b.minStretch)
          << ", \"energy\": {\"kinetic\": " << num(b.kinetic) << ", \"elastic\": " << num(b.elastic)
          << ", \"potential\": " << num(b.potential)
          << ", \"total\": " << num(b.kinetic + b.elastic + b.potential)
          << "}, \"wind_non_finite\": " << b.windNonFinite
          << ", \"clamped_jacobians\": " << b.clampedJacobians << ", \"contacts\": " << b.contacts
          << ", \"contact_solve\": {\"constraints\": " << b.contactConstraints
          << ", \"added\": " << b.contactAdded << ", \"through\": " << b.contactsThrough
          << ", \"released\": " << b.contactReleases << ", \"slid\": " << b.contactSlides
          << ", \"extra_solves\": " << b.contactSolves
          << "}, \"rotation_projection\": {\"substeps\": " << b.rotationSubsteps
          << ", \"edges\": " << b.rotationEdges << ", \"max_excess\": " << num(b.rotationExcess)
          << "}, \"stretch_limit\": {\"substeps\": " << b.stretchLimitSubsteps
          << "}, \"contact_projection\": {\"vertices\": " << b.projected
          << ", \"max_distance\": " << num(b.projectedDistance)
          << ", \"max_speed\": " << num(b.projectedSpeed) << ", \"relaxed\": " << b.sweepRelaxed
          << "}";
        if (b.selfIntersections >= 0) o << ", \"self_intersections\": " << b.selfIntersections;
        o
          << ", \"failed\": " << (b.failed ? "true" : "false") << ", \"events\": [";
        for (size_t e = 0; e < b.events.size(); ++e)
            o << (e ? ", " : "") << jsonString(b.events[e]);
        o << "], \"trouble\": [";
        for (size_t e = 0; e < b.trouble.size(); ++e) {
            const solver::FrameTrouble& t = b.trouble[e];
            o << (e ? ", " : "") << "{\"kind\": \"" << t.kindName() << "\", \"vertex\": " << t.vertex;
            if (t.other >= 0) o << ", \"other_vertex\": " << t.other;
            o << ", \"position\": [" << num(t.position.x()) << ", " << num(t.position.y()) << ", "
              << num(t.position.z()) << "], \""
              << (t.kind == solver::FrameTrouble::Kind::OverStretch ? "stretch" : "depth")
              << "\": " << num(t.amount) << ", \"limit\": " << num(t.limit)
              << ", \"count\": " << t.count << ", \"forced_by\": " << jsonString(t.forcedBy)
              << ", \"scene\": " << (t.scene ? "true" : "false") << "}";
        }
        o << "]}";
    }
    o << "]";
    if (f.selfCollision) {
        const solver::SelfCollisionStats& s = f.selfContacts;
        o << ", \"self_collision\": {\"passes\": " << s.passes
          << ", \"proximity_pairs\": " << s.proximityPairs << ", \"ccd_hits\": " << s.ccdHits
          << ", \"ccd_rounds\": " << s.ccdRounds << ", \"broad_phases\": " << s.broadPhases
          << ", \"candidates\": " << s.candidates << ", \"fail_safe_runs\": " << s.failSafeRuns
          << ", \"halvings\": " << s.halvings << ", \"retries\": " << s.retries
          << ", \"zone_vertices\": " << s.zoneVertices
          << ", \"frozen_vertices\": " << s.frozenVertices << ", \"unresolved\": " << s.unresolved
          << ", \"start_touching\": " << s.startTouching
          << ", \"tangled_hair_vertices\": " << s.tangledHairVertices
          << ", \"seconds\": {\"broad\": " << num(s.broadSeconds)
          << ", \"proximity\": " << num(s.proximitySeconds) << ", \"ccd\": " << num(s.ccdSeconds)
          << ", \"fail_safe\": " << num(s.failSafeSeconds) << "}}";
    }
    o << "}";
    return o.str();
}

solver::FrameStats initialStats(const solver::World& w, int frame, double t) {
    solver::FrameStats f;
    f.frame = frame;
    f.time = t;
    for (const auto& b : w.bodies()) {
        solver::BodyFrameStats s;
        s.name = b->name();
        s.maxStretch = b->maxEdgeStretch();
        s.minStretch = b->minEdgeStretch();
        s.kinetic = b->kineticEnergy();
        s.potential = b->potentialEnergy(w.settings().gravity);
        s.elastic = const_cast<Body&>(*b).elasticEnergy(f.time);
        f.bodies.push_back(s);
    }
    return f;
}

} // namespace gale::run
