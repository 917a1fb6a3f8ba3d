// Collider contact inside the implicit step (issue 25): the cost of a substep with contacts
// against the same substep without them (a sheet resting on the ground against the same sheet
// with no ground, from the same state, measured in the same run: time and CG iterations; and a
// sheet pinned along an edge draped over a sphere or a bar against the same without it), and
// speed against error of the two drop scenes of solver/world/contact_solve_test.cpp at 1, 2, 4,
// 8 and 16 substeps a frame (error: the largest stretch and the kinetic energy after the impact
// against the 16-substep run).
// Usage: gale_bench_contact_solve [frames=48 | draped]
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/world/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

using namespace gale::solver;
using gale::fields::Param;

namespace {

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

ClothMaterial sheetMaterial() {
    ClothMaterial m;
    m.density = 0.1;
    m.stretch = Param(2000.0);
    m.lift.value = Param(0.0);
    m.drag.value = Param(0.0);
    return m;
}

Collider ground(double mu = 0.3) {
    Collider c;
    c.friction = mu;
    c.a = Param(std::vector<double>{0, 0, 0});
    c.normal = Param(std::vector<double>{0, 1, 0});
    return c;
}

// A 64 × 64 sheet settled on the ground for `settle` frames at 1 substep a frame; then `steps`
// substeps of 1/24 s from that state with the ground and, from the same state, without it.
void contactCost(int steps, double mu) {
    const TriMesh mesh =
        makeGrid(0.5, 0.5, 64, 64, Vec3(-0.25, 0.007, -0.25), Vec3::UnitX(), Vec3::UnitZ());
    WorldSettings ws;
    ws.substeps = 1;
    World settle(ws);
    settle.addBody(std::make_unique<Cloth>("sheet", mesh, sheetMaterial()));
    settle.addCollider(ground(mu));
    for (int f = 1; f <= 24; ++f) settle.advanceFrame(f);
    const std::string state = settle.saveState();
    double sec[2] = {0, 0};
    long it[2] = {0, 0};
    int contacts = 0;
    for (int withGround = 1; withGround >= 0; --withGround) {
        World w(ws);
        w.addBody(std::make_unique<Cloth>("sheet", mesh, sheetMaterial()));
        if (withGround) w.addCollider(ground(mu));
        std::string err;
        w.loadState(state, err);
        for (int s = 0; s < steps; ++s) {
            // Each step from the settled state again, so both sides solve the same problem.
            w.loadState(state, err);
            const double t0 = now();
            const FrameStats fs = w.advance(1.0, 1.0 / 24.0, 1);
            sec[withGround] += now() - t0;
            it[withGround] += fs.bodies[0].iterations;
            if (withGround) contacts = fs.bodies[0].contactConstraints;
        }
    }
    std::printf("64x64 sheet on the ground (friction %g), 1/24 s substeps, %d steps: %d "
                "contacts\n",
                mu, steps, contacts);
    std::printf("  without ground: %.3f ms/step, %.1f CG iterations/step\n", 1e3 * sec[0] / steps,
                double(it[0]) / steps);
    std::printf("  with contacts : %.3f ms/step, %.1f CG iterations/step\n", 1e3 * sec[1] / steps,
                double(it[1]) / steps);
    std::printf("  ratio         : %.2fx time, %.2fx iterations\n", sec[1] / sec[0],
                double(it[1]) / double(std::max(1L, it[0])));
}

// The comparison on a draped, partly constrained sheet: a 64 × 64 sheet (0.5 m) hung
// vertically from its top edge (pinned) 1 cm in front of a horizontal bar (r = 0.1 m; or a
// 0.15 m sphere), leaned onto it by a 3 m/s² push towards it besides gravity (a steady wind's
// share), settles for `settle` frames at one substep a frame: wrapped over the bar (the sphere
// it touches at a point), the rest hanging below it.
// Then, from that state, `steps` frames at one substep a frame with the sphere and, from the
// same state, without it (the same pins: the same conditioning but for the contacts): the cost
// of a substep with contact against the same substep without.
void drapedCost(bool bar, int settle, int steps, double mu) {
    const TriMesh mesh =
        makeGrid(0.5, 0.5, 64, 64, Vec3(-0.25, 0.0, 0.01), Vec3::UnitX(), Vec3::UnitY());
    PinSet pins;
    for (size_t i = 0; i < mesh.vertexCount(); ++i)
        if (mesh.position(i).y() > 0.5 - 1e-9) pins.vertices.push_back(static_cast<int>(i));
    auto sheet = [&] {
        auto c = std::make_unique<Cloth>("sheet", mesh, sheetMaterial());
        c->addPins(pins);
        return c;
    };
    Collider ball = ground(mu);
    if (bar) { // a flat sheet wraps a bar (a contact patch); a sphere it touches at a point
        ball.shape = ColliderShape::Capsule;
        ball.radius = 0.1;
        ball.a = Param(std::vector<double>{-0.4, 0.25, -0.1});
        ball.b = Param(std::vector<double>{0.4, 0.25, -0.1});
    } else {
        ball.shape = ColliderShape::Sphere;
        ball.radius = 0.15;
        ball.a = Param(std::vector<double>{0, 0.25, -0.15});
    }
    WorldSettings ws;
    ws.substeps = 1;
    ws.gravity = Vec3(0.0, -9.81, -3.0);
    World w0(ws);
    w0.addBody(sheet());
    w0.addCollider(ball);
    for (int f = 1; f <= settle; ++f) w0.advanceFrame(f);
    const std::string state = w0.saveState();
    double sec[2] = {0, 0};
    long it[2] = {0, 0}, solves[2] = {0, 0}, contacts = 0, touching = 0;
    for (int withBall = 1; withBall >= 0; --withBall) {
        World w(ws);
        w.addBody(sheet());
        if (withBall) w.addCollider(ball);
        std::string err;
        for (int s = 0; s < steps; ++s) {
            w.loadState(state, err); // each step from the draped state again: the same problem
            const double t0 = now();
            const FrameStats fs = w.advance(settle / 24.0, 1.0 / 24.0, 1);
            sec[withBall] += now() - t0;
            it[withBall] += fs.bodies[0].iterations;
            solves[withBall] += fs.bodies[0].linearSolves; // 1 + the active set's rounds
            if (withBall) contacts = fs.bodies[0].contactConstraints;
            if (withBall) touching = fs.bodies[0].contacts;
        }
    }
    std::printf("64x64 sheet hung from its top edge, pressed onto %s (friction %g) after %d "
                "frames, %d steps of 1/24 s: %ld vertices touching it, %ld of them constrained "
                "in the solve, of %zu\n",
                bar ? "a 0.1 m bar" : "a 0.15 m sphere", mu, settle, steps, touching, contacts,
                mesh.vertexCount());
    std::printf("  without it        : %.3f ms/step, %.1f CG iterations/step, %.1f solves/step\n",
                1e3 * sec[0] / steps, double(it[0]) / steps, double(solves[0]) / steps);
    std::printf("  with contacts     : %.3f ms/step, %.1f CG iterations/step, %.1f solves/step\n",
                1e3 * sec[1] / steps, double(it[1]) / steps, double(solves[1]) / steps);
    std::printf("  ratio             : %.2fx time, %.2fx iterations (goals: 1.3x, 1.5x)\n",
                sec[1] / sec[0], double(it[1]) / double(std::max(1L, it[0])));
}

struct Drop {
    double seconds = 0, stretch = 0, ke = 0;
    int rejected = 0, retries = 0;
};

Drop drop(bool sphere, int substeps, int frames) {
    const TriMesh mesh =
        sphere ? makeGrid(0.5, 0.5, 24, 24, Vec3(-0.25, 0.25, -0.25), Vec3::UnitX(), Vec3::UnitZ())
               : makeGrid(0.5, 0.5, 24, 24, Vec3(-0.25, 0.25, 0.0), Vec3::UnitX(), Vec3::UnitY());
    WorldSettings ws;
    ws.substeps = substeps;
    World w(ws);
    w.addBody(std::make_unique<Cloth>("sheet", mesh, sheetMaterial()));
    Collider c = ground();
    if (sphere) {
        c.shape = ColliderShape::Sphere;
        c.radius = 0.15;
    }
    w.addCollider(c);
    Drop d;
    bool touched = false;
    const double t0 = now();
    for (int f = 1; f <= frames; ++f) {
        const FrameStats fs = w.advanceFrame(f);
        const BodyFrameStats& b = fs.bodies[0];
        d.stretch = std::max(d.stretch, b.maxStretch);
        if (touched && f >= 6) d.ke = std::max(d.ke, b.kinetic); // after the impact (frame 5)
        touched = touched || b.contacts > 0;
        d.rejected += b.rejected;
        d.retries += b.newtonRetries;
    }
    d.seconds = now() - t0;
    return d;
}

} // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::string(argv[1]) == "draped") { // the draped comparison only
        for (bool bar : {true, false})
            for (double mu : {0.0, 0.3}) drapedCost(bar, 48, 24, mu);
        return 0;
    }
    const int frames = argc > 1 ? std::atoi(argv[1]) : 48;
    contactCost(24, 0.0); // sliding contacts: S = I − nnᵀ
    contactCost(24, 0.3); // sticking contacts: S = 0
    for (bool bar : {true, false})
        for (double mu : {0.0, 0.3}) drapedCost(bar, 48, 24, mu);
    for (bool sphere : {false, true}) {
        std::printf("\n%s, %d frames (error against 16 substeps: strain and kinetic energy)\n",
                    sphere ? "flat onto a 0.15 m sphere" : "edge-first onto the ground", frames);
        const Drop ref = drop(sphere, 16, frames);
        std::printf("  substeps  seconds  stretch  strain error  KE after (mJ)  rejected  "
                    "retries\n");
        for (int s : {1, 2, 4, 8, 16}) {
            const Drop d = s == 16 ? ref : drop(sphere, s, frames);
            std::printf("  %8d  %7.3f  %7.4f  %12.4f  %13.3f  %8d  %7d\n", s, d.seconds, d.stretch,
                        (d.stretch - 1.0) - (ref.stretch - 1.0), 1e3 * d.ke, d.rejected, d.retries);
        }
    }
}
