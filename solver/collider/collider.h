// Analytic colliders — plane, sphere, capsule — with keyframable placement, a contact
// thickness and Coulomb friction. Queried per vertex only when a scene has colliders.
#pragma once

#include "fields/keyframes.h"
#include "solver/linalg/types.h"

#include <memory>
#include <string>

namespace gale::solver {

class MeshCollider;      // solver/collider/mesh_collider.h
class MovingMeshContact; // solver/collider/moving_collider.h

enum class ColliderShape { Plane, Sphere, Capsule, Mesh };

struct Collider {
    std::string name;
    ColliderShape shape = ColliderShape::Plane;
    // Plane: `a` a point on it, `normal` its outward normal. Sphere: centre `a`. Capsule: the
    // segment from `a` to `b`. Positions may be keyframed vectors (m, seconds).
    fields::Param a{std::vector<double>{0.0, 0.0, 0.0}};
    fields::Param b{std::vector<double>{0.0, 1.0, 0.0}};
    fields::Param normal{std::vector<double>{0.0, 1.0, 0.0}};
    double radius = 0.5;    // m (sphere, capsule)
    double thickness = 0.005; // m: vertices are kept this far outside the surface
    double friction = 0.3;  // Coulomb coefficient μ (dimensionless)
    std::shared_ptr<const MeshCollider> mesh; // Mesh: the body's SDF (static)
    // Mesh from a moving sequence (`mesh = "body.#.obj"`): its triangles, tree and CCD (shared
    // state, prepared per substep; then `mesh` is null).
    std::shared_ptr<MovingMeshContact> moving;
    int line = 0, col = 0; // where the scene file wrote it (0: not from a file)
};

// A contact query: signed distance to the surface (m, negative inside), the outward unit
// normal at the closest point, and the surface velocity there (m/s, from the keyframes).
struct ContactPoint {
    double distance = 0.0;
    Vec3 normal = Vec3::UnitY();
    Vec3 velocity = Vec3::Zero();
    int triangle = -1; // a moving mesh's triangle the closest point is on (-1: none or other)
};

// Collider placement at a time, resolved once per query batch.
struct ColliderPose {
    ColliderShape shape = ColliderShape::Plane;
    Vec3 a = Vec3::Zero(), b = Vec3::Zero(), normal = Vec3::UnitY();
    Vec3 velA = Vec3::Zero(), velB = Vec3::Zero(); // m/s of a and b (finite difference of keys)
    double radius = 0.0;
    const MeshCollider* mesh = nullptr;
    const MovingMeshContact* moving = nullptr; // at the start (atEnd false) or end of its step
    bool atEnd = false;
    double searchRadius = 0.0; // m: how far a moving mesh is searched for the closest point
};
ColliderPose colliderPose(const Collider& c, double t);

// Signed distance, normal and surface velocity at point x.
// `hint`: a moving mesh's triangle likely closest (an earlier answer's `triangle`), searched
// first; the answer is the same with or without it.
ContactPoint queryCollider(const ColliderPose& pose, const Vec3& x, int hint = -1);

// The largest jump the collider's step-keyed position makes within (t0, t1] (m: its `a`, or its
// `b`; fields::Param::stepJump), the key's time in `at`, and whether it was `b` in `ofB`; 0 when
// none (a teleport: scene checks warn of it, frame trouble blames the scene for it).
double colliderStepJump(const Collider& c, double t0, double t1, double& at, bool& ofB);

} // namespace gale::solver
