// Mesh geometry through OpenVDB (one of the two translation units that include its slow
// headers): narrow-band SDFs from meshToLevelSet, their sampling (distance, gradient, the wind
// shadow march) and the closest-triangle index grid behind meshvel().
#include "geometry/geometry.h"

#include "io/atomic_file.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <cmath>
#include <exception>

namespace gale::geometry {

namespace {

void initOpenVdb() {
    static const bool done = [] {
        openvdb::initialize();
        return true;
    }();
    (void)done;
}

io::IoError dataError(const std::string& name, const std::string& message) {
    io::IoError e;
    e.kind = io::IoError::Data;
    e.file = name;
    e.message = message;
    return e;
}

double smoothstep(double lo, double hi, double x) {
    if (x <= lo) return 0.0;
    if (x >= hi) return 1.0;
    const double u = (x - lo) / (hi - lo);
    return u * u * (3.0 - 2.0 * u);
}

// The mesh as OpenVDB wants it; false when an index is out of range.
bool toVdb(const TriangleMesh& mesh, std::vector<openvdb::Vec3s>& points,
           std::vector<openvdb::Vec3I>& triangles) {
    points.resize(mesh.points.size());
    for (size_t i = 0; i < mesh.points.size(); ++i)
        points[i] = openvdb::Vec3s(mesh.points[i][0], mesh.points[i][1], mesh.points[i][2]);
    triangles.resize(mesh.triangles.size());
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k)
            if (mesh.triangles[i][k] >= mesh.points.size()) return false;
        triangles[i] =
            openvdb::Vec3I(mesh.triangles[i][0], mesh.triangles[i][1], mesh.triangles[i][2]);
    }
    return true;
}

double surfaceArea(const TriangleMesh& mesh) {
    double area = 0.0;
    for (const auto& t : mesh.triangles) {
        const auto& a = mesh.points[t[0]];
        const auto& b = mesh.points[t[1]];
        const auto& c = mesh.points[t[2]];
        const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
        const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
                     z = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * std::sqrt(x * x + y * y + z * z);
    }
    return area;
}

std::string voxelText(double v) {
    return io::formatNumber(v);
}

io::IoError checkBuildInputs(const TriangleMesh& mesh, double voxel, const std::string& name) {
    if (mesh.triangles.empty() || mesh.points.empty())
        return dataError(name, "the mesh has no triangles");
    if (!(voxel > 0.0) || !std::isfinite(voxel))
        return dataError(name, "the voxel size must be a positive number, not " + voxelText(voxel));
    return {};
}

} // namespace

// ---- SdfVolume ----

struct SdfVolume::Impl {
    openvdb::FloatGrid::Ptr grid;
    double voxel = 0.0;
    double band = 0.0; // metres
    std::array<double, 6> box{};
    size_t activeVoxels = 0;
    size_t memoryBytes = 0;

    // Distance from p to the mesh's bounding box (0 inside it), and the unit direction away
    // from the box (from the closest box point, or from the box centre inside).
    double boxDistance(const double* p, double* away) const {
        double d2 = 0.0, q[3];
        for (int a = 0; a < 3; ++a) {
            q[a] = std::clamp(p[a], box[a], box[3 + a]);
            d2 += (p[a] - q[a]) * (p[a] - q[a]);
        }
        if (away) {
            double v[3], len2 = 0.0;
            for (int a = 0; a < 3; ++a) {
                v[a] = d2 > 0.0 ? p[a] - q[a] : p[a] - 0.5 * (box[a] + box[3 + a]);
                len2 += v[a] * v[a];
            }
            const double len = std::sqrt(len2);
            for (int a = 0; a < 3; ++a) away[a] = len > 0.0 ? v[a] / len : (a == 1 ? 1.0 : 0.0);
        }
        return std::sqrt(d2);
    }

    // The extended distance at p (see the header): trilinear inside the band, continued
    // outside by the box distance.
    template <class Accessor>
    double distance(Accessor& acc, const double* p) const {
        const openvdb::Vec3d index(p[0] / voxel, p[1] / voxel, p[2] / voxel);
        float phi = 0.0f;
        openvdb::tools::BoxSampler::sample(acc, index, phi);
        const double d = static_cast<double>(phi);
        if (d <= 0.0) return d;
        return std::max(d, boxDistance(p, nullptr));
    }
};

SdfVolume::SdfVolume(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
SdfVolume::~SdfVolume() = default;

io::IoError SdfVolume::build(const TriangleMesh& mesh, const SdfOptions& options,
                             std::shared_ptr<const SdfVolume>& out, const std::string& name) {
    if (io::IoError e = checkBuildInputs(mesh, options.voxel, name)) return e;
    const double voxel = options.voxel;
    const int bandVoxels =
        options.bandVoxels > 0 ? options.bandVoxels : automaticBandVoxels(mesh, voxel);
    // Active voxels ~ area * 2 * band / voxel^3, plus the leaves' slack.
    const double estimate = surfaceArea(mesh) * 2.0 * bandVoxels / (voxel * voxel);
    if (estimate > kMaxSdfVoxels)
        return dataError(name, "a voxel size of " + voxelText(voxel) + " m needs about " +
                                   std::to_string(static_cast<long long>(estimate)) +
                                   " voxels for this mesh (the limit is " +
                                   std::to_string(static_cast<long long>(kMaxSdfVoxels)) +
                                   "); use a larger voxel");
    initOpenVdb();
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    if (!toVdb(mesh, points, triangles)) return dataError(name, "a triangle index is out of range");
    auto impl = std::make_unique<Impl>();
    try {
        openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(voxel);
        impl->grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(
            *xf, points, triangles, static_cast<float>(bandVoxels));
    } catch (const std::exception& e) {
        return dataError(name, std::string("cannot build the signed distance volume: ") + e.what());
    }
    if (!impl->grid || impl->grid->activeVoxelCount() == 0)
        return dataError(name, "the signed distance volume is empty (is the voxel size of " +
                                   voxelText(voxel) + " m much larger than the mesh?)");
    impl->voxel = voxel;
    impl->band = bandVoxels * voxel;
    impl->box = mesh.bounds();
    impl->activeVoxels = static_cast<size_t>(impl->grid->activeVoxelCount());
    impl->memoryBytes = static_cast<size_t>(impl->grid->memUsage());
    out = std::shared_ptr<const SdfVolume>(new SdfVolume(std::move(impl)));
    return {};
}

void SdfVolume::sample(const double* xyz, size_t n, double* dist, double* grad) const {
    const Impl& m = *mImpl;
    auto acc = m.grid->getConstAccessor();
    const double h = m.voxel;
    for (size_t i = 0; i < n; ++i) {
        const double* p = xyz + 3 * i;
        if (dist) dist[i] = m.distance(acc, p);
        if (!grad) continue;
        double g[3], len2 = 0.0;
        for (int a = 0; a < 3; ++a) {
            double q[3] = {p[0], p[1], p[2]};
            q[a] = p[a] + h;
            const double hi = m.distance(acc, q);
            q[a] = p[a] - h;
            const double lo = m.distance(acc, q);
            g[a] = (hi - lo) / (2.0 * h);
            len2 += g[a] * g[a];
        }
        double* o = grad + 3 * i;
        const double len = std::sqrt(len2);
        if (len > 1e-3) {
            for (int a = 0; a < 3; ++a) o[a] = g[a] / len;
        } else {
            m.boxDistance(p, o);
        }
    }
}

void SdfVolume::shadow(const double* xyz, const double* dir, const double* length, size_t n,
                       double* out) const {
    const Impl& m = *mImpl;
    auto acc = m.grid->getConstAccessor();
    const double w = m.voxel;       // soft edge half-width of the blockage
    const double h = 0.5 * m.voxel; // march lattice spacing
    auto blockage = [w](double d) { return 1.0 - smoothstep(-w, w, d); };
    for (size_t i = 0; i < n; ++i) {
        const double* p = xyz + 3 * i;
        double u[3] = {dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]};
        const double ulen = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        const double L = length[i];
        const double d0 = m.distance(acc, p);
        double occlusion = blockage(d0); // P itself (weight 1)
        if (!(ulen > 0.0) || !std::isfinite(ulen) || !(L > 0.0) || !std::isfinite(L)) {
            out[i] = 1.0 - occlusion;
            continue;
        }
        for (double& c : u) c /= ulen;
        // Samples on a lattice fixed in space along the wind (points whose projection on u is
        // a multiple of h), so moving P downwind only lowers every weight: monotone shadows.
        const double along = p[0] * u[0] + p[1] * u[1] + p[2] * u[2];
        double s = along - h * std::floor(along / h);
        if (s == 0.0) s = h;
        while (s <= L) {
            const double weight = 1.0 - smoothstep(0.0, L, s);
            if (weight <= occlusion) break; // no later sample can raise it
            const double q[3] = {p[0] - s * u[0], p[1] - s * u[1], p[2] - s * u[2]};
            const double d = m.distance(acc, q);
            occlusion = std::max(occlusion, blockage(d) * weight);
            // The distance is a lower bound of the true one: every point closer than d - w is
            // in free air (blockage 0), so skip to the first lattice point beyond.
            const double skip = d - w;
            s += skip > h ? h * std::floor(skip / h) : h;
        }
        out[i] = 1.0 - occlusion;
    }
}

io::IoError SdfVolume::writeVdb(const std::string& path, const std::string& gridName) const {
    openvdb::FloatGrid::Ptr grid = mImpl->grid->deepCopy();
    grid->setName(gridName);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return io::writeFileAtomic(path, [&](const std::string& tmp) -> io::IoError {
        try {
            openvdb::io::File file(tmp);
            file.write(openvdb::GridPtrVec{grid});
            file.close();
        } catch (const std::exception& e) {
            io::IoError err;
            err.kind = io::IoError::Io;
            err.file = path;
            err.message = std::string("cannot write: ") + e.what();
            return err;
        }
        return {};
    });
}

double SdfVolume::voxel() const {
    return mImpl->voxel;
}
double SdfVolume::band() const {
    return mImpl->band;
}
const std::array<double, 6>& SdfVolume::meshBounds() const {
    return mImpl->box;
}
size_t SdfVolume::activeVoxels() const {
    return mImpl->activeVoxels;
}
size_t SdfVolume::memoryBytes() const {
    return mImpl->memoryBytes;
}

// ---- ClosestTriangleIndex ----

struct ClosestTriangleIndex::Impl {
    openvdb::Int32Grid::Ptr grid;
    double voxel = 0.0;
    size_t memoryBytes = 0;
};

ClosestTriangleIndex::ClosestTriangleIndex(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
ClosestTriangleIndex::~ClosestTriangleIndex() = default;

io::IoError ClosestTriangleIndex::build(const TriangleMesh& mesh, double voxel, double reach,
                                        std::shared_ptr<const ClosestTriangleIndex>& out,
                                        const std::string& name) {
    if (io::IoError e = checkBuildInputs(mesh, voxel, name)) return e;
    const double bandVoxels = std::ceil(std::max(reach, 0.0) / voxel) + 2.0;
    const double estimate = surfaceArea(mesh) * 2.0 * bandVoxels / (voxel * voxel);
    if (estimate > kMaxSdfVoxels)
        return dataError(name, "a reach of " + voxelText(reach) + " m at a voxel size of " +
                                   voxelText(voxel) + " m needs about " +
                                   std::to_string(static_cast<long long>(estimate)) +
                                   " voxels for this mesh; use a larger voxel or a shorter reach");
    initOpenVdb();
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    if (!toVdb(mesh, points, triangles)) return dataError(name, "a triangle index is out of range");
    auto impl = std::make_unique<Impl>();
    try {
        openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(voxel);
        impl->grid = openvdb::Int32Grid::create(-1);
        impl->grid->setTransform(xf);
        openvdb::util::NullInterrupter interrupter;
        // meshToVolume takes index-space points (meshToLevelSet converts them itself).
        for (openvdb::Vec3s& p : points) p = openvdb::Vec3s(xf->worldToIndex(p));
        openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(
            points, triangles);
        // An unsigned distance: meshvel() also works on open surfaces (a cape).
        openvdb::tools::meshToVolume<openvdb::FloatGrid>(
            interrupter, adapter, *xf, static_cast<float>(bandVoxels),
            static_cast<float>(bandVoxels), openvdb::tools::UNSIGNED_DISTANCE_FIELD,
            impl->grid.get());
    } catch (const std::exception& e) {
        return dataError(name, std::string("cannot build the closest-triangle index: ") + e.what());
    }
    impl->voxel = voxel;
    impl->memoryBytes = static_cast<size_t>(impl->grid->memUsage());
    out = std::shared_ptr<const ClosestTriangleIndex>(new ClosestTriangleIndex(std::move(impl)));
    return {};
}

void ClosestTriangleIndex::candidates(const double* xyz, size_t n, int32_t* out) const {
    const Impl& m = *mImpl;
    auto acc = m.grid->getConstAccessor();
    for (size_t i = 0; i < n; ++i) {
        const double* p = xyz + 3 * i;
        const double g[3] = {std::floor(p[0] / m.voxel), std::floor(p[1] / m.voxel),
                             std::floor(p[2] / m.voxel)};
        // A NaN or far-away point has no candidates (and must not be converted to int).
        if (!(std::fabs(g[0]) < 1e9 && std::fabs(g[1]) < 1e9 && std::fabs(g[2]) < 1e9)) {
            for (int c = 0; c < 8; ++c) out[8 * i + static_cast<size_t>(c)] = -1;
            continue;
        }
        const openvdb::Coord base(static_cast<int>(g[0]), static_cast<int>(g[1]),
                                  static_cast<int>(g[2]));
        for (int c = 0; c < 8; ++c) {
            const openvdb::Coord q = base.offsetBy(c & 1, (c >> 1) & 1, (c >> 2) & 1);
            int32_t v = -1;
            out[8 * i + static_cast<size_t>(c)] = acc.probeValue(q, v) ? v : -1;
        }
    }
}

double ClosestTriangleIndex::voxel() const {
    return mImpl->voxel;
}
size_t ClosestTriangleIndex::memoryBytes() const {
    return mImpl->memoryBytes;
}

} // namespace gale::geometry
