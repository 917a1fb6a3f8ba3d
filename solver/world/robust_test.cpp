// Robustness: a substep in trouble is undone and retried at half the step with the reason
// logged; unrecoverable non-finite state fails the frame cleanly (state restored, never NaN
// output); results do not depend on the thread count; saving and restoring the state
// continues a run bit for bit.
#include "solver/bodies/cloth.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace gale::solver;
using namespace gale::solver::testing;
using gale::fields::Param;

namespace {

std::unique_ptr<Cloth> flag(int n, double sigma = 0.05) {
    ClothMaterial m;
    m.density = sigma;
    auto c = std::make_unique<Cloth>("flag", makeGrid(1.0, 1.0, n, n, Vec3(0, 1, 0)), m);
    PinSet pins;
    pins.vertices = gridColumn(n, n, 0);
    c->addPins(pins);
    return c;
}

// A gusty, swirling wind so that every vertex sees a different force.
gale::fields::FieldPtr gustyWind() {
    return std::make_shared<LambdaField>([](const Vec3& x, double t) {
        return Vec3(12.0 + 4.0 * std::sin(3.0 * t + 2.0 * x.y()), 2.0 * std::cos(5.0 * t + 3.0 * x.x()),
                    3.0 * std::sin(7.0 * t + x.x() + x.y()));
    });
}

bool contains(const std::vector<std::string>& events, const std::string& what) {
    for (const std::string& e : events)
        if (e.find(what) != std::string::npos) return true;
    return false;
}

} // namespace

TEST_CASE("robust: a linear solve that does not converge halves the substep, with the reason", "[robust]") {
    World w(WorldSettings{});
    w.setWind(gustyWind());
    auto c = flag(12);
    c->options().cgMaxIterations = 3;
    c->options().warmStart = false;
    w.addBody(std::move(c));
    const FrameStats fs = w.advanceFrame(1);
    CHECK_FALSE(fs.failed);
    CHECK(fs.bodies[0].rejected > 0);
    CHECK(fs.bodies[0].deepestHalving > 0);
    CHECK(contains(fs.bodies[0].events, "linear solver did not converge"));
    CHECK(contains(fs.bodies[0].events, "substep halved"));
    CHECK(w.bodies()[0]->positions().allFinite());
}

TEST_CASE("robust: the recoil of a flag stretched ×10 is caught as a velocity jump", "[robust]") {
    World w(WorldSettings{});
    TriMesh mesh = makeGrid(1.0, 1.0, 10, 10);
    VecX start = Eigen::Map<const VecX>(mesh.positions.data(), mesh.positions.size());
    for (size_t i = 0; i < mesh.vertexCount(); ++i) start[3 * i] *= 10.0;
    auto c = std::make_unique<Cloth>("flag", mesh, ClothMaterial{}, &start);
    PinSet pins;
    pins.vertices = gridColumn(10, 10, 0);
    c->addPins(pins);
    w.addBody(std::move(c));
    const FrameStats fs = w.advanceFrame(1);
    CHECK_FALSE(fs.failed);
    CHECK(contains(fs.bodies[0].events, "velocity jump"));
    CHECK(fs.bodies[0].rejected > 0);
    CHECK(w.bodies()[0]->positions().allFinite());
}

TEST_CASE("robust: non-finite state that halving cannot fix is recovered, reported and bounded", "[robust]") {
    // A NaN stiffness makes every substep non-finite: at the smallest substep the world recovers
    // (speeds capped at velocity_jump + 2 (wind + pins), strain limited) instead of failing, and
    // says so; the state stays finite, no edge longer than 3× its rest length.
    World w(WorldSettings{});
    auto c = flag(6);
    c->material().stretch = Param(std::numeric_limits<double>::quiet_NaN());
    w.addBody(std::move(c));
    const FrameStats fs = w.advanceFrame(1);
    CHECK_FALSE(fs.failed);
    CHECK(fs.bodies[0].recovered > 0);
    CHECK(contains(fs.bodies[0].events, "non-finite"));
    CHECK(contains(fs.bodies[0].events, "recovered by strain limiting"));
    CHECK(w.bodies()[0]->positions().allFinite());
    CHECK(w.bodies()[0]->velocities().allFinite());
    CHECK(w.bodies()[0]->maxEdgeStretch() <= 3.0 * (1.0 + 1e-6));
    // No wind and still pins: the cap is velocity_jump (50 m/s); strain limiting only pulls
    // vertices back towards their neighbours.
    for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i)
        CHECK(vec3At(w.bodies()[0]->velocities().data(), i).norm() <= 50.0 * (1.0 + 1e-9));
}

TEST_CASE("robust: results do not depend on the thread count", "[robust]") {
    VecX ref;
    for (int threads : {1, 2, 3}) {
        WorldSettings ws;
        ws.threads = threads;
        World w(ws);
        w.setWind(gustyWind());
        w.addBody(flag(40));
        for (int f = 1; f <= 3; ++f) REQUIRE_FALSE(w.advanceFrame(f).failed);
        const VecX& x = w.bodies()[0]->positions();
        if (threads == 1)
            ref = x;
        else
            CHECK((x - ref).cwiseAbs().maxCoeff() == 0.0);
    }
}

TEST_CASE("robust: saving and loading the state continues bit for bit", "[robust]") {
    auto makeWorld = [] {
        auto w = std::make_unique<World>(WorldSettings{});
        w->setWind(gustyWind());
        w->addBody(flag(16));
        return w;
    };
    auto straight = makeWorld();
    for (int f = 1; f <= 6; ++f) REQUIRE_FALSE(straight->advanceFrame(f).failed);

    auto first = makeWorld();
    for (int f = 1; f <= 3; ++f) REQUIRE_FALSE(first->advanceFrame(f).failed);
    const std::string state = first->saveState();
    auto resumed = makeWorld();
    std::string error;
    REQUIRE(resumed->loadState(state, error));
    for (int f = 4; f <= 6; ++f) REQUIRE_FALSE(resumed->advanceFrame(f).failed);
    CHECK(resumed->bodies()[0]->positions() == straight->bodies()[0]->positions());
    CHECK(resumed->bodies()[0]->velocities() == straight->bodies()[0]->velocities());

    // A patch sliding down a 30° incline with friction μ = 0.2: its contacts start each substep
    // sliding with the friction they ended the last with (body_contact.cpp), which the state
    // carries too.
    const auto makeIncline = [] { return inclineWorld(30.0, 0.2); };
    auto slid = makeIncline();
    for (int f = 1; f <= 12; ++f) REQUIRE_FALSE(slid->advanceFrame(f).failed);
    auto half = makeIncline();
    for (int f = 1; f <= 6; ++f) REQUIRE_FALSE(half->advanceFrame(f).failed);
    auto slidResumed = makeIncline();
    REQUIRE(slidResumed->loadState(half->saveState(), error));
    for (int f = 7; f <= 12; ++f) REQUIRE_FALSE(slidResumed->advanceFrame(f).failed);
    CHECK(slidResumed->bodies()[0]->positions() == slid->bodies()[0]->positions());
    CHECK(slidResumed->bodies()[0]->velocities() == slid->bodies()[0]->velocities());

    // A state from a different scene is refused with a reason.
    World other(WorldSettings{});
    other.addBody(flag(5));
    CHECK_FALSE(other.loadState(state, error));
    CHECK_FALSE(error.empty());
    CHECK_FALSE(other.loadState("garbage", error));
}
