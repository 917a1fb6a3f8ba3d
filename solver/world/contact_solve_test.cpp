// Collider contact inside the implicit step (body_contact.cpp, contact constraints): a sheet dropped
// flat onto a sphere and edge-first onto the ground at one substep per frame against the same
// scene at sixteen (stretch, kinetic energy after the impact, no halving, nothing left for the
// projection after the solve), and a sheet at rest on the floor that loses energy every frame.
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <tuple>

using namespace gale::solver;
using namespace gale::solver::testing;
using gale::fields::Param;

namespace {

enum class Drop { FlatOnSphere, EdgeOnGround };

// The scenes: a 0.5 m sheet, 24 × 24 vertices, 0.1 kg/m², 2000 N/m, no wind, dropped
// from 0.25 m (flat, over a sphere of radius 0.15 m at the origin; or hanging vertically, its
// lower edge 0.25 m above the ground plane y = 0).
constexpr RotationProjection kDefault = StepOptions{}.rotationProjection;

std::unique_ptr<World> dropScene(Drop d, int substeps, RotationProjection rotations = kDefault,
                                 bool defer = StepOptions{}.deferStackedContacts) {
    ClothMaterial m;
    m.density = 0.1;
    m.stretch = Param(2000.0);
    m.lift.value = Param(0.0);
    m.drag.value = Param(0.0);
    TriMesh mesh =
        d == Drop::FlatOnSphere
            ? makeGrid(0.5, 0.5, 24, 24, Vec3(-0.25, 0.25, -0.25), Vec3::UnitX(), Vec3::UnitZ())
            : makeGrid(0.5, 0.5, 24, 24, Vec3(-0.25, 0.25, 0.0), Vec3::UnitX(), Vec3::UnitY());
    WorldSettings ws;
    ws.substeps = substeps;
    auto w = std::make_unique<World>(ws);
    w->addBody(std::make_unique<Cloth>("sheet", mesh, m));
    w->body(0).options().rotationProjection = rotations;
    w->body(0).options().deferStackedContacts = defer;
    if (const char* nt = std::getenv("GALE_PROBE_NEWTON")) {
        w->body(0).options().newtonIterations = std::atoi(nt);
        w->body(0).options().newtonFullJacobian = false;
    }
    Collider c;
    c.a = Param(std::vector<double>{0, 0, 0});
    if (d == Drop::FlatOnSphere) {
        c.shape = ColliderShape::Sphere;
        c.radius = 0.15;
    } else {
        c.shape = ColliderShape::Plane;
        c.normal = Param(std::vector<double>{0, 1, 0});
    }
    w->addCollider(c);
    return w;
}

struct DropRun {
    double maxStretch = 0.0; // over all frames
    std::vector<double> ke;  // J: kinetic energy at the end of each frame
    int firstContact = -1;   // the first frame that ends with contacts
    int rejected = 0, newtonRetries = 0, recovered = 0;
    int projected = 0; // vertices the projection after the solve still moved or stopped
    double projectedDistance = 0.0; // m: its largest push-out
    std::vector<int> rotationSubsteps; // per frame: substeps the rotation projection ran in
    std::vector<int> contacts;         // per frame: vertices in contact at its end
};

DropRun runDrop(Drop d, int substeps, int frames = 48, bool print = false,
                RotationProjection rotations = kDefault,
                bool defer = StepOptions{}.deferStackedContacts) {
    auto w = dropScene(d, substeps, rotations, defer);
    DropRun r;
    for (int f = 1; f <= frames; ++f) {
        const FrameStats fs = w->advanceFrame(f);
        const BodyFrameStats& b = fs.bodies[0];
        r.maxStretch = std::max(r.maxStretch, b.maxStretch);
        r.ke.push_back(b.kinetic);
        if (r.firstContact < 0 && b.contacts > 0) r.firstContact = f;
        r.rejected += b.rejected;
        r.newtonRetries += b.newtonRetries;
        r.recovered += b.recovered;
        r.projected += b.projected;
        r.projectedDistance = std::max(r.projectedDistance, b.projectedDistance);
        r.rotationSubsteps.push_back(b.rotationSubsteps);
        r.contacts.push_back(b.contacts);
        if (print)
            std::printf("frame %2d substeps %3d rejected %d retries %d stretch %.4f ke %.3e "
                        "elastic %.3e contacts %d vmax %.4f | c %ld add %d rel %d slides %d "
                        "solves %d proj %d %.2e m %.2e m/s it %ld\n",
                        f, b.substeps, b.rejected, b.newtonRetries, b.maxStretch, b.kinetic,
                        b.elastic, b.contacts, b.maxSpeed, b.contactConstraints, b.contactAdded,
                        b.contactReleases, b.contactSlides, b.contactSolves, b.projected,
                        b.projectedDistance, b.projectedSpeed, b.iterations);
    }
    return r;
}

// The goals of issue 25 against the 16-substep run of the same scene, computed here: the strain
// (stretch − 1) at most 1.5× the reference's plus 1 %, the kinetic energy after the impact at
// most 1.2× plus 1 mJ, no halving, no Newton retry, and no push-out left for the projection.
void checkAgainstReference(Drop d, bool goal, RotationProjection rotations = kDefault) {
    const DropRun fine = runDrop(d, 16, 48, false, rotations);
    const DropRun coarse = runDrop(d, 1, 48, false, rotations);
    // After the impact: from the frame after both runs first end a frame in contact.
    const size_t from = static_cast<size_t>(std::max(fine.firstContact, coarse.firstContact));
    double keFine = 0.0, keCoarse = 0.0;
    for (size_t f = from; f < fine.ke.size(); ++f) {
        keFine = std::max(keFine, fine.ke[f]);
        keCoarse = std::max(keCoarse, coarse.ke[f]);
    }
    INFO("16 substeps: stretch " << fine.maxStretch << ", kinetic after impact " << keFine
                                 << " J; 1 substep: stretch " << coarse.maxStretch << ", kinetic "
                                 << keCoarse << " J, projected " << coarse.projected
                                 << " (largest push-out " << coarse.projectedDistance << " m)");
    REQUIRE(fine.firstContact > 0);
    REQUIRE(coarse.firstContact > 0);
    CHECK(fine.rejected == 0);
    CHECK(coarse.rejected == 0);
    CHECK(coarse.newtonRetries == 0);
    CHECK(coarse.recovered == 0);
    CHECK(keCoarse <= 1.2 * keFine + 1e-3);
    // What the projection after the solve still pushes out: the goal is nothing (rounding,
    // 1 µm); held here to a tenth of the collider's thickness (5 mm).
    CHECK(coarse.projectedDistance <= (goal ? 1e-6 : 5e-4));
    if (goal) CHECK(coarse.maxStretch - 1.0 <= 1.5 * (fine.maxStretch - 1.0) + 0.01);
}

} // namespace

// With the rotation projection as shipped (rotation_projection.h: in the substeps where a collider
// holds a vertex in the solve) both drops meet every goal of the issue at one substep a frame,
// the stretch one included.
TEST_CASE("contact in the solve: the drops' goals at one substep per frame", "[contact]") {
    checkAgainstReference(Drop::FlatOnSphere, true);
    checkAgainstReference(Drop::EdgeOnGround, true);
}

// Projecting in every substep (rotation_projection = "always") meets them as well.
TEST_CASE("contact in the solve: the drops' goals with the projection in every substep",
          "[contact]") {
    checkAgainstReference(Drop::FlatOnSphere, true, RotationProjection::Always);
    checkAgainstReference(Drop::EdgeOnGround, true, RotationProjection::Always);
}

// Without the projection the contact solve alone holds the weaker bounds (no halving, no retry,
// the energy goal, push-out within a tenth of the thickness) but not the stretch goal: the
// sphere's strain is 0.068 against 1.5 × 0.013 + 0.01 allowed; the edges turning about the contact
// ring end longer than the linearised step saw (docs/solver.md).
TEST_CASE("contact in the solve: the drops at one substep per frame without the projection",
          "[contact]") {
    checkAgainstReference(Drop::FlatOnSphere, false, RotationProjection::Off);
    checkAgainstReference(Drop::EdgeOnGround, false, RotationProjection::Off);
}

// Two substeps a frame, edge-first: the sheet falls 4.3 cm a substep onto the ground, two rows
// of 2.2 cm. Held at once, the second row was pressed onto the ground beside the first (the sheet
// folded flat there, its diagonals at 1.14×, 2 J of elastic energy from 52 mJ of fall); waiting a
// round behind the first (StepOptions::deferStackedContacts), it is stopped by its edge to it.
// The goals against 16 substeps hold, and without the wait (the control) the stretch one
// does not.
TEST_CASE("contact in the solve: the edge-first drop at two substeps a frame", "[contact]") {
    const DropRun fine = runDrop(Drop::EdgeOnGround, 16);
    const DropRun two = runDrop(Drop::EdgeOnGround, 2);
    const DropRun held = runDrop(Drop::EdgeOnGround, 2, 48, false, kDefault, false);
    const auto keAfter = [](const DropRun& r, size_t from) {
        double ke = 0.0;
        for (size_t f = from; f < r.ke.size(); ++f) ke = std::max(ke, r.ke[f]);
        return ke;
    };
    REQUIRE(fine.firstContact > 0);
    REQUIRE(two.firstContact > 0);
    const size_t from = static_cast<size_t>(std::max(fine.firstContact, two.firstContact));
    INFO("16 substeps: stretch " << fine.maxStretch << ", kinetic after impact "
                                 << keAfter(fine, from) << " J; 2 substeps: stretch "
                                 << two.maxStretch << ", kinetic " << keAfter(two, from)
                                 << " J; held at once: stretch " << held.maxStretch);
    const double allowed = 1.5 * (fine.maxStretch - 1.0) + 0.01;
    CHECK(two.maxStretch - 1.0 <= allowed);
    CHECK(keAfter(two, from) <= 1.2 * keAfter(fine, from) + 1e-3);
    CHECK(two.rejected == 0);
    CHECK(two.newtonRetries == 0);
    CHECK(held.maxStretch - 1.0 > allowed); // the control
}

TEST_CASE("contact in the solve: the sphere drop's stretch goal without the projection",
          "[.goal][contact]") {
    checkAgainstReference(Drop::FlatOnSphere, true, RotationProjection::Off);
}

// "contact" projects in the substeps with a collider contact in the solve and in no other: the
// drop's free fall is not projected, its impact is. "always" (the default) projects in every
// substep, in free air only the edges more than rotationFreeTolerance (3 %) beyond their target:
// a sheet swinging down from a pinned edge with no collider (one substep a frame: its edges turn
// ~10° a step, 1.5 % longer than the linearised step saw) gives the same bits as with the
// projection off under "contact" and under "always", and changes under "always" with the free
// tolerance at the contact one (0.1 %).
TEST_CASE("contact in the solve: where the rotation projection acts, and at what tolerance",
          "[contact]") {
    const DropRun drop = runDrop(Drop::FlatOnSphere, 1, 12, false, RotationProjection::Contact);
    REQUIRE(drop.firstContact > 1);
    int after = 0;
    for (size_t f = 0; f < drop.rotationSubsteps.size(); ++f) {
        INFO("frame " << f + 1 << " contacts " << drop.contacts[f]);
        if (static_cast<int>(f) + 2 < drop.firstContact) CHECK(drop.rotationSubsteps[f] == 0);
        if (drop.contacts[f] > 0) CHECK(drop.rotationSubsteps[f] == 1);
        after += drop.rotationSubsteps[f];
    }
    CHECK(after > 0);
    CHECK(StepOptions{}.rotationProjection == RotationProjection::Always);

    const auto swing = [](RotationProjection r, double freeTolerance) {
        ClothMaterial m;
        m.density = 0.1;
        m.stretch = Param(2000.0);
        m.lift.value = Param(0.0);
        m.drag.value = Param(0.0);
        auto c = std::make_unique<Cloth>(
            "sheet",
            makeGrid(0.5, 0.5, 16, 16, Vec3(-0.25, 1.0, 0.0), Vec3::UnitX(), Vec3::UnitZ()), m);
        PinSet pins;
        pins.vertices = gridRow(16, 0);
        c->addPins(pins);
        c->options().rotationProjection = r;
        c->options().rotationFreeTolerance = freeTolerance;
        WorldSettings ws;
        ws.substeps = 1;
        World w(ws);
        w.addBody(std::move(c));
        long edges = 0;
        int substeps = 0;
        double excess = 0.0;
        for (int f = 1; f <= 12; ++f) {
            const FrameStats fs = w.advanceFrame(f);
            edges += fs.bodies[0].rotationEdges;
            substeps += fs.bodies[0].rotationSubsteps;
            excess = std::max(excess, fs.bodies[0].rotationExcess);
        }
        return std::make_tuple(VecX(w.bodies()[0]->positions()), edges, substeps, excess);
    };
    const double freeTolerance = StepOptions{}.rotationFreeTolerance;
    const double fine = StepOptions{}.rotationTolerance;
    const auto [xOff, edgesOff, substepsOff, excessOff] =
        swing(RotationProjection::Off, freeTolerance);
    const auto [xContact, edgesContact, substepsContact, excessContact] =
        swing(RotationProjection::Contact, freeTolerance);
    const auto [xAlways, edgesAlways, substepsAlways, excessAlways] =
        swing(RotationProjection::Always, freeTolerance);
    const auto [xFine, edgesFine, substepsFine, excessFine] =
        swing(RotationProjection::Always, fine);
    INFO("always: " << edgesAlways << " edges beyond the free tolerance, largest excess "
                    << excessAlways << "; at the contact tolerance " << edgesFine << " edges");
    CHECK(substepsOff == 0);
    CHECK(substepsContact == 0);
    CHECK(edgesContact == 0);
    CHECK((xContact - xOff).cwiseAbs().maxCoeff() == 0.0);
    // "always": it runs every substep, finds edges beyond their targets, none by the free
    // tolerance (the swing's excess lies between the two tolerances), and leaves the bits.
    CHECK(substepsAlways == 12); // one substep in each of the 12 frames advanced
    CHECK(excessAlways > fine);
    CHECK(excessAlways < freeTolerance);
    CHECK((xAlways - xOff).cwiseAbs().maxCoeff() == 0.0);
    CHECK(edgesFine > 0);
    CHECK((xFine - xOff).cwiseAbs().maxCoeff() > 1e-4);
}

TEST_CASE("contact in the solve: a sheet resting on the floor comes to rest", "[contact]") {
    // A 0.5 m sheet laid on the ground plane at the collider's thickness, one substep per frame:
    // its kinetic energy falls every frame (no jitter) and every vertex is below 1 mm/s after
    // 1 s.
    ClothMaterial m;
    m.lift.value = Param(0.0);
    m.drag.value = Param(0.0);
    Collider c;
    c.a = Param(std::vector<double>{0, 0, 0});
    c.normal = Param(std::vector<double>{0, 1, 0});
    TriMesh mesh = makeGrid(0.5, 0.5, 24, 24, Vec3(-0.25, c.thickness + 0.002, -0.25),
                            Vec3::UnitX(), Vec3::UnitZ());
    for (int substeps : {1, 4}) {
        WorldSettings ws;
        ws.substeps = substeps;
        World w(ws);
        w.addBody(std::make_unique<Cloth>("sheet", mesh, m));
        w.addCollider(c);
        double keBefore = 0.0;
        for (int f = 1; f <= 48; ++f) {
            const FrameStats fs = w.advanceFrame(f);
            const BodyFrameStats& b = fs.bodies[0];
            INFO("substeps " << substeps << " frame " << f << " kinetic " << b.kinetic
                             << " max speed " << b.maxSpeed);
            CHECK(b.rejected == 0);
            if (f > 2) CHECK(b.kinetic <= keBefore);
            if (f >= 24) CHECK(b.maxSpeed < 1e-3);
            double low = 1e9;
            const VecX& x = w.bodies()[0]->positions();
            for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i)
                low = std::min(low, x[3 * i + 1]);
            CHECK(low >= c.thickness - 1e-9);
            keBefore = b.kinetic;
        }
    }
}

TEST_CASE("contact probe: the drop scenes frame by frame", "[.probe]") {
    const char* s = std::getenv("GALE_PROBE_SUBSTEPS");
    const char* d = std::getenv("GALE_PROBE_SCENE");
    runDrop(d && d[0] == '1' ? Drop::EdgeOnGround : Drop::FlatOnSphere, s ? std::atoi(s) : 1, 48,
            true, [] {
                // GALE_PROBE_ROTATION: off, contact (the default) or always.
                const char* r = std::getenv("GALE_PROBE_ROTATION");
                for (RotationProjection m : {RotationProjection::Off, RotationProjection::Contact,
                                             RotationProjection::Always})
                    if (r && std::string(r) == rotationProjectionName(m)) return m;
                return kDefault;
            }());
}

TEST_CASE("contact in the solve: a slide just past the stick threshold keeps its closed form",
          "[contact]") {
    // tan θ a few % above μ: the slide's acceleration g (sin θ − μ cos θ) is a small difference
    // (0.05–0.14 m/s² against friction's 2.8–3.9). The friction each substep starts from must be
    // for the slip that substep reaches, not the last one's: carried unchanged, an accelerating
    // slide was held back (17°, μ 0.3: 0.034 against 0.054 m/s² after 2 s), since the 1 % the
    // rounds refine friction to is 20–70 % of the acceleration. Within 2 % after 1 s.
    const double g = 9.81, T = 1.0;
    for (auto [thetaDeg, mu] : {std::pair{17.0, 0.3}, std::pair{17.5, 0.3}, std::pair{27.0, 0.5}}) {
        const double theta = thetaDeg * M_PI / 180.0;
        const Vec3 down(-std::cos(theta), -std::sin(theta), 0.0);
        const auto world = inclineWorld(thetaDeg, mu, g);
        World& w = *world;
        for (int f = 1; f <= 24; ++f) w.advanceFrame(f);
        const VecX& v = w.bodies()[0]->velocities();
        Vec3 vc = Vec3::Zero();
        const size_t count = w.bodies()[0]->vertexCount();
        for (size_t i = 0; i < count; ++i) vc += vec3At(v.data(), i) / double(count);
        const double accel = vc.dot(down) / T, a = g * (std::sin(theta) - mu * std::cos(theta));
        INFO("theta " << thetaDeg << " mu " << mu << " acceleration " << accel
                      << " m/s², closed form " << a);
        CHECK(accel == Approx(a).epsilon(0.02));
    }
}

TEST_CASE("contact in the solve: Coulomb friction on an incline at one substep per frame",
          "[contact]") {
    // A 10 cm patch at rest on a plane tilted by θ, friction in the solve, h = 1/24 s: it sticks
    // when tan θ < μ, else it slides with a = g (sin θ − μ cos θ) (closed form, within 2 %),
    // staying on the plane.
    const double g = 9.81, T = 1.0;
    for (double thetaDeg : {20.0, 30.0}) {
        const double theta = thetaDeg * M_PI / 180.0;
        const Vec3 normal(-std::sin(theta), std::cos(theta), 0.0);
        const Vec3 down(-std::cos(theta), -std::sin(theta), 0.0); // along the slope, downhill
        for (double mu : {0.2, 0.3, 0.5}) {
            const auto world = inclineWorld(thetaDeg, mu, g);
            World& w = *world;
            int rejected = 0;
            for (int f = 1; f <= 24; ++f) {
                const BodyFrameStats b = w.advanceFrame(f).bodies[0];
                rejected += b.rejected;
                if (std::getenv("GALE_PROBE_INCLINE"))
                    std::printf("theta %g mu %g f %d c %ld add %d rel %d slides %d solves %d "
                                "proj %d\n",
                                thetaDeg, mu, f, b.contactConstraints, b.contactAdded,
                                b.contactReleases, b.contactSlides, b.contactSolves, b.projected);
            }
            const VecX& x = w.bodies()[0]->positions();
            const VecX& v = w.bodies()[0]->velocities();
            Vec3 c = Vec3::Zero(), c0 = Vec3::Zero(), vc = Vec3::Zero();
            const VecX& x0 = w.bodies()[0]->restPositions();
            const size_t count = w.bodies()[0]->vertexCount();
            for (size_t i = 0; i < count; ++i) {
                c += vec3At(x.data(), i) / double(count);
                c0 += vec3At(x0.data(), i) / double(count);
                vc += vec3At(v.data(), i) / double(count);
            }
            // The acceleration from the speed at T (backward Euler under a constant force gives
            // v = a T exactly; its distance is ½ a T² (1 + h/T)).
            const double accel = vc.dot(down) / T;
            const double slid = (c - c0).dot(down);
            const double a = g * (std::sin(theta) - mu * std::cos(theta));
            INFO("theta " << thetaDeg << " mu " << mu << " acceleration " << accel
                          << " m/s², closed form " << std::max(a, 0.0) << "; slid " << slid);
            CHECK(rejected == 0);
            if (a > 0) {
                CHECK(accel == Approx(a).epsilon(0.02));
            } else {
                CHECK(std::abs(slid) < 1e-6);
                CHECK(std::abs(accel) < 1e-6);
            }
            CHECK(std::abs((c - c0).dot(normal)) < 1e-6);
        }
    }
}
