// Rest shapes for bending: a hinge with a curved rest keeps zero energy at its rest fold under
// rigid motion and has the closed-form energy ½ c (2|e|)² (sin(θ/2) − sin(θ₀/2))² folded to θ; a
// pre-curved sheet in zero gravity keeps its curvature with rest_shape "mesh" and unrolls with
// "flat"; a curled strand keeps its turning angles, a straight-rest one straightens.
#include "solver/bodies/cloth.h"
#include "solver/bodies/elastic.h"
#include "solver/bodies/hair.h"
#include "solver/world/world.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace gale::solver;
using gale::fields::Param;

namespace {

double curvedHingeEnergy(const HingeRest& r, const Vec3 x[4], double kb) {
    Vec3 s = Vec3::Zero();
    for (int a = 0; a < 4; ++a) s += r.k[a] * x[a];
    return 0.5 * kb * r.scale * (s - hingeFrame(x) * r.bent).squaredNorm();
}

// A half-cylinder of radius R (axis along y, arc in xz), nu × nv vertices, flat-grid topology.
TriMesh halfCylinder(double R, double width, int nu, int nv) {
    TriMesh m = makeGrid(M_PI * R, width, nu, nv);
    m.uv.clear();
    m.uvIsMaterialSpace = false;
    for (size_t i = 0; i < m.vertexCount(); ++i) {
        const double u = m.positions[3 * i] / R;
        m.positions[3 * i] = R * std::sin(u);
        m.positions[3 * i + 2] = R * (1.0 - std::cos(u));
    }
    return m;
}

// Distance between the two straight edges of the sheet (mean over rows): 2R while it keeps the
// half-cylinder, π R when flat.
double edgeGap(const Cloth& c, int nu, int nv) {
    double sum = 0.0;
    for (int j = 0; j < nv; ++j)
        sum +=
            (vec3At(c.positions().data(), j * nu + nu - 1) - vec3At(c.positions().data(), j * nu))
                .norm();
    return sum / nv;
}

} // namespace

TEST_CASE("rest shape: a curved hinge, closed form", "[elastic][rest]") {
    const double L = 0.2, a = 0.07, b = 0.11, kb = 0.003, th0 = 0.8;
    const Vec3 flat[4] = {Vec3(0, 0, 0), Vec3(0, L, 0), Vec3(a, 0.3 * L, 0), Vec3(-b, 0.6 * L, 0)};
    auto folded = [&](double th, Vec3 x[4]) {
        const Mat3 R = Eigen::AngleAxisd(th, Vec3::UnitY()).toRotationMatrix();
        x[0] = flat[0];
        x[1] = flat[1];
        x[2] = flat[2];
        x[3] = R * flat[3];
    };
    Vec3 rest[4];
    folded(th0, rest);
    HingeRest hr;
    REQUIRE(makeHingeRest(rest, hr));
    setHingeRestShape(rest, hr);
    // |s̄| = 2 L sin(θ₀/2), along the bisector normal (the frame's second axis).
    CHECK(hr.bent.norm() == Approx(2.0 * L * std::sin(th0 / 2)).epsilon(1e-9));
    CHECK(std::abs(hr.bent.y()) == Approx(hr.bent.norm()).epsilon(1e-9));
    CHECK(curvedHingeEnergy(hr, rest, kb) == Approx(0.0).margin(1e-18));
    // Rigidly moved: still zero.
    const Mat3 Q = Eigen::AngleAxisd(1.1, Vec3(1, 2, 0).normalized()).toRotationMatrix();
    Vec3 moved[4];
    for (int i = 0; i < 4; ++i) moved[i] = Q * rest[i] + Vec3(0.3, -1, 2);
    CHECK(curvedHingeEnergy(hr, moved, kb) == Approx(0.0).margin(1e-18));
    const double A0 = 0.5 * L * a, A1 = 0.5 * L * b, c = kb * 3.0 / (A0 + A1);
    for (double th : {0.0, 0.3, th0 + 0.4, -th0}) {
        Vec3 x[4];
        folded(th, x);
        const double want =
            0.5 * c * 4.0 * L * L * std::pow(std::sin(th / 2) - std::sin(th0 / 2), 2);
        CHECK(curvedHingeEnergy(hr, x, kb) == Approx(want).epsilon(1e-9).margin(1e-18));
    }
    // A flat rest hinge stays the flat model (bent = 0).
    HingeRest hf;
    REQUIRE(makeHingeRest(flat, hf));
    setHingeRestShape(flat, hf);
    CHECK(hf.bent.norm() == 0.0);
}

TEST_CASE("rest shape: a pre-curved sheet keeps its shape with \"mesh\", unrolls with \"flat\"",
          "[cloth][rest]") {
    const double R = 0.1;
    const int nu = 17, nv = 5;
    double gap[2];
    for (int curved = 0; curved < 2; ++curved) {
        ClothMaterial mat;
        mat.lift.value = Param(0.0);
        mat.drag.value = Param(0.0);
        mat.bend = Param(2e-4);
        mat.curvedRest = curved == 1;
        auto cloth = std::make_unique<Cloth>("shell", halfCylinder(R, 0.1, nu, nv), mat);
        Cloth* c = cloth.get();
        CHECK(edgeGap(*c, nu, nv) == Approx(2.0 * R).epsilon(1e-9));
        // Kicked: the two straight edges thrown apart at 0.3 m/s (so the rest shape must
        // restore, not merely be left alone).
        VecX v = VecX::Zero(c->positions().size());
        for (int j = 0; j < nv; ++j) {
            v[3 * (j * nu)] = -0.3;
            v[3 * (j * nu + nu - 1)] = 0.3;
        }
        c->setVelocities(v);
        WorldSettings ws;
        ws.fps = 24;
        ws.substeps = 4;
        ws.gravity = Vec3::Zero();
        World world(ws);
        world.addBody(std::move(cloth));
        for (int f = 1; f <= 48; ++f) REQUIRE(!world.advanceFrame(f).failed);
        gap[curved] = edgeGap(*c, nu, nv);
        INFO("curved " << curved << " gap " << gap[curved]);
        if (curved)
            CHECK(std::abs(gap[curved] - 2.0 * R) < 0.02 * R); // within 2% of the half-cylinder
        else
            CHECK(gap[curved] > 2.0 * R + 0.5 * (M_PI - 2.0) * R); // more than halfway to flat
    }
}

TEST_CASE("rest shape: a curled strand keeps its curl, a straight-rest one straightens",
          "[hair][rest]") {
    // A helix of 24 segments (radius 2 cm, pitch 2 cm/turn, 2 turns), root pinned, no gravity.
    Strands s;
    const int segs = 24;
    for (int i = 0; i <= segs; ++i) {
        const double phi = 4.0 * M_PI * i / segs;
        s.positions.insert(s.positions.end(),
                           {0.02 * std::cos(phi), -0.02 * phi / (2 * M_PI), 0.02 * std::sin(phi)});
    }
    s.offsets = {0, segs + 1};
    auto turning = [&](const VecX& x, int i) {
        const Vec3 a = vec3At(x.data(), i) - vec3At(x.data(), i - 1),
                   b = vec3At(x.data(), i + 1) - vec3At(x.data(), i);
        return std::atan2(a.cross(b).norm(), a.dot(b));
    };
    VecX x0 = Eigen::Map<const VecX>(s.positions.data(), static_cast<long>(s.positions.size()));
    const double turn0 = turning(x0, 12);
    REQUIRE(turn0 > 0.4);
    for (int curl = 0; curl < 2; ++curl) {
        HairMaterial mat;
        mat.dragNormal.value = Param(0.0);
        mat.dragTangent.value = Param(0.0);
        mat.curledRest = curl == 1;
        mat.radius = 2e-4;
        mat.bend = Param(1e-6);
        auto hair = std::make_unique<Hair>("curl", s, mat);
        Hair* h = hair.get();
        VecX v = VecX::Zero(h->positions().size());
        v[3 * segs] = 0.2; // the tip kicked sideways
        h->setVelocities(v);
        WorldSettings ws;
        ws.fps = 24;
        ws.substeps = 4;
        ws.gravity = Vec3::Zero();
        World world(ws);
        world.addBody(std::move(hair));
        for (int f = 1; f <= 48; ++f) REQUIRE(!world.advanceFrame(f).failed);
        double worst = 0.0, mean = 0.0;
        for (int i = 1; i < segs; ++i) {
            const double d = std::abs(turning(h->positions(), i) - turn0);
            worst = std::max(worst, d);
            mean += turning(h->positions(), i) / (segs - 1);
        }
        INFO("curl " << curl << " worst " << worst << " mean " << mean << " rest " << turn0);
        if (curl)
            CHECK(worst < 0.05 * turn0);
        else
            CHECK(mean < 0.5 * turn0);
    }
}
