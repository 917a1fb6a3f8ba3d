// OpenVDB reading and writing of velocity grids, and the VelocityVolume behind vdb(). One of
// the two files that include OpenVDB headers (they are slow to compile; vdb_geometry.cpp is the
// other); everything else goes through geometry/vdb_io.h and geometry/geometry.h.
#include "geometry/vdb_io.h"

#include "geometry/geometry.h"

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <fstream>
#include <stdexcept>

namespace gale::geometry {

namespace {

void initOpenVdb() {
    static const bool done = [] {
        openvdb::initialize();
        return true;
    }();
    (void)done;
}

io::IoError makeError(io::IoError::Kind kind, const std::string& file, const std::string& message) {
    io::IoError e;
    e.kind = kind;
    e.file = file;
    e.message = message;
    return e;
}

std::string vectorTypeName(openvdb::VecType t) {
    switch (t) {
    case openvdb::VEC_INVARIANT:
        return "invariant";
    case openvdb::VEC_COVARIANT:
        return "covariant";
    case openvdb::VEC_COVARIANT_NORMALIZE:
        return "covariant-normalize";
    case openvdb::VEC_CONTRAVARIANT_RELATIVE:
        return "contravariant-relative";
    case openvdb::VEC_CONTRAVARIANT_ABSOLUTE:
        return "contravariant-absolute";
    }
    return "unknown";
}

std::string gridClassName(openvdb::GridClass c) {
    switch (c) {
    case openvdb::GRID_LEVEL_SET:
        return "level set";
    case openvdb::GRID_FOG_VOLUME:
        return "fog volume";
    case openvdb::GRID_STAGGERED:
        return "staggered";
    default:
        return "unknown";
    }
}

// Index (0,0,0) at the centre of cell (0,0,0); a scale by the voxel size per axis.
openvdb::math::Transform::Ptr cellCentredTransform(const io::GridSpec& grid) {
    const openvdb::Vec3d voxel(grid.voxel[0], grid.voxel[1], grid.voxel[2]);
    const openvdb::Vec3d first(grid.origin[0] + 0.5 * grid.voxel[0],
                               grid.origin[1] + 0.5 * grid.voxel[1],
                               grid.origin[2] + 0.5 * grid.voxel[2]);
    openvdb::math::Transform::Ptr xf;
    if (grid.cubicVoxels()) {
        xf = openvdb::math::Transform::createLinearTransform(grid.voxel[0]);
    } else {
        openvdb::Mat4d m = openvdb::Mat4d::identity();
        m.setToScale(voxel);
        xf = openvdb::math::Transform::createLinearTransform(m);
    }
    xf->postTranslate(first);
    return xf;
}

} // namespace

io::IoError writeVdbVelocity(const std::string& path, const io::GridSpec& spec,
                             const std::vector<float>& values, const VdbWriteOptions& options) {
    if (values.size() != 3 * spec.cellCount())
        return makeError(io::IoError::Data, path,
                         "the grid has " + std::to_string(spec.cellCount()) + " cells but " +
                             std::to_string(values.size()) + " values were given (3 per cell)");
    initOpenVdb();
    openvdb::Vec3SGrid::Ptr grid;
    try {
        grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        grid->setName(options.gridName);
        grid->setTransform(cellCentredTransform(spec));
        grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
        grid->setGridClass(openvdb::GRID_UNKNOWN);
        grid->setSaveFloatAsHalf(false);
        for (const auto& [key, text] : options.metadata)
            grid->insertMeta(key, openvdb::StringMetadata(text));
        for (const auto& [key, v] : options.floatMetadata)
            grid->insertMeta(key, openvdb::DoubleMetadata(v));

        // Every cell active, then the values leaf by leaf (in parallel), then runs of equal
        // values folded into tiles.
        const int nx = spec.res[0], ny = spec.res[1], nz = spec.res[2];
        const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(nx - 1, ny - 1, nz - 1));
        openvdb::Vec3STree& tree = grid->tree();
        tree.denseFill(box, openvdb::Vec3s(0.0f), /*active=*/true);
        openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(tree);
        leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, size_t) {
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const openvdb::Coord c = it.getCoord();
                const float* v = values.data() + 3 * spec.index(c.x(), c.y(), c.z());
                it.setValue(openvdb::Vec3s(v[0], v[1], v[2]));
            }
        });
        openvdb::tools::prune(tree);
    } catch (const std::exception& e) {
        return makeError(io::IoError::Data, path,
                         std::string("cannot build the VDB grid: ") + e.what());
    }

    return io::writeFileAtomic(path, [&](const std::string& tmp) -> io::IoError {
        try {
            openvdb::GridPtrVec grids{grid};
            openvdb::MetaMap fileMeta;
            fileMeta.insertMeta("creator", openvdb::StringMetadata("gale"));
            openvdb::io::File file(tmp);
            file.write(grids, fileMeta);
            file.close();
        } catch (const std::exception& e) {
            return makeError(io::IoError::Io, path, std::string("cannot write: ") + e.what());
        }
        return {};
    });
}

// Every grid of a .vdb file, read through a stream that throws on a short read. OpenVDB's
// io::File does not check its reads: on a truncated file it takes a block size it never read
// and asks new[] for that many bytes (docs/sanitizers.md), so a cut-off cache could allocate
// gigabytes or read garbage. A failed read here is an exception, reported as a corrupt file.
openvdb::GridPtrVecPtr readAllGrids(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open the file");
    in.exceptions(std::ios::failbit | std::ios::badbit);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    return stream.getGrids();
}

io::IoError readVdbVelocity(const std::string& path, const std::string& gridName,
                            VdbVelocity& out) {
    initOpenVdb();
    openvdb::GridPtrVecPtr grids;
    try {
        grids = readAllGrids(path);
    } catch (const std::exception& e) {
        return makeError(io::IoError::Io, path, std::string("cannot read: ") + e.what());
    }
    openvdb::Vec3SGrid::Ptr grid;
    for (const openvdb::GridBase::Ptr& g : *grids) {
        if (!gridName.empty() && g->getName() != gridName) continue;
        grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g);
        if (!grid && !gridName.empty())
            return makeError(io::IoError::Data, path,
                             "grid '" + gridName + "' holds " + g->valueType() +
                                 " values, not vec3s");
        if (grid) break;
    }
    if (!grid)
        return makeError(io::IoError::Data, path,
                         gridName.empty() ? std::string("the file has no vec3s grid")
                                          : "the file has no grid named '" + gridName + "'");

    const openvdb::math::Transform& xf = grid->transform();
    if (!xf.isLinear())
        return makeError(io::IoError::Data, path,
                         "grid '" + grid->getName() + "' has a non-linear (frustum) transform");
    const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0.0));
    openvdb::Vec3d voxel;
    for (int a = 0; a < 3; ++a) {
        openvdb::Vec3d unit(0.0);
        unit[a] = 1.0;
        const openvdb::Vec3d d = xf.indexToWorld(unit) - o;
        for (int b = 0; b < 3; ++b)
            if (b != a && std::abs(d[b]) > 1e-12 * std::abs(d[a]))
                return makeError(io::IoError::Data, path,
                                 "grid '" + grid->getName() +
                                     "' has a rotated or sheared transform");
        if (!(d[a] > 0))
            return makeError(io::IoError::Data, path,
                             "grid '" + grid->getName() + "' has a mirrored transform");
        voxel[a] = d[a];
    }
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    if (box.empty())
        return makeError(io::IoError::Data, path,
                         "grid '" + grid->getName() + "' has no active voxels");
    const openvdb::Coord dim = box.dim();
    const double cells = static_cast<double>(dim.x()) * dim.y() * dim.z();
    if (cells > static_cast<double>(io::kMaxGridCells))
        return makeError(io::IoError::Data, path,
                         "grid '" + grid->getName() + "' is too large to read densely");

    VdbVelocity r;
    r.gridName = grid->getName();
    r.vectorType = vectorTypeName(grid->getVectorType());
    r.gridClass = gridClassName(grid->getGridClass());
    r.uniformScale = xf.hasUniformScale();
    r.indexMin = {box.min().x(), box.min().y(), box.min().z()};
    const openvdb::Vec3d corner =
        xf.indexToWorld(openvdb::Vec3d(box.min().x(), box.min().y(), box.min().z()) - 0.5);
    for (int a = 0; a < 3; ++a) {
        r.grid.origin[static_cast<size_t>(a)] = corner[a];
        r.grid.voxel[static_cast<size_t>(a)] = voxel[a];
        r.grid.res[static_cast<size_t>(a)] = dim[a];
    }
    for (auto it = grid->beginMeta(); it != grid->endMeta(); ++it)
        r.metadata[it->first] = it->second ? it->second->str() : std::string();
    try {
        // LayoutZYX: z fastest, x slowest — the same order as sampleGrid.
        openvdb::tools::Dense<openvdb::Vec3s, openvdb::tools::LayoutZYX> dense(box);
        openvdb::tools::copyToDense(*grid, dense);
        r.values.resize(3 * r.grid.cellCount());
        const openvdb::Vec3s* src = dense.data();
        for (size_t i = 0; i < r.grid.cellCount(); ++i)
            for (int c = 0; c < 3; ++c) r.values[3 * i + static_cast<size_t>(c)] = src[i][c];
    } catch (const std::exception& e) {
        return makeError(io::IoError::Data, path,
                         std::string("cannot read the voxels: ") + e.what());
    }
    out = std::move(r);
    return {};
}

// ---- VelocityVolume (vdb() sampling) ----

namespace {

bool isVectorGrid(const openvdb::GridBase& g) {
    return g.isType<openvdb::Vec3SGrid>() || g.isType<openvdb::Vec3DGrid>();
}

// "density (float), vel (vec3s)" for error messages.
std::string gridList(const openvdb::GridPtrVec& grids) {
    std::string out;
    for (const openvdb::GridBase::Ptr& g : grids)
        out += (out.empty() ? "" : ", ") +
               (g->getName().empty() ? std::string("<unnamed>") : g->getName()) + " (" +
               g->valueType() + ")";
    return out.empty() ? std::string("none") : out;
}

// Picks the grid from descriptors or loaded grids; an error when absent or of the wrong type.
io::IoError pickVectorGrid(const std::string& path, const std::string& gridName,
                           const openvdb::GridPtrVec& grids, openvdb::GridBase::Ptr& out) {
    for (const openvdb::GridBase::Ptr& g : grids) {
        if (!gridName.empty() && g->getName() != gridName) continue;
        if (!isVectorGrid(*g)) {
            if (gridName.empty()) continue;
            return makeError(io::IoError::Data, path,
                             "grid '" + gridName + "' holds " + g->valueType() +
                                 " values, not vectors (vec3s or vec3d)");
        }
        if (!g->transform().isLinear())
            return makeError(io::IoError::Data, path,
                             "grid '" + g->getName() + "' has a non-linear (frustum) transform");
        out = g;
        return {};
    }
    return makeError(io::IoError::Data, path,
                     (gridName.empty() ? std::string("the file has no vector grid")
                                       : "the file has no grid named '" + gridName + "'") +
                         " (its grids: " + gridList(grids) + ")");
}

io::IoError readFailure(const std::string& path, const std::exception& e) {
    std::string what = e.what();
    if (what.empty()) what = "unknown error";
    return makeError(io::IoError::Io, path,
                     "cannot read the VDB file (missing, truncated or corrupt): " + what);
}

} // namespace

struct VelocityVolume::Impl {
    openvdb::Vec3SGrid::Ptr grid;
    std::string name;
    size_t memoryBytes = 0;
};

VelocityVolume::VelocityVolume(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
VelocityVolume::~VelocityVolume() = default;

io::IoError checkVdbGrid(const std::string& path, const std::string& gridName) {
    initOpenVdb();
    try {
        openvdb::GridPtrVecPtr grids = readAllGrids(path);
        openvdb::GridBase::Ptr grid;
        return pickVectorGrid(path, gridName, *grids, grid);
    } catch (const std::exception& e) {
        return readFailure(path, e);
    }
}

io::IoError VelocityVolume::load(const std::string& path, const std::string& gridName,
                                 std::shared_ptr<const VelocityVolume>& out) {
    initOpenVdb();
    openvdb::GridBase::Ptr grid;
    try {
        // Everything is read now: a truncated file fails here, not mid-sample.
        openvdb::GridPtrVecPtr grids = readAllGrids(path);
        if (io::IoError e = pickVectorGrid(path, gridName, *grids, grid)) return e;
    } catch (const std::exception& e) {
        return readFailure(path, e);
    }
    auto impl = std::make_unique<Impl>();
    impl->name = grid->getName();
    if (auto s = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid)) {
        impl->grid = s;
    } else if (auto d = openvdb::gridPtrCast<openvdb::Vec3DGrid>(grid)) {
        impl->grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(d->background()));
        impl->grid->setTree(std::make_shared<openvdb::Vec3STree>(d->tree()));
        impl->grid->setTransform(d->transform().copy());
    } else {
        return makeError(io::IoError::Data, path, "grid '" + impl->name + "' is not a vector grid");
    }
    impl->memoryBytes = static_cast<size_t>(impl->grid->memUsage());
    out = std::shared_ptr<const VelocityVolume>(new VelocityVolume(std::move(impl)));
    return {};
}

void VelocityVolume::sample(const double* xyz, size_t n, VolumeInterp interp, double* vel) const {
    const openvdb::Vec3SGrid& grid = *mImpl->grid;
    const openvdb::math::Transform& xf = grid.transform();
    auto acc = grid.getConstAccessor(); // one accessor per call: per thread, per block
    const openvdb::Vec3d voxel = xf.voxelSize();
    const double minVoxel = std::min(voxel[0], std::min(voxel[1], voxel[2]));
    for (size_t i = 0; i < n; ++i) {
        const openvdb::Vec3d p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        openvdb::Vec3d index = xf.worldToIndex(p);
        // A position within float rounding of a voxel centre reads that voxel exactly, so a
        // grid written by `gale sample` reads back bit for bit at its cell centres even from
        // float positions (a float keeps 24 bits: 6e-8 relative).
        const double tol =
            1.2e-7 * (std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2])) / minVoxel +
            1e-9 * (1.0 + std::abs(index[0]) + std::abs(index[1]) + std::abs(index[2]));
        for (int a = 0; a < 3; ++a) {
            const double r = std::round(index[a]);
            if (std::abs(index[a] - r) <= tol) index[a] = r;
        }
        openvdb::Vec3s v(0.0f);
        switch (interp) {
        case VolumeInterp::Nearest:
            openvdb::tools::PointSampler::sample(acc, index, v);
            break;
        case VolumeInterp::Trilinear:
            openvdb::tools::BoxSampler::sample(acc, index, v);
            break;
        case VolumeInterp::Quadratic:
            openvdb::tools::QuadraticSampler::sample(acc, index, v);
            break;
        }
        for (int c = 0; c < 3; ++c) vel[3 * i + static_cast<size_t>(c)] = v[c];
    }
}

const std::string& VelocityVolume::gridName() const {
    return mImpl->name;
}
size_t VelocityVolume::memoryBytes() const {
    return mImpl->memoryBytes;
}

} // namespace gale::geometry
