// Signed distances of the analytic colliders and their surface velocities.
#include "solver/collider/collider.h"
#include "solver/collider/mesh_collider.h"
#include "solver/collider/moving_collider.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {
Vec3 vecParam(const fields::Param& p, double t) {
    const std::vector<double> v = p.at(t);
    if (v.size() >= 3) return Vec3(v[0], v[1], v[2]);
    const double s = v.empty() ? 0.0 : v[0];
    return Vec3(s, s, s);
}
// Velocity of a keyframed vector by a central difference over 1 ms (zero when constant).
Vec3 vecParamVelocity(const fields::Param& p, double t) {
    if (!p.isKeyed()) return Vec3::Zero();
    const double d = 1e-3;
    return (vecParam(p, t + d) - vecParam(p, t - d)) / (2.0 * d);
}
} // namespace

ColliderPose colliderPose(const Collider& c, double t) {
    ColliderPose p;
    p.shape = c.shape;
    p.a = vecParam(c.a, t);
    p.b = vecParam(c.b, t);
    p.velA = vecParamVelocity(c.a, t);
    p.velB = vecParamVelocity(c.b, t);
    p.normal = vecParam(c.normal, t);
    const double nn = p.normal.norm();
    p.normal = nn > 0.0 ? Vec3(p.normal / nn) : Vec3::UnitY();
    p.radius = c.radius;
    p.mesh = c.mesh.get();
    if (c.moving) {
        p.moving = c.moving.get();
        p.atEnd = !(t <= c.moving->t0());
        p.searchRadius = 2.0 * c.thickness + 1e-3;
    }
    return p;
}

double colliderStepJump(const Collider& c, double t0, double t1, double& at, bool& ofB) {
    double atA = 0.0, atB = 0.0;
    const double a = c.a.stepJump(t0, t1, &atA), b = c.b.stepJump(t0, t1, &atB);
    ofB = b > a;
    at = ofB ? atB : atA;
    return std::max(a, b);
}

ContactPoint queryCollider(const ColliderPose& pose, const Vec3& x, int hint) {
    ContactPoint cp;
    switch (pose.shape) {
    case ColliderShape::Plane:
        cp.distance = (x - pose.a).dot(pose.normal);
        cp.normal = pose.normal;
        cp.velocity = pose.velA;
        break;
    case ColliderShape::Sphere: {
        const Vec3 d = x - pose.a;
        const double len = d.norm();
        cp.normal = len > 0.0 ? Vec3(d / len) : Vec3::UnitY();
        cp.distance = len - pose.radius;
        cp.velocity = pose.velA;
        break;
    }
    case ColliderShape::Capsule: {
        const Vec3 ab = pose.b - pose.a;
        const double l2 = ab.squaredNorm();
        const double s = l2 > 0.0 ? std::clamp((x - pose.a).dot(ab) / l2, 0.0, 1.0) : 0.0;
        const Vec3 c = pose.a + s * ab;
        const Vec3 d = x - c;
        const double len = d.norm();
        Vec3 fallback = ab.cross(Vec3::UnitX());
        if (fallback.squaredNorm() < 1e-12) fallback = ab.cross(Vec3::UnitY());
        if (fallback.squaredNorm() < 1e-12) fallback = Vec3::UnitY();
        cp.normal = len > 0.0 ? Vec3(d / len) : Vec3(fallback.normalized());
        cp.distance = len - pose.radius;
        cp.velocity = (1.0 - s) * pose.velA + s * pose.velB;
        break;
    }
    case ColliderShape::Mesh:
        if (pose.moving)
            pose.moving->closest(x, pose.atEnd, pose.searchRadius, cp, hint); // inf when far
        else if (pose.mesh) pose.mesh->query(x, cp.distance, cp.normal);
        else cp.distance = 1e30; // not loaded: never touches
        break;
    }
    return cp;
}

} // namespace gale::solver
