// Helpers shared by the solver tests (header only, not part of the library): analytic wind
// fields that implement fields::Field directly, and small scene builders.
#pragma once

#include "fields/field.h"
#include "solver/bodies/cloth.h"
#include "solver/world/world.h"

#include <cmath>
#include <functional>
#include <memory>

namespace gale::solver::testing {

// v(x, t) from a lambda. `sanitize` = false passes NaN through unrepaired (a misbehaving field).
class LambdaField : public fields::Field {
public:
    using Fn = std::function<Vec3(const Vec3&, double)>;
    LambdaField(Fn fn, bool sanitize = true) : mFn(std::move(fn)), mSanitize(sanitize) {}
    fields::SampleStatus sample(const double* p, size_t count, const fields::SampleTime& when,
                                double* out) const override {
        fields::SampleStatus st;
        for (size_t i = 0; i < count; ++i) {
            Vec3 v = mFn(Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), when.time);
            if (mSanitize && !v.allFinite()) {
                v.setZero();
                ++st.nonFinite;
            }
            for (int k = 0; k < 3; ++k) out[3 * i + k] = v[k];
        }
        if (st.nonFinite) {
            st.ok = false;
            st.message = std::to_string(st.nonFinite) + " non-finite wind sample(s)";
        }
        return st;
    }
    std::string describe() const override { return "test field"; }

private:
    Fn mFn;
    bool mSanitize;
};

inline fields::FieldPtr constantWind(const Vec3& v) {
    return std::make_shared<LambdaField>([v](const Vec3&, double) { return v; });
}

// Vertices of a grid's column i (0-based), bottom to top.
inline std::vector<int> gridColumn(int nx, int ny, int i) {
    std::vector<int> out;
    for (int j = 0; j < ny; ++j) out.push_back(j * nx + i);
    return out;
}
inline std::vector<int> gridRow(int nx, int j) {
    std::vector<int> out;
    for (int i = 0; i < nx; ++i) out.push_back(j * nx + i);
    return out;
}

// A 10 cm patch (5 × 5 vertices, 1e4 N/m, no aerodynamics) lying on a plane through the origin
// tilted by θ about z (normal (−sin θ, cos θ, 0)), the plane's friction μ and no thickness, one
// substep a frame, gravity g along −y.
inline std::unique_ptr<World> inclineWorld(double thetaDeg, double mu, double g = 9.81) {
    const double theta = thetaDeg * M_PI / 180.0;
    const Vec3 normal(-std::sin(theta), std::cos(theta), 0.0);
    const Vec3 down(-std::cos(theta), -std::sin(theta), 0.0); // along the slope, downhill
    Collider plane;
    plane.a = fields::Param(std::vector<double>{0, 0, 0});
    plane.normal = fields::Param(std::vector<double>{normal.x(), normal.y(), normal.z()});
    plane.friction = mu;
    plane.thickness = 0.0;
    ClothMaterial m;
    m.lift.value = fields::Param(0.0);
    m.drag.value = fields::Param(0.0);
    m.stretch = fields::Param(1e4);
    WorldSettings ws;
    ws.gravity = Vec3(0, -g, 0);
    ws.substeps = 1;
    auto w = std::make_unique<World>(ws);
    w->addBody(std::make_unique<Cloth>(
        "patch", makeGrid(0.1, 0.1, 5, 5, Vec3::Zero(), -down, Vec3::UnitZ()), m));
    w->addCollider(plane);
    return w;
}

inline bool allFinite(const VecX& v) { return v.allFinite(); }

} // namespace gale::solver::testing
