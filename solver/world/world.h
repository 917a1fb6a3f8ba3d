// A simulation: bodies, colliders and the summed wind, advanced frame by frame with robust
// substepping — a substep in trouble (non-finite state, the linear solver not converging,
// over-stretch, a velocity jump) is undone and retried at half the step, the reason logged.
#pragma once

#include "fields/field.h"
#include "solver/bodies/body.h"
#include "solver/collider/collider.h"
#include "solver/world/frame_trouble.h"
#include "solver/world/self_collision.h"

#include <memory>
#include <string>
#include <vector>

namespace gale::solver {

struct WorldSettings {
    double fps = 24.0;
    double timeZero = 0.0; // the frame at t = 0 (scene.time_zero): frame F ends at (F − timeZero)/fps
    int substeps = 4;    // per frame, the minimum
    int maxHalvings = 6; // a substep may be split down to 1/2⁶ of its size
    Vec3 gravity = Vec3(0.0, -9.81, 0.0);
    double airDensity = 1.225;  // kg/m³
    int threads = 1;            // 0: all hardware threads; results do not depend on it
    bool noNewtonRetry = false; // tests and benchmarks of the raw halving: no Newton retry
    // The response to a substep whose linearised step over-stretches or jumps a vertex's speed
    // (docs/solver.md, Robust substepping; bench/README.md, issue 26, third pass): at most
    // retryNewtonIterations Newton iterations (0: no retry, halve at once), run inside the
    // substep from its linearised step (Environment::retry*), each correction solved to
    // retryCgTolerance (0: the body's cg_tolerance); retryKeepCoarse: the retry's solves after
    // its first keep that solve's coarse multigrid levels. With retryRepeat the substep is
    // instead run again from its start with that many Newton iterations at full tolerance (the
    // response before issue 26's third pass: 16 iterations, ~20× a median frame's work).
    int retryNewtonIterations = 4;
    double retryCgTolerance = 0.1;
    bool retryKeepCoarse = false;
    bool retryRepeat = false;
    // A halved substep grows back: after two accepted substeps at a level, at a boundary of
    // the next coarser one, the step doubles again (down to the base size); the same for the
    // colliding bodies' interval halved for the self-collision pass. Off: the halved step holds
    // to the end of the frame.
    bool growBack = false;
    // Over-stretch or a velocity jump is answered by strain limiting the step (Body::recover,
    // as at the smallest substep) instead of a retry or halving (measured, not the default).
    bool strainLimitRetry = false;
    // Hair that collides with cloth meets each cloth inside its own solve too (the cloth's motion
    // over the interval as a moving mesh collider, World::clothAsColliders), not only in the
    // self-collision pass after it. Off: the pass alone (measured against it).
    bool hairMeetsClothInSolve = true;
    // Hair through a cloth (a start like that, or a strand that started touching it) is let
    // through where it crosses until it is clear (SelfCollision::setUntangleHair). Off: contact
    // holds it where it crosses (the control).
    bool untangleHair = true;
    // Cloth resting on cloth is held in its own solve too: the self-collision pass's resting
    // vertex–triangle pairs become sliding contact planes of the next interval's solves
    // (SelfCollision::contactPlanes, Body::setClothPlanes), so that the pass after the solve
    // has little left to push. Off: the pass alone (measured against it).
    bool clothContactInSolve = true;
    // The self-collision pass's own settings (self_collision.h; with clothContactInSolve, its
    // planeReach: how far from a pinned side a pair is held in the solve).
    SelfCollisionSettings selfCollision;
};

// Per body, per frame.
struct BodyFrameStats {
    std::string name;
    int substeps = 0;       // accepted substeps
    int rejected = 0;       // substeps undone and retried at half the step
    int recovered = 0;      // substeps at the smallest size recovered by Body::recover
    int newtonRetries = 0;  // substeps in trouble retried with Newton before halving
    int deepestHalving = 0; // 0: every substep at the base size
    long iterations = 0;    // linear-solver iterations, summed over substeps
    int linearSolves = 0;   // linear solves with a fresh matrix, summed (rejected ones too)
    int maxIterations = 0;  // the most in one substep
    double maxResidual = 0.0;
    int newtonIterations = 0;       // Newton corrections after the linearised solves, summed
    int maxNewtonIterations = 0;    // the most in one substep
    double maxNewtonResidual = 0.0; // m/s: the largest velocity residual a substep ended with
    int lineSearchCuts = 0;         // Newton line-search halvings, summed
    int newtonStalled = 0;          // substeps that ended above newton_tolerance
    double maxSpeed = 0.0;          // m/s at the end of the frame
    double maxStretch = 0.0;        // edge length / rest length at the end of the frame
    double minStretch = 1.0;        // the shortest edge's, the same way
    double kinetic = 0.0, elastic = 0.0, potential = 0.0; // J, end of frame
    size_t windNonFinite = 0;
    int clampedJacobians = 0;
    int contacts = 0; // vertices touching colliders at the end of the frame
    // Collider contact in the solve, summed over the frame's accepted substeps (SubstepStatus):
    // contact constraints, added after a solve, released, extra solves; and the projection
    // after the solve: vertices it still moved or stopped, its largest push-out (m) and the
    // largest approach speed it removed (m/s).
    long contactConstraints = 0;
    long clothConstraints = 0; // of contactConstraints: cloth held against cloth in the solve
    // The rotation projection ([solver] rotation_projection): edges it found beyond their target,
    // summed over the substeps, and the largest excess over the target (× rest).
    long rotationEdges = 0;
    double rotationExcess = 0.0;
    int rotationSubsteps = 0; // substeps in which it ran
    int stretchLimitSubsteps = 0; // substeps the strain limit ([solver] stretch_limit) acted in
    int contactAdded = 0, contactReleases = 0, contactSlides = 0, contactSolves = 0, projected = 0,
        contactsThrough = 0;
    double projectedDistance = 0.0, projectedSpeed = 0.0;
    int sweepRelaxed = 0; // vertices moved to give back what the sweep stretched (strands)
    // Intersecting triangle pairs with a triangle of this body at the end of the frame, counted
    // when it takes part in cloth–cloth collision (−1: not counted).
    int selfIntersections = -1;
    std::vector<std::string> events; // substep halvings and recoveries, with reasons
    // What the frame ends with beyond over_stretch or inside a collider (also in `events`).
    std::vector<FrameTrouble> trouble;
    bool failed = false;             // non-finite state that halving could not fix (state restored)
};

struct FrameStats {
    int frame = 0;
    double time = 0.0; // seconds at the end of the frame
    double wallSeconds = 0.0;
    std::vector<BodyFrameStats> bodies;
    bool failed = false;
    bool selfCollision = false;      // some bodies collide with themselves and each other
    SelfCollisionStats selfContacts; // ... their passes over the frame
};

class World {
public:
    explicit World(WorldSettings settings);
    ~World();

    const WorldSettings& settings() const { return mSettings; }
    void setWind(fields::FieldPtr wind) { mWind = std::move(wind); }
    const fields::FieldPtr& wind() const { return mWind; }
    void addBody(std::unique_ptr<Body> body) { mBodies.push_back(std::move(body)); }
    void addCollider(Collider c) { mColliders.push_back(std::move(c)); }
    const std::vector<std::unique_ptr<Body>>& bodies() const { return mBodies; }
    Body& body(size_t i) { return *mBodies[i]; }
    const std::vector<Collider>& colliders() const { return mColliders; }

    // Advances every body from frame − 1 to `frame` (times (frame − 1)/fps → frame/fps).
    FrameStats advanceFrame(int frame);
    // Advances by one interval [t0, t0 + dt] split into `substeps` base substeps.
    FrameStats advance(double t0, double dt, int substeps);

    // The complete state (positions, velocities, warm starts) as bytes, and back: a run
    // resumed from it continues bit for bit. Returns false with `error` on a mismatch.
    std::string saveState() const;
    bool loadState(const std::string& bytes, std::string& error);

    // Cloth–cloth collision of the bodies with collision().self (null when none has it); set
    // up on the first advance.
    const SelfCollision* selfCollision() const { return mSelf.get(); }

private:
    // Where a body's frame stepping stands: ticks of the finest substep done, halving level,
    // substep index, stopped by a failure.
    struct BodyRun {
        long tick = 0;
        int level = 0;
        int index = 0;
        int streak = 0; // substeps accepted at `level` since it last changed
        bool stopped = false;
    };
    void advanceBody(Body& body, double t0, double dt, int substeps, BodyFrameStats& stats);
    // Steps `body` until `run.tick` reaches `untilTick` (ticks: 2^maxHalvings per base substep).
    // `colliders`: what the body collides with (null: the scene's colliders).
    void stepBody(Body& body, double t0, double dt, int substeps, long untilTick, BodyRun& run,
                  BodyFrameStats& stats, const std::vector<Collider>* colliders = nullptr);
    void finishBodyStats(Body& body, double t1, BodyFrameStats& stats) const;
    void setUpSelfCollision(FrameStats& fs);
    void advanceColliding(double t0, double dt, int substeps, FrameStats& fs);
    // The colliding cloth's motion over the interval [t0, t1] (from `starts`, their positions
    // now) into mClothContacts, for the hair's solves.
    void clothAsColliders(const std::vector<VecX>& starts, double t0, double t1);
    // What the body k of mSelfBodies collides with in its solve when it is a hair that meets
    // some cloth there (mHairColliders); null: the scene's colliders.
    const std::vector<Collider>* hairColliders(size_t k) const;

    WorldSettings mSettings;
    fields::FieldPtr mWind;
    std::vector<std::unique_ptr<Body>> mBodies;
    std::vector<Collider> mColliders;
    struct Arena;
    std::unique_ptr<Arena> mArena;
    std::unique_ptr<SelfCollision> mSelf;
    std::vector<size_t> mSelfBodies; // indices of the bodies in mSelf, in its order
    bool mSelfSetUp = false;
    // Hair against the colliding cloth inside the hair's own solve, not only in the pass after
    // it: the bodies of mSelfBodies step cloth first, so within an interval each cloth's motion
    // is solved before the hair steps, and the hair collides with it as with a moving mesh
    // (moving_collider.h: contact constraints in the solve, the continuous sweep after it).
    // mClothBodies: how many of mSelfBodies are cloth (the first ones); mClothContacts: one
    // per cloth; mHairColliders: per hair (mSelfBodies after the cloth), the scene's colliders
    // then the cloth it is light against (empty: none, the pass alone).
    size_t mClothBodies = 0;
    std::vector<std::shared_ptr<MovingMeshContact>> mClothContacts;
    std::vector<std::vector<Collider>> mHairColliders;
    // Per colliding body (mSelfBodies), the cloth contact planes of the last accepted pass.
    std::vector<std::vector<ClothContactPlane>> mClothPlanes;
};

} // namespace gale::solver
