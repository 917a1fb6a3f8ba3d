// Mesh colliders: the SDF from the geometry cache, queried one vertex at a time.
#include "solver/collider/mesh_collider.h"

#include "geometry/cache.h"
#include "geometry/file_policy.h"

namespace gale::solver {

std::shared_ptr<const MeshCollider> MeshCollider::load(const std::string& path, double voxel,
                                                       std::string& error) {
    geometry::FrameFile file;
    if (!geometry::frameFileFor(path, file, error)) return nullptr;
    std::shared_ptr<const geometry::SdfVolume> sdf;
    if (io::IoError e = geometry::cachedSdf(file, voxel, sdf)) {
        error = "cannot use '" + path + "' as a collider: " + e.message;
        return nullptr;
    }
    return std::make_shared<const MeshCollider>(std::move(sdf));
}

void MeshCollider::query(const Vec3& x, double& distance, Vec3& normal) const {
    const double p[3] = {x.x(), x.y(), x.z()};
    double g[3];
    mSdf->sample(p, 1, &distance, g);
    normal = Vec3(g[0], g[1], g[2]);
}

} // namespace gale::solver
