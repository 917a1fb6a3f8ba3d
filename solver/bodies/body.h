// A simulated body (cloth or hair): particle state, lumped masses, pins, and the linearised
// backward-Euler substep (Baraff & Witkin 1998) shared by every kind of body. Subclasses
// supply the pattern of coupled vertices and their forces with SPD Jacobians.
#pragma once

#include "fields/field.h"
#include "fields/keyframes.h"
#include "solver/bodies/aero.h"
#include "solver/bodies/kinematics.h"
#include "solver/collider/collider.h"
#include "solver/linalg/linear.h"
#include "solver/linalg/types.h"

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

namespace gale::solver {

class MeshSequence; // solver/mesh/mesh_sequence.h
struct SurfaceBinding;

// A scalar that is keyframable (`value`) and optionally painted per vertex (`map`, multiplied).
struct PaintedParam {
    fields::Param value{1.0};
    std::vector<double> map; // per vertex, empty: 1 everywhere

    double at(double t) const { return value.scalarAt(t); }
    bool painted() const { return !map.empty(); }
    // True when the value is zero at every key (and the constant): the term can be skipped.
    bool alwaysZero() const;
};

// A keyframable rotation of pinned vertices by `angle` (degrees, right-handed) about the line
// through `pivot` along `axis` (world space, fixed).
struct PinRotation {
    bool active = false;
    Vec3 pivot = Vec3::Zero();
    Vec3 axis = Vec3::UnitY();
    fields::Param angle{0.0}; // degrees, scalar keys
};

// Pinned vertices, held at their initial positions moved rigidly by a keyframable rotation about
// a pivot, then a keyframable translation (Houdini/Maya order: rotate about the pivot, then
// translate): target(t) = pivot + R(t)(x_start − pivot) + translate(t). With `attach`, each
// vertex is instead bound (when added) to its closest point on that mesh's first frame and
// follows it (mesh_sequence.h, SurfaceBinding): an attachment, a hard constraint like a pin.
struct PinSet {
    std::vector<int> vertices;
    fields::Param translate{std::vector<double>{0.0, 0.0, 0.0}}; // m, vector keys
    PinRotation rotate;
    std::shared_ptr<const MeshSequence> attach;
    // s: the time of the body's pose the attachment binds against — the first simulated frame's
    // (the start state's) time; NaN: the sequence's first file.
    double bindTime = NAN;
    // N/m per vertex: a soft attachment, each vertex pulled to its bound point p(t) by a
    // zero-length spring, f = −k (x − p(t + h)) at the step's end (backward Euler, its stiffness in
    // the implicit matrix: A += h² k I), energy ½ k |x − p|². 0: hard (a pin on the surface).
    double stiffness = 0.0;
};

// When the length a linearised step's rotations add is projected out (rotation_projection.h):
// never, in the substeps where a collider holds one of the body's vertices in the solve (the
// default: an impact turns the free cloth about the contact within one step), or in every
// substep (a cloth flapping at one substep a frame too, at 1.7–2.6× the step's cost).
enum class RotationProjection : uint8_t { Off, Contact, Always };
const char* rotationProjectionName(RotationProjection r); // "off", "contact", "always"

// Numerical settings of a body's substep.
struct StepOptions {
    AeroJacobian aeroJacobian = AeroJacobian::Bounded;
    LinearSolverKind linearSolver = LinearSolverKind::Pcg;
    Preconditioner preconditioner =
        Preconditioner::Multigrid; // of PCG (multigrid.h; measured faster, bench/README.md)
    // The multigrid's hierarchy: Automatic takes smoothed aggregation from
    // BlockMultigrid::Settings::smoothedMinRows block rows up (its set-up pays only there,
    // bench/README.md) and plain aggregation below; Plain and Smoothed force one;
    // SmoothedRotations is Smoothed with rotations in the near-null space.
    MultigridKind multigrid = MultigridKind::Automatic;
    double cgTolerance = 1e-3; // relative residual of the filtered system
    int cgMaxIterations = 2000;
    // Newton on the backward-Euler residual after the linearised solve (body.cpp, newton()):
    // at most `newtonIterations` corrections, until every free vertex's velocity residual
    // error Aᵢᵢ⁻¹ S gᵢ is below
    // `newtonTolerance` (m/s).
    int newtonIterations = 0;
    double newtonTolerance = 0.01;
    // Newton's iterations solve with the full Jacobian: also how the aerodynamic force turns
    // with each triangle (∂F/∂x) and the parts of ∂F/∂v the symmetric damping drops, by GMRES.
    // Off: the SPD linearisation of every iterate (cheaper; no quadratic convergence).
    bool newtonFullJacobian = true;
    // Newton's solves keep the multigrid's coarse levels from the substep's linearised solve
    // (only level 0 takes each iterate's matrix). Off: measured on the wind-onset flag the
    // iterates' matrices are far from the linearised one (CG 17 → 275 iterations per solve).
    bool newtonKeepCoarse = false;
    bool warmStart = true; // start CG from the previous substep's Δv
    // Symplectic (semi-implicit) Euler, v += h M⁻¹ f, x += h v: the explicit baseline the
    // benchmarks compare against (no linear solve; unstable when h·k > 2, see aero.md).
    bool explicitEuler = false;
    // After the linearised step (when no Newton ran on it), the length its rotations added is
    // projected out of every edge longer than both its rest length and the length the step saw
    // (rotation_projection.h, docs/solver.md; the scene's [solver] rotation_projection), by
    // default in every substep: by more than rotationTolerance × rest in substeps where a
    // collider holds a vertex in the solve (an impact turns a ring of edges about it) ...
    RotationProjection rotationProjection = RotationProjection::Always;
    double rotationTolerance = 1e-3;
    // ... and by more than this in the others: the whip fronts of a cloth flapping in free air,
    // not every turned edge (5,000–8,000 of the wind-onset flag's 12,000 at 0.1 %, which its
    // Gauss–Newton does not bring in within its iterations, at 1.7–2.6× the step; at 3 % the
    // flag's largest stretch is the same, 1.22 against 1.99 without, for 5 % of the step).
    double rotationFreeTolerance = 0.03;
    // Strain limit (× rest length; 0: none): a substep whose step would end with an edge longer
    // than this projects every such edge back to it, by the same projection (Provot 1995's
    // limit, solved as Goldenthal et al. 2007 do; [solver] stretch_limit).
    double stretchLimit = 0.0;
    // Contacts of vertices stacked behind a deeper edge neighbour along the normal wait a
    // round (Body::updateContacts). Off: every vertex that ends inside is held at once.
    bool deferStackedContacts = true;
};

// What a substep sees of the world.
struct Environment {
    const fields::Field* wind = nullptr; // summed scene fields (may be null: still air)
    double airDensity = 1.225;           // kg/m³
    Vec3 gravity = Vec3(0.0, -9.81, 0.0);
    const std::vector<Collider>* colliders = nullptr;
    double fps = 24.0;
    double frameZero = 0.0; // the frame at t = 0 ($frame = t · fps + frameZero)
    int threads = 1;
    int substepIndex = 0;
    // The in-substep retry of a linearised step in trouble (World::stepBody; docs/solver.md,
    // Robust substepping): when the linearised step's end state would over-stretch an edge or
    // jump a vertex's speed (the trouble detector's rules), at most `retryNewtonIterations`
    // Newton iterations (SPD iterates, their line search keeping every iterate
    // stretch-feasible) from it, without solving the linearised step again, each correction
    // solved to `retryCgTolerance` (0: cg_tolerance). 0 iterations: no retry here. Ignored
    // when newton_iterations > 0 (Newton runs anyway).
    int retryNewtonIterations = 0;
    double retryCgTolerance = 0.0;
    // The retry's solves after its first keep the multigrid's coarse levels of its first solve
    // (level 0 refreshed; smoothed aggregation only).
    bool retryKeepCoarse = false;
};

// Contact settings of a body (cloth): cloth–cloth collision (solver/world/self_collision.h) and the
// collision thickness ξ (m) it keeps from itself and other cloth; against colliders the larger
// of ξ and the collider's own thickness applies when `thicknessForColliders` is set (a cloth
// with an explicit `thickness` in the scene).
struct CollisionSettings {
    bool self = false;
    double thickness = 0.003;
    bool thicknessForColliders = false;
};

// Why a substep was rejected (the caller halves the step and retries).
enum class Trouble { None, NonFinite, SolverNotConverged, OverStretch, VelocityJump };
const char* troubleName(Trouble t);

struct SubstepStatus {
    Trouble trouble = Trouble::None;
    std::string reason;    // human-readable detail of the trouble
    int iterations = 0;    // linear-solver iterations (all Newton iterations)
    double residual = 0.0; // the largest relative residual of those solves
    bool converged = true;
    int newtonIterations = 0;    // Newton corrections after the linearised solve
    double newtonResidual = 0.0; // m/s: the largest free vertex's velocity residual at the end
    int lineSearchCuts = 0;      // step halvings of the Newton line search
    bool newtonStalled = false;  // stopped above the tolerance: no step lowered the merit
    // The linearised step was in trouble and retried inside the substep with Newton
    // (Environment::retryNewtonIterations): what it was, and why.
    Trouble retried = Trouble::None;
    std::string retryReason;
    int linearSolves = 0; // solves with a fresh matrix (linearised step, contact rounds, Newton)
    size_t windNonFinite = 0;    // wind samples that came back NaN/inf (replaced by zero)
    std::string windMessage;
    int clampedJacobians = 0; // paper Jacobian with C_D < C_L, clamped
    double maxSpeed = 0.0;    // m/s after the step
    double maxStretch = 0.0;  // largest edge length / rest length after the step
    int contacts = 0;         // vertices touching a collider after the step
    // Collider contact in the solve: constraints at the end, added after a solve (ended
    // inside), released (their force pulled), extra solves for those changes; and what the
    // projection after the solve still had to do: vertices it moved or stopped, the largest
    // push-out (m) and the largest approach speed it removed (m/s).
    int contactConstraints = 0, contactAdded = 0, contactReleases = 0, contactSolves = 0;
    int clothConstraints = 0; // of contactConstraints: cloth held against cloth (setClothPlanes)
    int contactSlides = 0; // sticking contacts that turned to slide (friction at μ λ_n)
    int contactsThrough = 0; // of contactAdded: vertices whose step went through the collider
    // The rotation projection (StepOptions::rotationProjection): edges beyond their target by
    // more than the tolerance before it, and the largest excess over the target (× rest).
    int rotationEdges = 0;
    double rotationExcess = 0.0;
    bool rotationProjected = false; // the projection ran in this substep
    bool stretchLimited = false;    // ... for edges beyond StepOptions::stretchLimit
    int projected = 0;
    int sweepRelaxed = 0; // vertices moved to give back what the sweep stretched (relaxSwept)
    double projectedDistance = 0.0, projectedSpeed = 0.0;
};

// Limits of the trouble detectors.
struct TroubleLimits {
    double overStretch = 1.5;   // edge length / rest length that counts as over-stretched
    double velocityJump = 50.0; // m/s: a |Δv| larger than this and than 2× the speed scale
};

// One element's aerodynamic linearisation (ForceOutput::aero); unused corners are −1. With
// s = Σ_{c in element} x_c, every corner c gets (A x)_c += damping s + axis × s: `damping` the
// symmetric part (already in A), `axis` the skew part (a cloth triangle: (h/9) D and (h/9) ω).
struct AeroCoupling {
    std::array<int, 3> v{-1, -1, -1};
    Mat3 damping = Mat3::Zero();
    Vec3 axis = Vec3::Zero();
};
// Newton's full Jacobian only (ForceInput::aeroPosition), per cloth triangle beside its
// AeroCoupling, allocated only for such assemblies: the force's dependence on the triangle's
// orientation, −h²∂f/∂x δ at every corner = P((δ₁ − δ₀) × e₂ + e₁ × (δ₂ − δ₀)),
// P = −(h²/6) ∂F/∂a, e₁ = x₁ − x₀, e₂ = x₂ − x₀ (a = ½ e₁ × e₂, f = F/3 per corner); and what
// `damping` leaves out of the exact (h/9)∂F/∂v (its whole skew part, ungated, and the clamped
// negative part): Newton's iterations solve with the exact Jacobian, this in place of `axis`.
// `psd`: the PSD part of the symmetrised orientation Jacobian (9×9, corners' blocks), also
// added to A so that the preconditioner sees it; the rest stays in the Krylov operator.
struct AeroOrientation {
    Mat3 position = Mat3::Zero();
    Vec3 e1 = Vec3::Zero(), e2 = Vec3::Zero();
    Mat3 velocityRest = Mat3::Zero();
    Mat9 psd = Mat9::Zero();
};

// What a body's force routine reads and writes.
struct ForceInput {
    const double* x = nullptr;
    const double* v = nullptr;
    const double* wind = nullptr; // per vertex, null when the body feels no wind
    double t = 0.0, h = 0.0;
    double airDensity = 1.225;
    AeroJacobian aeroJacobian = AeroJacobian::Bounded;
    bool aeroPosition = false; // also the orientation part of ∂F/∂x (AeroOrientation)
};
struct ForceOutput {
    VecX* f = nullptr;          // forces (N), accumulated
    VecX* kv = nullptr;         // K v (N/s) with K = −∂f/∂x, accumulated (null: not needed)
    BlockMatrix* A = nullptr;   // h·D + h²·K accumulated (null: forces only)
    double elasticEnergy = 0.0; // J
    int clamped = 0;
    // The aerodynamic linearisation per element when asked for (one slot each; empty: none).
    std::vector<AeroCoupling>* aero = nullptr;
    // With ForceInput::aeroPosition: per element, its AeroOrientation (the slots of `aero`).
    std::vector<AeroOrientation>* aeroOrientation = nullptr;
    bool skewed = false; // some element's coupling has a skew part (the solve corrects for it)
};

// A plane that holds a cloth vertex in its own solve against another piece of cloth (its own or
// another's) it rests on or against: the self-collision pass's resting pair at the step's start
// (SelfCollision::contactPlanes). The vertex may not come closer to `point` along `normal` than it
// starts (at most ξ), the plane moving at `velocity`.
struct ClothContactPlane {
    int vertex = -1; // the body's vertex
    Vec3 normal;     // unit, from the other cloth towards the vertex
    Vec3 point;      // m: the other cloth's closest point at the step's start
    Vec3 velocity;   // m/s: the pair's centre-of-mass velocity (an inelastic meeting)
    // The pass after this very step found the pair closing (a retry, World): held whatever the
    // explicit prediction says (it missed the approach once).
    bool closing = false;
};

class Body {
public:
    virtual ~Body() = default;
    Body(const Body&) = delete;
    Body& operator=(const Body&) = delete;

    const std::string& name() const { return mName; }
    size_t vertexCount() const { return mMass.size(); }
    const VecX& positions() const { return mX; }
    const VecX& velocities() const { return mV; }
    const VecX& masses() const { return mMass; } // kg per vertex
    // Replace state (e.g. a pre-stretched start, or a resumed run). Sizes must match.
    void setPositions(const VecX& x) { mX = x; }
    void setVelocities(const VecX& v) { mV = v; }
    // Overrides lumped masses (kg per vertex; e.g. tests of equal-mass chains).
    void setMasses(const VecX& m) { mMass = m; }
    StepOptions& options() { return mOptions; }
    const StepOptions& options() const { return mOptions; }
    TroubleLimits& limits() { return mLimits; }
    // The cloth contact planes for the next substep (World, cloth against cloth in the solve).
    void setClothPlanes(std::vector<ClothContactPlane> planes) { mClothPlanes = std::move(planes); }
    CollisionSettings& collision() { return mCollision; }
    const CollisionSettings& collision() const { return mCollision; }
    // The triangles cloth–cloth contact sees (null: a body without a surface, e.g. hair).
    virtual const std::vector<std::array<int, 3>>* collisionTriangles() const { return nullptr; }
    const VecX& restPositions() const { return mRest; } // 3 per vertex (m)
    // Per vertex: touching a collider after the last substep (empty: no colliders).
    const std::vector<uint8_t>& colliderContacts() const { return mTouching; }

    void addPins(const PinSet& pins);
    const std::vector<int>& pinnedVertices() const { return mPinned; }
    // Pin target position of vertex index `k` in pinnedVertices() at time t.
    Vec3 pinTarget(size_t k, double t) const;
    // Its velocity d/dt of the rigid motion at t (m/s): ω × R(x_start − pivot) + d(translate)/dt,
    // the key curves' right derivatives (over 1e-6 s). The substep itself moves a pin along the
    // chord (target(t + h) − x₀)/h, so that x₁ lands exactly on the motion (backward Euler).
    Vec3 pinVelocity(size_t k, double t) const;

    // One linearised backward-Euler substep from t to t + h. Updates the state even when the
    // status reports trouble: the caller keeps a snapshot and decides.
    SubstepStatus substep(const Environment& env, double t, double h);

    // Whether any force of this body reads the wind (aerodynamic coefficients not all zero).
    virtual bool feelsWind() const = 0;
    virtual const char* kind() const = 0;

    // The full state a bit-identical continuation needs (positions, velocities, warm start).
    struct Snapshot {
        VecX x, v, dvGuess;
        double hGuess = 0.0;
        std::vector<double> slidRate, slipMass; // sliding contacts (mSlidRate, mSlipMass, mSlidOn)
        std::vector<int> slidOn;
    };
    Snapshot snapshot() const { return {mX, mV, mDvGuess, mHGuess, mSlidRate, mSlipMass, mSlidOn}; }
    void restore(const Snapshot& s);

    // The last line of defence at the smallest substep (World): from the state a troubled
    // substep left, speeds capped at the world's speed scale, then strain limiting (no edge
    // longer than max(1.1, the stretch at the substep's start, capped at over_stretch) × its
    // rest length) and velocities consistent with the positions. Always finite. Returns the
    // number of edge corrections.
    int recover(const Snapshot& start, double h);

    double kineticEnergy() const;
    double potentialEnergy(const Vec3& gravity) const; // −Σ m g·x (J)
    double elasticEnergy(double t);                    // J, at the current positions
    double maxEdgeStretch() const;                     // max |e| / |e_rest|
    double minEdgeStretch() const; // min |e| / |e_rest| (a squashed hair segment, a crushed fold)
    double maxEdgeStretchOf(const VecX& x) const;      // the same at positions x (NaN if any is)
    const std::vector<std::array<int, 2>>& edges() const { return mEdges; }
    // Edge e's length at positions x over its rest length (0 for an edge of zero rest length).
    double edgeStretchOf(const VecX& x, size_t e) const;
    // Every vertex bound to a body's surface (hard and soft attachments) and its bound point at t.
    void attachmentTargets(double t, std::vector<std::pair<int, Vec3>>& out) const;
    // Every vertex bound to a body's surface and its distance (m) to that surface at the bind
    // pose (SurfaceBinding::distance): how far from the body the cloth was when it was bound.
    void attachmentGaps(std::vector<std::pair<int, double>>& out) const;
    // The pin and attachment sets as added (addPins), in order.
    const std::vector<PinSet>& pinSets() const { return mPinSets; }
    // The colliders will not be where the last substep left them at its end (a collider made
    // anew for the next substep): the distance bounds carried from it are dropped.
    void forgetColliderBounds() { mBoundTime = NAN; }
    // Whether pin k (pinnedVertices()[k]) follows an attachment (a body's surface), not a pin.
    bool pinIsAttachment(size_t k) const { return k < mPinBinding.size() && mPinBinding[k]; }

protected:
    Body(std::string name, const VecX& restPositions);

    // Vertex pairs coupled by any element (for the matrix pattern), edges for the stretch
    // monitor; call once from the subclass constructor via `finishSetup`.
    virtual void couplings(std::vector<std::pair<int, int>>& pairs) const = 0;
    virtual void addForces(const ForceInput& in, ForceOutput& out) = 0;
    void finishSetup(const std::vector<std::array<int, 2>>& edges);
    const BlockMatrix& matrix() const { return mA; }

    std::string mName;
    VecX mX, mV, mMass, mRest;
    StepOptions mOptions;
    TroubleLimits mLimits;
    CollisionSettings mCollision;

private:
    // The thickness kept from collider c (m): its own, or the body's when larger and asked for.
    double colliderThickness(const Collider& c) const {
        return mCollision.thicknessForColliders ? std::max(c.thickness, mCollision.thickness)
                                                : c.thickness;
    }
    // Everything scripted for the substep [t, t + h] into mKin (kinematics.h), once.
    void evaluateKinematics(const Environment& env, double t, double h);
    void contactConstraints(const Environment& env, double t, double h);
    // Cloth against cloth in the solve: the planes the next substep's contactConstraints turns
    // into sliding constraints (applyClothPlanes), then forgets.
    std::vector<ClothContactPlane> mClothPlanes;
    void applyClothPlanes(double t, double h);
    void setContact(size_t i, int collider, const ContactPoint& cp, const Vec3& p, double tq,
                    double thick, double t1, double h, const VecX& x0, const VecX& v0,
                    const Vec3& path, bool stick);
    void contactRhs(double h);
    // The sliding contacts' implicit friction (updateContacts) into A's diagonal blocks and its
    // surface-velocity part into mFriction; `keep` false takes it out of A again.
    void syncFriction(const VecX& v0, bool keep);
    void landed();
    void rememberSliding(const VecX& v0, double h);
    void slide(size_t i, double c);
    // The rotation-length projection of the linearised step (rotation_projection.h); with
    // `constraints` in place of the body's own, and per-edge length caps and floors (m), when
    // given.
    void projectRotations(const VecX& x0, const VecX& v0, double h, SubstepStatus& st,
                          bool rotations, double stretchLimit, double tolerance,
                          const Constraints* constraints = nullptr,
                          const std::vector<double>* caps = nullptr,
                          const std::vector<double>* floors = nullptr);
    // What the continuous sweep (step 6) stretched, given back (its neighbours follow a swept
    // vertex); returns the vertices moved.
    int relaxSwept(const VecX& x0, const VecX& v0, const VecX& xBefore, double h,
                   SubstepStatus& st);
    double slipOf(size_t i, const VecX& v0) const;
    int updateContacts(const Environment& env, double t, double h, const VecX& x0, const VecX& v0,
                       SubstepStatus& st);
    int resolveContacts(const Environment& env, double h, SubstepStatus& st);
    // Whether moving mesh `mesh`'s continuous test finds the path x0 → x1 of slot (collider,
    // vertex) ending behind the face it met (deeper than ξ/4 when `deep`); cp that face's plane.
    bool sweptBehind(const MovingMeshContact& mesh, size_t slot, const Vec3& x0, const Vec3& x1,
                     double thick, bool deep, ContactPoint& cp);
    // The closest point of collider k's end pose to vertex i at x, unless the vertex is known to
    // be farther than `beyond` from it (mEndBound): then false, without a query.
    bool endPoseQuery(size_t k, size_t i, const Vec3& x, double beyond, ContactPoint& cp);
    // Collider k, a sphere or a capsule thinner than this body's longest edge, as a degenerate
    // mesh moving over [t, t + h] (its centre, or its axis), for the pairs its vertex contact
    // misses (a rod between two rows of cloth vertices); null for other colliders.
    MovingMeshContact* thinContact(size_t k, const Collider& c, double t, double h);
    // The resting side of a thin collider's edge contacts, at the substep's start
    // (body_contact.cpp).
    void thinEdgePlanes(size_t k, const Collider& c, const ColliderPose& pose, double thick,
                        const std::vector<uint8_t>& nearSurface, double t, double h);
    // A sliding contact for free vertex i at the substep's start on a plane (body_contact.cpp).
    void planeContact(size_t i, int ci, const Vec3& normal, double distance, const Vec3& velocity,
                      double offset, double mu, double t, double h);
    // Whether vertex i's step x₀ → x₁ went through collider k, ending outside (the entry in at,
    // cp).
    bool passedThrough(size_t k, size_t i, const Vec3& xStart, const Vec3& x1, double h,
                       double thick, Vec3& at, ContactPoint& cp);
    void assemble(const ForceInput& in, ForceOutput& out, const Vec3& gravity,
                  bool withMatrix = true);
    // The filtered backward-Euler residual g at Δv into mG (mX, mV, mF, and A when asked, left
    // there); returns max |Aᵢᵢ⁻¹ S gᵢ| (m/s), infinite when not finite.
    double residualAt(const VecX& dv, const VecX& x0, const VecX& v0, double h, ForceInput& in,
                      ForceOutput& out, const Vec3& gravity, bool withMatrix);
    // y = B x, B the skew part of the couplings in mAero (in Newton's iterations, mAeroPosition,
    // all of the Jacobian the assembled A lacks); aeroQuadratic: xᵀ D x of their symmetric part.
    void skewProduct(const VecX& x, VecX& y) const;
    double aeroQuadratic(const VecX& x) const;
    // The linear solve of the step with the assembled matrix and the skew couplings.
    SolveStatus solveLinear(const VecX& b, VecX& dv);
    // Whether no edge at positions x is over-stretched by the trouble detector's rule.
    bool stretchFeasible(const VecX& x) const;
    // Elastic energy (J) and conservative elastic forces f_E = −∇E (N) at positions x.
    double elasticAt(const VecX& x, double t, VecX& fEl);
    void newton(const Environment& env, ForceInput& in, ForceOutput& out, const VecX& x0,
                const VecX& v0, double h, SubstepStatus& st);
    // The trouble detector's over-stretch and velocity-jump rules on the step's end state
    // x₀ + h(v₀ + Δv) + y before contacts (substep(), 7.); `jumpLimit` in m/s.
    Trouble predictedTrouble(const VecX& x0, const VecX& v0, const VecX& dv, double h,
                             double jumpLimit, std::string& reason) const;
    double mNewtonCgTolerance = 0.0; // Environment::retryCgTolerance while a retry runs
    bool mNewtonKeepCoarse = false;  // Environment::retryKeepCoarse while a retry runs

    StepKinematics mKin;      // the substep's scripted motion (evaluateKinematics)
    std::vector<int> mPinned; // vertex per pin
    std::vector<int> mPinSet; // index into mPinSets per pin
    std::vector<PinSet> mPinSets;
    std::vector<std::shared_ptr<const SurfaceBinding>>
        mPinBinding; // per pin: its attachment, or null
    VecX mAnchor;    // 3 per pin: initial position
    // Soft attachments (PinSet::stiffness > 0): free vertices pulled to their bound points.
    struct SoftAttachment {
        int vertex;
        int set; // into mPinSets
        std::shared_ptr<const SurfaceBinding> binding;
    };
    std::vector<SoftAttachment> mSoft;
    double mAssembledH = 0.0; // the step of the last assembled matrix (its springs' h²k)
    // Adds the soft attachments' springs to forces, K v, A and the elastic energy, targets at
    // in.t + in.h (after addForces, wherever it is called).
    void addSoftAttachments(const ForceInput& in, ForceOutput& out, bool matrix) const;
    std::vector<uint8_t> mHeld; // vertices in no element: held in place
    std::vector<std::array<int, 2>> mEdges;
    std::vector<double> mEdgeRest;
    double mLongestRest = 0.0; // the longest of mEdgeRest (m)
    std::vector<double> mDeferDepth; // updateContacts: per vertex, its depth past the surface
    BlockMatrix mA;
    FilteredSolver mSolver;
    double mResidualFloor = 0.0; // N·s: the substep's absolute floor of the PCG residual
    Constraints mConstraints;
    std::vector<double> mContactImpulse; // per vertex: suppressed normal speed (m/s)
    std::vector<int> mContactCollider;   // per vertex: collider holding it in the solve, or -1
    std::vector<uint8_t> mTouching;      // per vertex: touching a collider after the substep
    std::vector<double> mContactSpeed;   // per vertex: the surface's normal speed (m/s)
    std::vector<double> mContactMu;      // per vertex: the holding collider's friction μ
    VecX mFriction;        // 3 per vertex: a sliding contact's friction term in b (N·s)
    VecX mContactVelocity; // 3 per vertex: the surface velocity at the contact (m/s)
    VecX mStickVelocity;   // 3 per vertex: a sticking contact's velocity over the step (m/s)
    std::vector<uint8_t> mReleased;       // per vertex: contact released in this substep
    std::vector<uint8_t> mFoundInside;    // per vertex: its contact came from ending inside
    // Per collider and vertex, within a substep: a lower bound (m) on the distance to the
    // collider's end pose, known at position mEndAt (the distance is 1-Lipschitz in x, so a
    // vertex that moved less than bound − ξ since cannot be within ξ: endPoseQuery()); −1 unknown.
    std::vector<double> mEndBound;
    VecX mEndAt;
    // The same bounds carried to the next substep: its start pose is this one's end pose (time
    // mBoundTime), so a vertex whose distance is known to exceed the contact band needs no query
    // at the start either (contactConstraints).
    std::vector<double> mStartBound;
    VecX mStartAt;
    double mBoundTime = NAN;
    // Per collider and vertex, within a substep: the step's path to mSweptAt ended behind no face
    // of the moving mesh it met (1), or no deeper than updateContacts' re-planing depth (2); 0
    // unknown. updateContacts does not ask the continuous test again for the same end.
    std::vector<uint8_t> mSweptClear;
    VecX mSweptAt;
    // Per collider: its degenerate mesh (thinContact), made when first needed; the candidates of
    // its edge and face tests in the solve's rounds (scratch).
    std::vector<std::shared_ptr<MovingMeshContact>> mThinContacts;
    std::vector<int> mThinCandidates;
    // relaxSwept's scratch: the positions before the sweep, the directions it pushed the
    // vertices it moved, the edges' caps and floors, the constraints with the pushes' planes.
    VecX mSweepX;
    std::vector<Vec3> mSweepNormals;
    std::vector<double> mSweepCaps, mSweepFloors;
    Constraints mSweepConstraints;
    // Per collider and vertex: the moving mesh's triangle its last query found closest (−1
    // none), the hint of its next query (the answer does not depend on it).
    std::vector<int> mNearTriangle;
    std::vector<double> mFrictionDamping; // per vertex: a sliding contact's friction c (kg)
    std::vector<double> mFrictionPrev;    // per vertex: the previous solve's c and slip (secant)
    // Per vertex, from the last substep's end: a contact that slid (slip above 2 ε_v) on
    // collider mSlidOn[i] with friction c = mSlidRate[i] · h (kg; c/h in kg/s), so that the
    // next substep starts it sliding with that friction (contactConstraints). Empty when
    // nothing slid.
    std::vector<double> mSlidRate;
    std::vector<int> mSlidOn;
    // Per vertex: the effective mass (kg) of a sliding contact's slip response, m in
    // slip = p / (m + c), from the secant (updateContacts); carried with mSlidRate.
    std::vector<double> mSlipMass;
    std::vector<double> mFrictionInA;     // per vertex: the c now added to A (kg) ...
    VecX mFrictionAxis;                   // ... about this normal (3 per vertex)
    VecX mYPos; // 3 per vertex: the position alteration y of the contacts (x₁ = x₀ + h v₁ + y)
    VecX mBc, mTmp; // the right-hand side with y's term; scratch
    VecX mWind, mF, mKv, mDv, mDvGuess, mB, mG, mF0, mFel, mGk, mZero;
    std::vector<AeroCoupling> mAero; // the aerodynamic linearisation of the last assembly
    bool mSkewed = false;            // ... with a skew part somewhere
    bool mAeroPosition = false;      // ... with the orientation part (Newton's iterations)
    std::vector<AeroOrientation> mAeroOrientation; // Newton's full Jacobian only
    double mResidual2 = 0.0;     // residualAt()'s 2-norm of the velocity residual (m/s)
    double mStretchBefore = 0.0; // the largest edge stretch at the substep's start
    double mRecoverySpeed = 0.0, mRecoveryStretch = 3.0; // recover()'s limits, set by substep()
    Constraints mZeroZ;         // mConstraints with z = 0 (solveLinear's preconditioner)
    std::vector<Mat3> mDiagInv; // Newton's residual weights (body.cpp, newton())
    double mHGuess = 0.0;
};

} // namespace gale::solver
