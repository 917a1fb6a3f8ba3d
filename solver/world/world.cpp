// Frame stepping with substep halving (as production cloth solvers do on trouble), per-frame
// statistics, and the binary state used by `gale sim --resume`.
#include "solver/world/world.h"

#include "solver/collider/moving_collider.h"
#include "solver/mesh/mesh_sequence.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

namespace gale::solver {

namespace {
// A self-collision pass that leaves an edge longer than kPassStretch × its rest length and
// kPassStretchGrowth × what the solve left has its interval redone at half the step.
constexpr double kPassStretch = 1.1;
constexpr double kPassStretchGrowth = 1.05;
// A halved interval whose pass still adds more than this fraction of what the pass added before
// the halving is not halved again (World::advanceColliding).
constexpr double kPassHalvingGain = 0.75;
// A hair meets a cloth in its own solve only when it weighs at most this share of the cloth.
constexpr double kHairMassShare = 0.05;
} // namespace

struct World::Arena {
    tbb::task_arena arena;
    explicit Arena(int threads) : arena(threads) {}
};

World::World(WorldSettings settings) : mSettings(std::move(settings)) {
    int threads = mSettings.threads;
    if (threads <= 0) threads = tbb::info::default_concurrency();
    mSettings.threads = threads;
    mArena = std::make_unique<Arena>(threads);
}

World::~World() = default;

FrameStats World::advanceFrame(int frame) {
    FrameStats fs = advance((frame - 1 - mSettings.timeZero) / mSettings.fps, 1.0 / mSettings.fps,
                            mSettings.substeps);
    fs.frame = frame;
    return fs;
}

FrameStats World::advance(double t0, double dt, int substeps) {
    FrameStats fs;
    fs.time = t0 + dt;
    const auto start = std::chrono::steady_clock::now();
    fs.bodies.resize(mBodies.size());
    substeps = std::max(substeps, 1);
    mArena->arena.execute([&] {
        if (!mSelfSetUp) setUpSelfCollision(fs);
        if (mSelf) advanceColliding(t0, dt, substeps, fs);
        for (size_t b = 0; b < mBodies.size(); ++b) {
            if (mSelf && std::find(mSelfBodies.begin(), mSelfBodies.end(), b) != mSelfBodies.end())
                continue;
            advanceBody(*mBodies[b], t0, dt, substeps, fs.bodies[b]);
        }
        for (const BodyFrameStats& b : fs.bodies) fs.failed = fs.failed || b.failed;
    });
    fs.wallSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return fs;
}

void World::setUpSelfCollision(FrameStats& fs) {
    mSelfSetUp = true;
    auto self = std::make_unique<SelfCollision>(mSettings.selfCollision);
    for (size_t b = 0; b < mBodies.size(); ++b) {
        Body& body = *mBodies[b];
        const auto* tris = body.collisionTriangles();
        if (!body.collision().self || !tris) continue;
        self->addBody(body, *tris, body.restPositions(), body.collision().thickness);
        mSelfBodies.push_back(b);
    }
    if (mSelfBodies.empty()) return;
    mClothBodies = mSelfBodies.size();
    // Hair that collides with cloth (collision().self on a body without triangles) joins the
    // pass when some cloth is in it: its segments against the cloth's triangles and edges.
    static const std::vector<std::array<int, 3>> kNone;
    for (size_t b = 0; b < mBodies.size(); ++b) {
        Body& body = *mBodies[b];
        if (!body.collision().self || body.collisionTriangles()) continue;
        self->addBody(body, kNone, body.restPositions(), body.collision().thickness);
        mSelfBodies.push_back(b);
    }
    mSelf = std::move(self);
    // Each cloth as a moving mesh a hair collides with in its solve (mClothContacts), where the
    // hair is light against it (kHairMassShare: the cloth does not feel the hair in its solve);
    // per hair, its list (mHairColliders). The thickness the pass keeps between the two (the
    // larger ξ of a pair's vertices); no friction, as in the pass.
    if (mSelfBodies.size() > mClothBodies && mSettings.hairMeetsClothInSolve) {
        const auto mass = [](const Body& b) { return b.masses().sum(); };
        for (size_t k = 0; k < mClothBodies; ++k) {
            const Body& cloth = *mBodies[mSelfBodies[k]];
            const VecX& x = cloth.positions();
            std::vector<double> p(x.data(), x.data() + x.size());
            auto seq = std::make_shared<const MeshSequence>(
                *cloth.collisionTriangles(), std::vector<std::vector<double>>{p}, 0, 24.0);
            auto contact = std::make_shared<MovingMeshContact>(seq);
            contact->setOpenSurface(true);
            mClothContacts.push_back(std::move(contact));
        }
        mHairColliders.assign(mSelfBodies.size() - mClothBodies, {});
        for (size_t h = mClothBodies; h < mSelfBodies.size(); ++h) {
            const Body& hair = *mBodies[mSelfBodies[h]];
            std::vector<Collider>& list = mHairColliders[h - mClothBodies];
            for (size_t k = 0; k < mClothBodies; ++k) {
                const Body& cloth = *mBodies[mSelfBodies[k]];
                if (!(mass(hair) <= kHairMassShare * mass(cloth))) continue;
                if (list.empty()) list = mColliders;
                Collider c;
                c.name = cloth.name();
                c.shape = ColliderShape::Mesh;
                c.moving = mClothContacts[k];
                c.thickness = std::max(hair.collision().thickness, cloth.collision().thickness);
                c.friction = 0.0;
                list.push_back(std::move(c));
            }
        }
    }
    // A start that already intersects cannot be untangled; the passes keep it from worsening.
    const std::vector<int> start = mSelf->intersectionsPerBody();
    char buf[512];
    for (size_t k = 0; k < mSelfBodies.size(); ++k) {
        if (start[k] == 0) continue;
        std::snprintf(buf, sizeof buf,
                      "self-collision: the start shape has %d intersecting triangle pair(s); "
                      "they are kept from getting worse but not undone (untangle the mesh to "
                      "remove them)",
                      start[k]);
        fs.bodies[mSelfBodies[k]].events.push_back(buf);
    }
    // A hair that starts through a cloth (segments crossing its triangles): reported, and let
    // through the cloth where it crosses until it is clear (SelfCollision::setUntangleHair):
    // contact would hold each such segment where it crosses, and a cloth moving away then drags
    // the strand (the hard scenes' hair at 6-70×: docs/solver.md).
    // Every pass looks for hair through cloth, not only after such a start: a strand that starts
    // touching a cloth (no side to keep) can end a step through it, and is then let through too.
    if (mSettings.untangleHair && mSelfBodies.size() > mClothBodies) mSelf->setUntangleHair(true);
    for (size_t h = mClothBodies; h < mSelfBodies.size(); ++h) {
        const Body& hair = *mBodies[mSelfBodies[h]];
        for (size_t k = 0; k < mClothBodies; ++k) {
            const Body& cloth = *mBodies[mSelfBodies[k]];
            const HairThroughCloth through = hairThroughCloth(hair, cloth);
            if (through.segments == 0) continue;
            mSelf->markTangled(h);
            std::snprintf(buf, sizeof buf,
                          "hair-cloth collision: the start shape has %d segment(s) through cloth "
                          "'%s' (the first, %d-%d, at (%.4g, %.4g, %.4g)); the strands are let "
                          "through the cloth there until they are clear of it (start the hair "
                          "clear of the cloth to keep it on its side)",
                          through.segments, cloth.name().c_str(), through.a, through.b,
                          through.at.x(), through.at.y(), through.at.z());
            fs.bodies[mSelfBodies[h]].events.push_back(buf);
        }
    }
}

// The colliding bodies advance in lockstep, one base substep at a time (each with its own
// halving inside it), then one self-collision pass over the straight path from the substep's
// start to its end (self_collision.h): the end state has no crossing the start did not have.
void World::advanceColliding(double t0, double dt, int substeps, FrameStats& fs) {
    fs.selfCollision = true;
    const int maxLevel = std::clamp(mSettings.maxHalvings, 0, 20);
    const long ticksPerBase = 1L << maxLevel;
    const long totalTicks = ticksPerBase * substeps;
    const size_t n = mSelfBodies.size();
    std::vector<BodyRun> runs(n);
    std::vector<VecX> starts(n);
    std::vector<Body::Snapshot> snaps(n);
    std::vector<double> stretchBefore(n);
    char buf[320];
    // Collisions resolved at the end of a substep move positions without the implicit solve
    // seeing it: a fast impact at a long substep then stretches cloth (stored energy the contact
    // never had). When a pass stretches an edge beyond both kPassStretch and kPassStretchGrowth
    // × what the solve left (or beyond the over-stretch limit), the colliding bodies redo that
    // interval at half the step, as the solver halves a substep in trouble; the level holds for the
    // rest of the frame (or grows back, WorldSettings::growBack).
    int level = 0;
    int streak = 0; // passes accepted at `level` since it last changed
    // What the pass added to the stretch (its edge's stretch over the solve's) when it last had
    // the interval halved: a halving is worth its cost only while it cuts that. A hair pressed
    // between a cape and the body (the cape does not feel the hair) is stretched by the pass as
    // much at every step: three halvings there left it as stretched and made the frame cost 6×
    // the median. A pass at a halved level that adds more than kPassHalvingGain × what the last
    // halving's pass added is accepted (an event says so), unless it is over the limit.
    double lastPassExcess = std::numeric_limits<double>::infinity();
    // The vertices the pass pushed through a moving body when that last had the interval halved.
    int lastPushedIn = std::numeric_limits<int>::max();
    // The cloth planes of the interval's solves: the last accepted pass's, and on a retry the
    // rejected pass's pairs before them.
    std::vector<std::vector<ClothContactPlane>> held = mClothPlanes;
    bool retried = false; // this interval's solve was done again with the pass's pairs
    long tick = 0;
    while (tick < totalTicks) {
        const long end = std::min(totalTicks, tick + (ticksPerBase >> level));
        std::vector<BodyRun> runsBefore = runs;
        const double tStart = t0 + dt * static_cast<double>(tick) / static_cast<double>(totalTicks);
        const double tEnd = t0 + dt * static_cast<double>(end) / static_cast<double>(totalTicks);
        bool movedCloth = false; // mClothContacts hold this interval's motion
        for (size_t k = 0; k < n; ++k) {
            Body& body = *mBodies[mSelfBodies[k]];
            snaps[k] = body.snapshot();
            starts[k] = body.positions();
            runs[k].level = std::max(runs[k].level, level);
            // A hair that meets cloth in its solve: against the cloth's motion of this interval,
            // solved just above.
            const std::vector<Collider>* own = hairColliders(k);
            if (own) {
                if (!movedCloth) clothAsColliders(starts, tStart, tEnd);
                movedCloth = true;
                body.forgetColliderBounds(); // the cloth's motion is new each interval
            }
            if (k < mClothBodies && k < held.size()) body.setClothPlanes(held[k]);
            stepBody(body, t0, dt, substeps, end, runs[k], fs.bodies[mSelfBodies[k]], own);
            stretchBefore[k] = body.maxEdgeStretch();
        }
        // The cloth as its solve and the colliders' passes left it (the pass after it moves
        // vertices that no collider saw).
        bool moving = false;
        for (const Collider& c : mColliders) moving = moving || c.moving;
        std::vector<VecX> solved, solvedV;
        if (moving)
            for (size_t k = 0; k < n && k < mClothBodies; ++k) {
                solved.push_back(mBodies[mSelfBodies[k]]->positions());
                solvedV.push_back(mBodies[mSelfBodies[k]]->velocities());
            }
        const SelfCollisionStats st = mSelf->resolve(starts);
        fs.selfContacts.add(st);
        bool stretched = false;
        bool overLimit = false;
        double worst = 0.0;
        double excess = 0.0;   // the most the pass added to a stretched body's stretch
        std::string worstName; // the body the pass stretched most (cloth or hair)
        for (size_t k = 0; k < n; ++k) {
            Body& body = *mBodies[mSelfBodies[k]];
            const double after = body.maxEdgeStretch();
            if (after > worst) {
                worst = after;
                worstName = body.name();
            }
            // Beyond the over-stretch limit too, but up to twice it only where the pass grew the
            // stretch: a cape in 22-26 m/s gusts whose solve leaves edges near the limit (1.45)
            // and whose pass adds a hair (1.50) was halved 25-38 times and solved again 290-430
            // times (5-7× the run without self-collision) for a frame ending 1.495 against 1.518.
            const double limit = body.limits().overStretch;
            const bool over = (after > limit && after > kPassStretchGrowth * stretchBefore[k]) ||
                              after > 2.0 * limit;
            if ((after > kPassStretch && after > kPassStretchGrowth * stretchBefore[k]) || over) {
                stretched = true;
                overLimit = overLimit || over;
                excess = std::max(excess, after - stretchBefore[k]);
            }
        }
        // A pass that pushed cloth through a moving body's surface (a fold pressed between the
        // cloth and a turning head: its corrections moved vertices into the body, which nothing
        // pushed out again, and the cape stayed inside the head for the rest of the shot) is
        // answered as a pass that stretched: the interval again at half the step, whose smaller
        // motions the pass corrects less.
        int pushedIn = 0;
        std::vector<std::vector<int>> through(solved.size()); // per cloth body, those vertices
        for (size_t k = 0; k < solved.size(); ++k)
            for (const Collider& c : mColliders)
                if (c.moving && std::abs(c.moving->t1() - tEnd) <= 1e-9 * std::max(1.0, tEnd))
                    pushedIn += c.moving->movesThroughSurface(
                        solved[k], mBodies[mSelfBodies[k]]->positions(), &through[k]);
        // The interval undone and redone at half the step, the event `why` (its halved step
        // appended) for every colliding body.
        const auto halve = [&](const std::string& why) {
            for (size_t k = 0; k < n; ++k) {
                mBodies[mSelfBodies[k]]->restore(snaps[k]);
                BodyFrameStats& stats = fs.bodies[mSelfBodies[k]];
                ++stats.rejected;
                stats.deepestHalving = std::max(stats.deepestHalving, level + 1);
            }
            runs = runsBefore;
            ++level;
            streak = 0;
            held = mClothPlanes;
            retried = false;
            ++fs.selfContacts.halvings;
            std::snprintf(buf, sizeof buf, "t=%.6g s: %s; substep halved to %.6g s", tEnd,
                          why.c_str(), dt / substeps / static_cast<double>(1L << level));
            for (size_t b : mSelfBodies) fs.bodies[b].events.push_back(buf);
        };
        if (pushedIn > 0 && level < maxLevel && (level == 0 || pushedIn < lastPushedIn)) {
            lastPushedIn = pushedIn;
            halve("self-collision pushed " + std::to_string(pushedIn) +
                  " cloth vertex(es) through a moving body's surface");
            continue;
        }
        // Not halved again: the pass accepted but for those vertices, which keep the position
        // and velocity the solve gave them (outside the body). A vertex left inside it is not
        // pushed out reliably: the nearest surface of a thin part can be its far side (the storm
        // cape of cli:cape_storm_body, so accepted at frame 1061, stayed caught inside the body for
        // the rest of the shot).
        if (pushedIn > 0) {
            for (size_t k = 0; k < through.size(); ++k) {
                if (through[k].empty()) continue;
                Body& body = *mBodies[mSelfBodies[k]];
                VecX x = body.positions(), v = body.velocities();
                for (int i : through[k]) {
                    x.segment<3>(3 * i) = solved[k].segment<3>(3 * i);
                    v.segment<3>(3 * i) = solvedV[k].segment<3>(3 * i);
                }
                body.setPositions(x);
                body.setVelocities(v);
            }
            std::snprintf(buf, sizeof buf,
                          "t=%.6g s: self-collision pushed %d cloth vertex(es) through a moving "
                          "body's surface at a step halved %d time(s), no fewer than before the "
                          "last halving: accepted, those vertices kept as the solve left them",
                          tEnd, pushedIn, level);
            for (size_t b : mSelfBodies) fs.bodies[b].events.push_back(buf);
        }
        // First, the same interval again with the pairs the pass found as contact planes in
        // its solve (SelfCollision::retryPlanes): the solve then holds them and spreads what the
        // pass would have done to one vertex over the cloth round it. A vertex the solve left
        // passing through a face (it came within ξ and went on) is what stretches the cloth when
        // the pass pushes it back alone.
        if (stretched && !retried && mSettings.clothContactInSolve) {
            std::vector<VecX> startV(n);
            for (size_t k = 0; k < n; ++k) startV[k] = snaps[k].v;
            const std::vector<std::vector<ClothContactPlane>> planes = mSelf->retryPlanes(startV);
            bool any = false;
            for (size_t k = 0; k < n && k < mClothBodies && k < planes.size(); ++k)
                any = any || !planes[k].empty();
            retried = true;
            if (any) {
                held.resize(std::max(held.size(), planes.size()));
                for (size_t k = 0; k < n; ++k) {
                    mBodies[mSelfBodies[k]]->restore(snaps[k]);
                    if (k < planes.size())
                        held[k].insert(held[k].begin(), planes[k].begin(), planes[k].end());
                }
                runs = runsBefore;
                ++fs.selfContacts.retries;
                continue;
            }
        }
        if (stretched && level < maxLevel &&
            (overLimit || level == 0 || excess <= kPassHalvingGain * lastPassExcess)) {
            char what[160];
            std::snprintf(what, sizeof what,
                          "self-collision stretched '%s' to %.3g × its rest length",
                          worstName.c_str(), worst);
            lastPassExcess = excess;
            halve(what);
            continue;
        }
        if (stretched && level < maxLevel && !overLimit) {
            std::snprintf(buf, sizeof buf,
                          "t=%.6g s: self-collision stretched '%s' to %.3g × its rest length "
                          "(+%.3g) at a step halved %d time(s), as much as before the last "
                          "halving (+%.3g): accepted, not halved again",
                          tEnd, worstName.c_str(), worst, excess, level, lastPassExcess);
            for (size_t b : mSelfBodies) fs.bodies[b].events.push_back(buf);
        }
        if (st.unresolved > 0) {
            std::snprintf(buf, sizeof buf,
                          "t=%.6g s: self-collision left %lld pair(s) unresolved after the "
                          "fail-safe (pins or attachments moving apart inside an impact zone)",
                          tEnd, st.unresolved);
            for (size_t b : mSelfBodies) fs.bodies[b].events.push_back(buf);
        }
        if (mSettings.clothContactInSolve) mClothPlanes = mSelf->contactPlanes();
        held = mClothPlanes;
        retried = false;
        tick = end;
        // Grow back (WorldSettings::growBack), as stepBody does: two accepted passes at this
        // level and a boundary of the coarser one.
        ++streak;
        if (mSettings.growBack && level > 0 && streak >= 2 &&
            tick % (ticksPerBase >> (level - 1)) == 0) {
            --level;
            streak = 0;
        }
    }
    const std::vector<int> pairs = mSelf->intersectionsPerBody();
    for (size_t k = 0; k < mSelfBodies.size(); ++k) {
        BodyFrameStats& stats = fs.bodies[mSelfBodies[k]];
        finishBodyStats(*mBodies[mSelfBodies[k]], t0 + dt, stats);
        stats.selfIntersections = pairs[k];
    }
}

const std::vector<Collider>* World::hairColliders(size_t k) const {
    if (k < mClothBodies || k - mClothBodies >= mHairColliders.size()) return nullptr;
    // A hair through cloth at the last pass's start (or the run's) keeps its solve off the cloth.
    if (mSelf && mSelf->untanglingHair() && mSelf->tangledBodies()[k]) return nullptr;
    const std::vector<Collider>& list = mHairColliders[k - mClothBodies];
    return list.empty() ? nullptr : &list;
}

void World::clothAsColliders(const std::vector<VecX>& starts, double t0, double t1) {
    // Two frames, at t0 and t1: fps = 1/(t1 − t0), frame 0 at t0 (MeshSequence's frame F is at
    // (F − frameZero)/fps).
    const double fps = 1.0 / (t1 - t0);
    for (size_t k = 0; k < mClothContacts.size(); ++k) {
        const Body& cloth = *mBodies[mSelfBodies[k]];
        const VecX& x0 = starts[k];
        const VecX& x1 = cloth.positions();
        std::vector<std::vector<double>> frames{{x0.data(), x0.data() + x0.size()},
                                                {x1.data(), x1.data() + x1.size()}};
        mClothContacts[k]->setMesh(std::make_shared<const MeshSequence>(
            mClothContacts[k]->mesh().triangles(), std::move(frames), 0, fps, -t0 * fps));
    }
}

void World::advanceBody(Body& body, double t0, double dt, int substeps, BodyFrameStats& stats) {
    BodyRun run;
    const long ticksPerBase = 1L << std::clamp(mSettings.maxHalvings, 0, 20);
    stepBody(body, t0, dt, substeps, ticksPerBase * substeps, run, stats);
    finishBodyStats(body, t0 + dt, stats);
}

void World::stepBody(Body& body, double t0, double dt, int substeps, long untilTick, BodyRun& run,
                     BodyFrameStats& stats, const std::vector<Collider>* colliders) {
    stats.name = body.name();
    const int maxLevel = std::clamp(mSettings.maxHalvings, 0, 20);
    const long ticksPerBase = 1L << maxLevel;
    const double hBase = dt / substeps;
    Environment env;
    env.wind = mWind.get();
    env.airDensity = mSettings.airDensity;
    env.gravity = mSettings.gravity;
    env.colliders = colliders ? colliders : &mColliders;
    env.fps = mSettings.fps;
    env.frameZero = mSettings.timeZero;
    env.threads = mSettings.threads;
    const bool inSubstep = !mSettings.retryRepeat && !mSettings.noNewtonRetry;
    env.retryNewtonIterations = inSubstep ? std::max(mSettings.retryNewtonIterations, 0) : 0;
    env.retryCgTolerance = mSettings.retryCgTolerance;
    env.retryKeepCoarse = mSettings.retryKeepCoarse;
    long& tick = run.tick;
    int& level = run.level;
    int& index = run.index;
    char buf[512];
    while (tick < untilTick && !run.stopped) {
        const double h = hBase / static_cast<double>(1L << level);
        const double t =
            t0 + hBase * (static_cast<double>(tick) / static_cast<double>(ticksPerBase));
        env.substepIndex = index;
        const Body::Snapshot snap = body.snapshot();
        SubstepStatus st = body.substep(env, t, h);
        if (st.retried != Trouble::None) {
            ++stats.newtonRetries;
            // (No Newton iteration: the retry's line search along the linearised step, cut
            // st.lineSearchCuts times, already met the residual's tolerance.)
            char how[96];
            if (st.newtonIterations > 0)
                std::snprintf(how, sizeof how, "with %d Newton iteration(s)", st.newtonIterations);
            else
                std::snprintf(how, sizeof how,
                              "by its line search alone (the step cut %d time(s), no Newton "
                              "iteration needed)",
                              st.lineSearchCuts);
            std::snprintf(buf, sizeof buf, "t=%.6g s: %s (%s); substep retried %s: %s", t,
                          troubleName(st.retried), st.retryReason.c_str(), how,
                          st.trouble == Trouble::None ? "accepted" : "still in trouble");
            stats.events.push_back(buf);
        }
        if (mSettings.strainLimitRetry &&
            (st.trouble == Trouble::OverStretch || st.trouble == Trouble::VelocityJump)) {
            const int fixes = body.recover(snap, h);
            ++stats.recovered;
            std::snprintf(buf, sizeof buf,
                          "t=%.6g s: %s (%s); strain limited (%d edge correction(s))", t,
                          troubleName(st.trouble), st.reason.c_str(), fixes);
            stats.events.push_back(buf);
            if (body.positions().allFinite() && body.velocities().allFinite())
                st.trouble = Trouble::None;
        }
        // WorldSettings::retryRepeat (the response before issue 26's third pass; by default the
        // retry runs inside Body::substep, above): over-stretch or a velocity jump from the
        // linearised step first runs the same substep again with Newton's line search (which
        // cuts a step that over-stretches), then halving.
        const int newton = body.options().newtonIterations;
        const int kRetryNewtonIterations = mSettings.retryNewtonIterations;
        if ((st.trouble == Trouble::OverStretch || st.trouble == Trouble::VelocityJump) &&
            newton < kRetryNewtonIterations && !mSettings.noNewtonRetry && mSettings.retryRepeat) {
            std::snprintf(buf, sizeof buf,
                          "t=%.6g s: %s (%s); substep retried with %d Newton iterations", t,
                          troubleName(st.trouble), st.reason.c_str(), kRetryNewtonIterations);
            body.restore(snap);
            // The retry wants the line search's cut of an over-stretching step, not convergence:
            // the SPD linearisation of each iterate (no GMRES on the full Jacobian).
            const bool full = body.options().newtonFullJacobian;
            body.options().newtonIterations = kRetryNewtonIterations;
            body.options().newtonFullJacobian = false;
            const int firstIterations = st.iterations;
            const int firstSolves = st.linearSolves;
            st = body.substep(env, t, h);
            body.options().newtonIterations = newton;
            body.options().newtonFullJacobian = full;
            st.iterations += firstIterations;
            st.linearSolves += firstSolves;
            ++stats.newtonRetries;
            stats.events.push_back(std::string(buf) + (st.trouble == Trouble::None
                                                           ? ": accepted"
                                                           : ": still in trouble"));
        }
        stats.iterations += st.iterations;
        stats.linearSolves += st.linearSolves;
        stats.maxIterations = std::max(stats.maxIterations, st.iterations);
        stats.maxResidual = std::max(stats.maxResidual, st.residual);
        stats.clampedJacobians += st.clampedJacobians;
        stats.newtonIterations += st.newtonIterations;
        stats.maxNewtonIterations = std::max(stats.maxNewtonIterations, st.newtonIterations);
        stats.lineSearchCuts += st.lineSearchCuts;
        stats.maxNewtonResidual = std::max(stats.maxNewtonResidual, st.newtonResidual);
        if (st.newtonStalled) ++stats.newtonStalled;
        if (st.windNonFinite) {
            if (stats.windNonFinite == 0) {
                std::snprintf(buf, sizeof buf, "t=%.6g s: wind: %s", t, st.windMessage.c_str());
                stats.events.push_back(buf);
            }
            stats.windNonFinite += st.windNonFinite;
        }
        if (st.trouble != Trouble::None) {
            if (level < maxLevel) {
                body.restore(snap);
                ++level;
                run.streak = 0;
                ++stats.rejected;
                stats.deepestHalving = std::max(stats.deepestHalving, level);
                std::snprintf(buf, sizeof buf, "t=%.6g s: %s (%s); substep halved to %.6g s", t,
                              troubleName(st.trouble), st.reason.c_str(), hBase / (1L << level));
                stats.events.push_back(buf);
                continue;
            }
            // At the smallest substep: recover (speeds capped, strain limited) rather
            // than give up; the state stays finite and bounded.
            const int fixes = body.recover(snap, h);
            ++stats.recovered;
            std::snprintf(buf, sizeof buf,
                          "t=%.6g s: %s (%s) at the smallest substep %.6g s; recovered by strain "
                          "limiting (%d edge correction(s)) and a speed cap",
                          t, troubleName(st.trouble), st.reason.c_str(), h, fixes);
            stats.events.push_back(buf);
            if (!body.positions().allFinite() || !body.velocities().allFinite()) {
                body.restore(snap);
                stats.failed = true;
                stats.events.push_back("run failed: the recovered state is not finite");
                run.stopped = true;
                break;
            }
        }
        tick += ticksPerBase >> level;
        stats.contacts = st.contacts;
        stats.contactConstraints += st.contactConstraints;
        stats.clothConstraints += st.clothConstraints;
        stats.rotationEdges += st.rotationEdges;
        stats.rotationExcess = std::max(stats.rotationExcess, st.rotationExcess);
        stats.rotationSubsteps += st.rotationProjected ? 1 : 0;
        stats.stretchLimitSubsteps += st.stretchLimited ? 1 : 0;
        stats.contactAdded += st.contactAdded;
        stats.contactsThrough += st.contactsThrough;
        stats.contactReleases += st.contactReleases;
        stats.contactSlides += st.contactSlides;
        stats.contactSolves += st.contactSolves;
        stats.projected += st.projected;
        stats.sweepRelaxed += st.sweepRelaxed;
        stats.projectedDistance = std::max(stats.projectedDistance, st.projectedDistance);
        stats.projectedSpeed = std::max(stats.projectedSpeed, st.projectedSpeed);
        ++stats.substeps;
        ++index;
        // Grow back (WorldSettings::growBack): two accepted substeps at this level and a
        // boundary of the coarser one.
        ++run.streak;
        if (mSettings.growBack && level > 0 && run.streak >= 2 &&
            tick % (ticksPerBase >> (level - 1)) == 0) {
            --level;
            run.streak = 0;
        }
    }
}

void World::finishBodyStats(Body& body, double t1, BodyFrameStats& stats) const {
    stats.maxSpeed = 0.0;
    const VecX& v = body.velocities();
    for (size_t i = 0; i < body.vertexCount(); ++i)
        stats.maxSpeed = std::max(stats.maxSpeed, vec3At(v.data(), i).norm());
    stats.maxStretch = body.maxEdgeStretch();
    stats.minStretch = body.minEdgeStretch();
    stats.kinetic = body.kineticEnergy();
    stats.potential = body.potentialEnergy(mSettings.gravity);
    stats.elastic = body.elasticEnergy(t1);
    if (stats.failed) return;
    findFrameTrouble(body, mColliders, t1, body.limits().overStretch, stats.trouble,
                     t1 - 1.0 / mSettings.fps);
    for (const FrameTrouble& tr : stats.trouble) stats.events.push_back("trouble: " + tr.text());
}

// ---- state bytes: "GALESTATE" v1, then per body: name, vertex count, x, v, Δv guess, h guess.

namespace {
void putU64(std::string& s, uint64_t v) {
    s.append(reinterpret_cast<const char*>(&v), 8);
}
void putVec(std::string& s, const VecX& v) {
    putU64(s, static_cast<uint64_t>(v.size()));
    if (v.size() > 0) s.append(reinterpret_cast<const char*>(v.data()), sizeof(double) * v.size());
}
struct Reader {
    const std::string& s;
    size_t pos = 0;
    bool ok = true;
    uint64_t u64() {
        uint64_t v = 0;
        if (pos + 8 > s.size()) {
            ok = false;
            return 0;
        }
        std::memcpy(&v, s.data() + pos, 8);
        pos += 8;
        return v;
    }
    VecX vec() {
        const uint64_t n = u64();
        if (!ok || n > (s.size() - pos) / sizeof(double)) {
            ok = false;
            return VecX();
        }
        VecX v(static_cast<long>(n));
        if (n > 0)
            std::memcpy(v.data(), s.data() + pos, sizeof(double) * n); // data() is null when empty
        pos += sizeof(double) * n;
        return v;
    }
};
} // namespace

// GALESTATE2: per body its name, x, v, the warm start (Δv, h) and the sliding contacts' friction
// carried to the next substep (rate, response mass, collider index or −1; empty when nothing
// slid); GALESTATE1 (no carry) is read as well.
std::string World::saveState() const {
    std::string s = "GALESTATE2";
    putU64(s, mBodies.size());
    for (const auto& b : mBodies) {
        putU64(s, b->name().size());
        s += b->name();
        const Body::Snapshot snap = b->snapshot();
        putVec(s, snap.x);
        putVec(s, snap.v);
        putVec(s, snap.dvGuess);
        double h = snap.hGuess;
        s.append(reinterpret_cast<const char*>(&h), sizeof h);
        const auto toVec = [](const auto& a) {
            VecX v(static_cast<long>(a.size()));
            for (size_t k = 0; k < a.size(); ++k) v[static_cast<long>(k)] = double(a[k]);
            return v;
        };
        putVec(s, toVec(snap.slidRate));
        putVec(s, toVec(snap.slipMass));
        putVec(s, toVec(snap.slidOn));
    }
    return s;
}

bool World::loadState(const std::string& bytes, std::string& error) {
    const bool carry = bytes.compare(0, 10, "GALESTATE2") == 0;
    if (!carry && bytes.compare(0, 10, "GALESTATE1") != 0) {
        error = "not a gale solver state (bad header)";
        return false;
    }
    Reader r{bytes, 10};
    const uint64_t count = r.u64();
    if (!r.ok || count != mBodies.size()) {
        error = "the state holds a different number of objects than the scene";
        return false;
    }
    std::vector<Body::Snapshot> snaps(count);
    for (uint64_t i = 0; i < count; ++i) {
        const uint64_t len = r.u64();
        if (!r.ok || r.pos + len > bytes.size()) {
            error = "truncated state";
            return false;
        }
        const std::string name = bytes.substr(r.pos, len);
        r.pos += len;
        if (name != mBodies[i]->name()) {
            error = "the state's object '" + name + "' does not match the scene's '" +
                    mBodies[i]->name() + "'";
            return false;
        }
        snaps[i].x = r.vec();
        snaps[i].v = r.vec();
        snaps[i].dvGuess = r.vec();
        if (r.pos + sizeof(double) > bytes.size()) r.ok = false;
        if (r.ok) {
            std::memcpy(&snaps[i].hGuess, bytes.data() + r.pos, sizeof(double));
            r.pos += sizeof(double);
        }
        if (carry) {
            const VecX rate = r.vec(), mass = r.vec(), on = r.vec();
            const size_t n = mBodies[i]->vertexCount();
            const auto sized = [&](const VecX& v) {
                return v.size() == 0 || size_t(v.size()) == n;
            };
            if (!r.ok || !sized(rate) || !sized(mass) || !sized(on)) {
                error = "the state of '" + name + "' has a broken contact record";
                return false;
            }
            snaps[i].slidRate.assign(rate.data(), rate.data() + rate.size());
            snaps[i].slipMass.assign(mass.data(), mass.data() + mass.size());
            snaps[i].slidOn.resize(static_cast<size_t>(on.size()));
            for (long k = 0; k < on.size(); ++k)
                snaps[i].slidOn[static_cast<size_t>(k)] =
                    on[k] >= 0.0 && on[k] < 1e6 ? static_cast<int>(std::lround(on[k])) : -1;
        }
        const long n3 = static_cast<long>(3 * mBodies[i]->vertexCount());
        if (!r.ok || snaps[i].x.size() != n3 || snaps[i].v.size() != n3) {
            error = "the state of '" + name + "' does not match its vertex count";
            return false;
        }
    }
    for (uint64_t i = 0; i < count; ++i) mBodies[i]->restore(snaps[i]);
    return true;
}

} // namespace gale::solver
