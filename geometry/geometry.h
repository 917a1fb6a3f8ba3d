// Geometry as fields, behind an OpenVDB-free interface: triangle meshes read from OBJ/PLY, their
// narrow-band signed distance volumes (SdfVolume: distance, gradient, wind shadow), velocity
// volumes read from .vdb files (VelocityVolume) and the closest-triangle index behind meshvel().
// The OpenVDB code lives in vdb_geometry.cpp (SDF, closest triangle) and vdb_io.cpp (.vdb files).
#pragma once

#include "io/pointset.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace gale::geometry {

// A triangle soup with shared vertices (float positions, what OpenVDB consumes).
struct TriangleMesh {
    std::vector<std::array<float, 3>> points;
    std::vector<std::array<uint32_t, 3>> triangles;

    // {x0,y0,z0,x1,y1,z1} of the points (all zero when there are none).
    std::array<double, 6> bounds() const;
};

// Reads an OBJ or PLY mesh (by extension) and fans every polygon into triangles. Errors: Io when
// the file cannot be read; Data when it is malformed, has no faces, has a face with fewer than
// three corners or an index out of range, or a non-finite vertex.
io::IoError readTriangleMesh(const std::string& path, TriangleMesh& out);

// Closed meshes for tests, benchmarks and examples: a UV sphere (`rings` latitude bands,
// `segments` longitude slices) and an axis-aligned box (12 triangles), both outward-facing.
TriangleMesh uvSphereMesh(const std::array<double, 3>& centre, double radius, int rings,
                          int segments);
TriangleMesh boxMesh(const std::array<double, 3>& lo, const std::array<double, 3>& hi);

// Writes `v` and `f` lines (1-based indices) through a temporary file and a rename.
io::IoError writeTriangleMeshObj(const std::string& path, const TriangleMesh& mesh);

// The point of triangle (a, b, c) closest to p, with its barycentric weights (wa + wb + wc = 1).
std::array<double, 3> closestPointOnTriangle(const std::array<double, 3>& p,
                                             const std::array<double, 3>& a,
                                             const std::array<double, 3>& b,
                                             const std::array<double, 3>& c,
                                             std::array<double, 3>& weights);

// Narrow-band width of an SDF when SdfOptions::bandVoxels is 0: a quarter of the mesh's bounding
// box diagonal, in voxels, clamped to [3, 64].
int automaticBandVoxels(const TriangleMesh& mesh, double voxel);

struct SdfOptions {
    double voxel = 0.02; // m
    int bandVoxels = 0;  // half-width of the narrow band in voxels; 0: automaticBandVoxels
};

// The largest SDF (active voxels, estimated before building) SdfVolume::build accepts.
constexpr double kMaxSdfVoxels = 2.0e8;

// A signed distance volume of a closed triangle mesh (negative inside), stored as an OpenVDB
// narrow-band level set: exact distances at voxel centres within `band` of the surface,
// trilinear in between. Beyond the band the distance is max(band, distance to the mesh's
// bounding box) outside (a continuous lower bound of the true distance that keeps growing) and
// -band inside. Immutable once built; sample() may be called from many threads at once (each
// call uses its own accessor).
class SdfVolume {
public:
    struct Impl;
    ~SdfVolume();

    // Errors (Data, naming `name`): an empty mesh, a voxel size that is not positive and
    // finite, a band too large for kMaxSdfVoxels, or an OpenVDB failure.
    static io::IoError build(const TriangleMesh& mesh, const SdfOptions& options,
                             std::shared_ptr<const SdfVolume>& out, const std::string& name = {});

    // For n points xyz[3i..3i+2]: dist[i] (m) and the unit gradient grad[3i..] (central
    // differences of the distance one voxel apart; where those vanish — deep inside, or beyond
    // the band near the box — the direction away from the box). Either output may be null.
    void sample(const double* xyz, size_t n, double* dist, double* grad) const;

    // Wind shadow at n points (see docs/geometry.md): marching upwind from P along -dir[3i..]
    // over length[i] metres, shadow = 1 - max_s b(d(P - s dir)) * (1 - smoothstep(0, L, s)) with
    // b(d) = 1 - smoothstep(-w, w, d) the soft blockage (w = one voxel). 1 in free air, 0
    // inside the body and just behind it, rising monotonically to 1 at `length` downwind.
    void shadow(const double* xyz, const double* dir, const double* length, size_t n,
                double* out) const;

    // Writes the level set as a .vdb file (one float grid named `gridName`, class level set) for
    // inspection in Houdini or Blender; atomic like every gale output.
    io::IoError writeVdb(const std::string& path, const std::string& gridName = "surface") const;

    double voxel() const;
    double band() const; // metres
    const std::array<double, 6>& meshBounds() const;
    size_t activeVoxels() const;
    size_t memoryBytes() const;

private:
    explicit SdfVolume(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

// For meshvel(): which triangle of a mesh is closest to each voxel centre within `reach` metres
// of the surface (OpenVDB's polygon index grid from meshToVolume). Thread-safe like SdfVolume.
class ClosestTriangleIndex {
public:
    struct Impl;
    ~ClosestTriangleIndex();

    static io::IoError build(const TriangleMesh& mesh, double voxel, double reach,
                             std::shared_ptr<const ClosestTriangleIndex>& out,
                             const std::string& name = {});

    // For each point, the closest-triangle indices of the 8 voxel centres around it
    // (out[8i..8i+7]; -1 where a centre is beyond the reach).
    void candidates(const double* xyz, size_t n, int32_t* out) const;

    double voxel() const;
    size_t memoryBytes() const;

private:
    explicit ClosestTriangleIndex(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

// Sampling interpolation for velocity volumes.
enum class VolumeInterp { Nearest = 0, Trilinear = 1, Quadratic = 2 };

// A vector grid read from a .vdb file (Vec3s or Vec3d), sampled in world space through the
// grid's own transform (any linear transform: scale, rotation, translation). Values outside
// the active voxels are the grid's background (zero for gale's files). Thread-safe.
class VelocityVolume {
public:
    struct Impl;
    ~VelocityVolume();

    // Loads the grid named `gridName` (empty: the first vector grid). Errors: Io when the file
    // cannot be opened or is not a readable VDB file (truncated, corrupt); Data when the grid
    // is missing (the message lists the grids there are), holds non-vector values, or has a
    // non-linear (frustum) transform.
    static io::IoError load(const std::string& path, const std::string& gridName,
                            std::shared_ptr<const VelocityVolume>& out);

    // vel[3i..3i+2] at xyz[3i..3i+2].
    void sample(const double* xyz, size_t n, VolumeInterp interp, double* vel) const;

    const std::string& gridName() const;
    size_t memoryBytes() const;

private:
    explicit VelocityVolume(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

// Checks, from the file header and grid descriptors only (no voxel data), that `path` is a VDB
// file holding a vector grid named `gridName` (empty: any vector grid); the same errors as
// VelocityVolume::load.
io::IoError checkVdbGrid(const std::string& path, const std::string& gridName);

} // namespace gale::geometry
