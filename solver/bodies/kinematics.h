// What is scripted in a substep — pin and attachment targets, collider placements, moving mesh
// sequences — evaluated once for the substep [t0, t1] into one plain structure that the step
// reads (Body::substep): nothing inside the step evaluates keys or sequences again.
#pragma once

#include "solver/collider/collider.h"
#include "solver/linalg/types.h"

#include <vector>

namespace gale::solver {

// One collider as a body sees it over a substep.
struct ColliderMotion {
    ColliderPose start;     // placement at t0: where contact constraints of the solve are made
    ColliderPose end;       // placement at t1: where positions are pushed out after the solve
    double thickness = 0.0; // m: kept from it by this body (Body::colliderThickness)
};

struct StepKinematics {
    double t0 = 0.0, t1 = 0.0;             // s
    std::vector<Vec3> pinTargets;          // per pin (Body::pinnedVertices order): at t1 (m)
    std::vector<ColliderMotion> colliders; // per collider of the environment, in its order
};

} // namespace gale::solver
