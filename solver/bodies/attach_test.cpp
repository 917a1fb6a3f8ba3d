// Attachments: cloth vertices bound to a body that turns and translates follow their bound
// points (the closed-form rigid motion of the body) within 1 mm at every frame, as hard
// constraints, while the rest of the cape moves freely; hair roots attach the same way.
#include "solver/bodies/cloth.h"
#include "solver/bodies/hair.h"
#include "solver/mesh/mesh_sequence.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale::solver;
using gale::fields::Param;

namespace {

// A 0.4 × 0.4 × 0.4 box centred at the origin ("shoulders"), turning about y at 90°/s and
// walking along x at 1 m/s, frames 0..frames at fps.
Mat3 turn(double t) {
    return Eigen::AngleAxisd(0.5 * M_PI * t, Vec3::UnitY()).toRotationMatrix();
}
Vec3 walk(double t) {
    return Vec3(1.0 * t, 0.0, 0.0);
}

std::shared_ptr<const MeshSequence> turningBox(int frames, double fps) {
    std::vector<double> p;
    for (int k = 0; k < 8; ++k)
        p.insert(p.end(), {(k & 1) ? 0.2 : -0.2, (k & 2) ? 0.2 : -0.2, (k & 4) ? 0.2 : -0.2});
    const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    std::vector<std::array<int, 3>> tris;
    for (auto& f : q) {
        tris.push_back({f[0], f[1], f[2]});
        tris.push_back({f[0], f[2], f[3]});
    }
    std::vector<std::vector<double>> pos;
    for (int f = 0; f <= frames; ++f) {
        const double t = f / fps;
        std::vector<double> x(p.size());
        for (int v = 0; v < 8; ++v) {
            const Vec3 y = turn(t) * vec3At(p.data(), v) + walk(t);
            for (int c = 0; c < 3; ++c) x[3 * v + c] = y[c];
        }
        pos.push_back(std::move(x));
    }
    return std::make_shared<MeshSequence>(tris, pos, 0, fps);
}

} // namespace

TEST_CASE("attach: cloth bound to a turning, walking body stays within 1 mm", "[attach]") {
    const double fps = 24.0;
    auto body = turningBox(30, fps);
    // A cape hanging from the box's back-top edge: its top row 1 mm behind the back face
    // (z = −0.201), over y ∈ [0.15, 0.2] — bound to the back face, with an offset along the normal.
    TriMesh mesh =
        makeGrid(0.4, 0.6, 9, 13, Vec3(-0.2, -0.4, -0.201), Vec3::UnitX(), Vec3::UnitY());
    ClothMaterial mat;
    auto cloth = std::make_unique<Cloth>("cape", mesh, mat);
    PinSet attach;
    for (int j = 11; j < 13; ++j)
        for (int i = 0; i < 9; ++i) attach.vertices.push_back(j * 9 + i);
    attach.attach = body;
    cloth->addPins(attach);
    Cloth* c = cloth.get();
    WorldSettings ws;
    ws.fps = fps;
    ws.substeps = 2;
    World world(ws);
    world.addBody(std::move(cloth));
    double worst = 0.0, freeMoved = 0.0;
    for (int f = 1; f <= 24; ++f) {
        REQUIRE(!world.advanceFrame(f).failed);
        const double t = f / fps;
        for (size_t k = 0; k < c->pinnedVertices().size(); ++k) {
            const int i = c->pinnedVertices()[k];
            const Vec3 want = turn(t) * mesh.position(i) + walk(t); // the rigid motion of the body
            worst = std::max(worst, (vec3At(c->positions().data(), i) - want).norm());
        }
        freeMoved = (vec3At(c->positions().data(), 4) - mesh.position(4)).norm();
    }
    INFO("worst " << worst);
    CHECK(worst < 1e-3);
    CHECK(freeMoved > 0.5); // the hem went along (turned and walked a metre)
}

TEST_CASE("attach: hair roots bound to a scalp follow it", "[attach][hair]") {
    const double fps = 24.0;
    auto body = turningBox(30, fps);
    // Strands from the box's top (y = 0.2), pointing up.
    Strands s = makeStrandGrid(Vec3(0, 0.2005, 0), 0.2, 0.2, 3, 3, 0.2, 8, Vec3::UnitX(),
                               Vec3::UnitZ(), Vec3::UnitY());
    HairMaterial mat;
    mat.rootPinned = false;
    auto hair = std::make_unique<Hair>("tuft", s, mat);
    PinSet roots;
    for (size_t k = 0; k < s.strandCount(); ++k) roots.vertices.push_back(s.offsets[k]);
    roots.attach = body;
    hair->addPins(roots);
    Hair* h = hair.get();
    WorldSettings ws;
    ws.fps = fps;
    World world(ws);
    world.addBody(std::move(hair));
    double worst = 0.0;
    for (int f = 1; f <= 24; ++f) {
        REQUIRE(!world.advanceFrame(f).failed);
        const double t = f / fps;
        for (int i : h->pinnedVertices())
            worst = std::max(worst, (vec3At(h->positions().data(), i) -
                                     (turn(t) * vec3At(s.positions.data(), i) + walk(t)))
                                        .norm());
    }
    INFO("worst " << worst);
    CHECK(worst < 1e-3);
}
