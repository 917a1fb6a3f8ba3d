// Keyframed pins: a rotation about a pivot (then a translation) moves the pinned vertices on the
// closed-form rigid motion at every substep end, with the velocity ω × r + ṫ of that motion.
#include "solver/bodies/cloth.h"
#include "solver/world/test_support.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale::solver;
using namespace gale::solver::testing;
using gale::fields::KeyInterp;
using gale::fields::Param;

TEST_CASE("pins: rotation about a pivot then translation, closed form", "[pins]") {
    const int n = 6;
    TriMesh mesh = makeGrid(0.5, 0.5, n, n, Vec3(0.2, 0.0, 0.0), Vec3::UnitX(), Vec3::UnitY());
    ClothMaterial mat;
    mat.lift.value = Param(0.0);
    mat.drag.value = Param(0.0);
    auto cloth = std::make_unique<Cloth>("flag", mesh, mat);
    PinSet pins;
    pins.vertices = gridColumn(n, n, 0); // x = 0.2, y in [0, 0.5]
    pins.rotate.active = true;
    pins.rotate.pivot = Vec3(0.0, 0.0, 0.0);
    pins.rotate.axis = Vec3(0.0, 2.0, 0.0); // not unit: normalised
    pins.rotate.angle = Param::keyed({0.0, 1.0}, {{0.0}, {90.0}}, KeyInterp::Linear); // 90°/s
    pins.translate = Param::keyed({0.0, 1.0}, {{0, 0, 0}, {0, 0.3, 0}}, KeyInterp::Linear);
    cloth->addPins(pins);
    Cloth* c = cloth.get();

    // Closed form for the pinned column: about +y by θ = (π/2) t, (x, z) = 0.2 (cos θ, −sin θ).
    for (double t : {0.0, 0.25, 0.5, 0.75}) {
        const double th = 0.5 * M_PI * t;
        for (size_t k = 0; k < c->pinnedVertices().size(); ++k) {
            const double y0 = mesh.position(c->pinnedVertices()[k]).y();
            const Vec3 want(0.2 * std::cos(th), y0 + 0.3 * t, -0.2 * std::sin(th));
            CHECK((c->pinTarget(k, t) - want).norm() < 1e-12);
            // d/dt: ω = π/2 rad/s about y, plus 0.3 m/s up.
            const Vec3 vWant(-0.2 * 0.5 * M_PI * std::sin(th), 0.3,
                             -0.2 * 0.5 * M_PI * std::cos(th));
            CHECK((c->pinVelocity(k, t) - vWant).norm() < 1e-5);
        }
    }

    WorldSettings ws;
    ws.fps = 24;
    ws.substeps = 3;
    World world(ws);
    world.addBody(std::move(cloth));
    for (int f = 1; f <= 12; ++f) {
        FrameStats fs = world.advanceFrame(f);
        REQUIRE(!fs.failed);
        const double t = f / 24.0, th = 0.5 * M_PI * t;
        for (size_t k = 0; k < c->pinnedVertices().size(); ++k) {
            const int i = c->pinnedVertices()[k];
            const double y0 = mesh.position(i).y();
            const Vec3 want(0.2 * std::cos(th), y0 + 0.3 * t, -0.2 * std::sin(th));
            CHECK((vec3At(c->positions().data(), i) - want).norm() < 1e-9);
            // The step's velocity is the chord of the last substep (x₁ = x₀ + h v₁): within
            // ω² r h / 2 of the tangent velocity.
            const double h = 1.0 / 72.0;
            CHECK((vec3At(c->velocities().data(), i) - c->pinVelocity(k, t)).norm() <
                  0.5 * 0.25 * M_PI * M_PI * 0.2 * h + 1e-9);
        }
    }
}
