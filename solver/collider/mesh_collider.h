// Mesh colliders ([[collider]] type = "mesh"): a closed OBJ/PLY body as a narrow-band signed
// distance volume (geometry::SdfVolume, shared with sdf() through the geometry cache), queried
// per vertex for the distance and the outward normal. The mesh is static.
#pragma once

#include "geometry/geometry.h"
#include "solver/linalg/types.h"

#include <memory>
#include <string>

namespace gale::solver {

class MeshCollider {
public:
    explicit MeshCollider(std::shared_ptr<const geometry::SdfVolume> sdf) : mSdf(std::move(sdf)) {}

    // Loads `path` (a closed mesh) and builds its SDF at `voxel` metres (cached by file and
    // voxel). Null with `error` (a sentence naming the file) when it cannot be read or built.
    static std::shared_ptr<const MeshCollider> load(const std::string& path, double voxel,
                                                    std::string& error);

    // Signed distance at x (m, negative inside; see SdfVolume for the band) and the unit
    // outward normal (the SDF's gradient).
    void query(const Vec3& x, double& distance, Vec3& normal) const;

    const geometry::SdfVolume& sdf() const { return *mSdf; }

private:
    std::shared_ptr<const geometry::SdfVolume> mSdf;
};

} // namespace gale::solver
