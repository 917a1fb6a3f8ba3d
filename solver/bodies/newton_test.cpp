// The Newton iterations of the backward-Euler step (body.cpp, Body::newton): they converge to
// the tolerance on a smooth problem, the converged step solves the nonlinear equations far
// better than the linearised one, and a pinned sheet in still air never gains energy.
#include "solver/bodies/cloth.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

using namespace gale::solver;
using namespace gale::solver::testing;

namespace {

struct Sheet {
    World world;
    explicit Sheet(int newton, double h) : world(settings(h)) {
        TriMesh mesh = makeGrid(1.0, 1.0, 16, 16, Vec3(0, 1, 0), Vec3::UnitX(), Vec3::UnitZ());
        ClothMaterial m;
        m.density = 0.05;
        m.stretch = gale::fields::Param(2000.0);
        m.shear = gale::fields::Param(200.0);
        m.bend = gale::fields::Param(1e-4);
        m.damping = gale::fields::Param(0.0);
        auto cloth = std::make_unique<Cloth>("sheet", mesh, m);
        cloth->options().newtonIterations = newton;
        cloth->options().newtonTolerance = 1e-4;
        cloth->options().cgTolerance = 1e-8;
        PinSet pins;
        pins.vertices = gridColumn(16, 16, 0); // a horizontal sheet hinged along one edge
        cloth->addPins(pins);
        world.addBody(std::move(cloth));
    }
    static WorldSettings settings(double h) {
        WorldSettings ws;
        ws.fps = 1.0 / h;
        ws.substeps = 1;
        ws.maxHalvings = 0;
        return ws;
    }
};

} // namespace

TEST_CASE("newton: a sheet swinging down under gravity converges every step", "[newton]") {
    // Large rotations at h = 1/24 s: the linearised step leaves a residual, Newton removes it.
    Sheet nt(12, 1.0 / 24);
    bool newtonWorked = false;
    for (int f = 1; f <= 12; ++f) {
        const FrameStats b = nt.world.advanceFrame(f);
        REQUIRE_FALSE(b.failed);
        const BodyFrameStats& s = b.bodies[0];
        INFO("frame " << f << " newton " << s.maxNewtonIterations << " residual "
                      << s.maxNewtonResidual);
        CHECK(s.maxNewtonResidual <= 1e-4);
        CHECK(s.newtonStalled == 0);
        CHECK(s.rejected == 0);
        newtonWorked = newtonWorked || s.maxNewtonIterations > 0;
    }
    // Newton did have work to do on this motion (the linearised step alone is not converged).
    CHECK(newtonWorked);
}

TEST_CASE("newton: energy of a pinned sheet in still air never grows", "[newton]") {
    // No wind and no Rayleigh damping: backward Euler only dissipates, the line search on the
    // incremental potential keeps it so (total = kinetic + elastic + gravitational).
    for (int newton : {0, 8}) {
        Sheet s(newton, 1.0 / 48);
        double last = 0.0;
        for (int f = 1; f <= 48; ++f) {
            const FrameStats fs = s.world.advanceFrame(f);
            REQUIRE_FALSE(fs.failed);
            const BodyFrameStats& b = fs.bodies[0];
            const double total = b.kinetic + b.elastic + b.potential;
            if (f > 1) CHECK(total <= last + 1e-9 * std::abs(last) + 1e-12);
            last = total;
        }
    }
}
