// OpenVDB files for velocity grids: write a dense, cell-centred Vec3s grid (named `vel`,
// contravariant-relative, the Houdini/Blender convention) and read one back as a dense box.
// vdb_io.cpp and vdb_geometry.cpp are the only translation units that include OpenVDB headers
// (they are slow to compile); sampling a .vdb as a field is VelocityVolume in geometry/geometry.h.
#pragma once

#include "io/grid.h"
#include "io/pointset.h"

#include <map>
#include <string>
#include <vector>

namespace gale::geometry {

// What to store besides the voxels.
struct VdbWriteOptions {
    std::string gridName = "vel";
    // Extra grid metadata (string values), e.g. {"gale_source", "wind.se"}.
    std::map<std::string, std::string> metadata;
    // Extra float metadata, e.g. {"gale_time", 0.5}.
    std::map<std::string, double> floatMetadata;
};

// Writes `values` (float32, 3 per cell, x slowest, as sampleGrid leaves them) as a .vdb file
// holding one Vec3s grid: a linear transform with the grid's voxel size, index (0,0,0) at the
// centre of cell (0,0,0) so voxel (i,j,k) covers exactly that cell; every cell of the box is
// active (runs of equal values are stored as tiles); the background is zero; vector type
// VEC_CONTRAVARIANT_RELATIVE; grid class unknown (not a level set or fog volume).
// Written through a temporary file and a rename.
io::IoError writeVdbVelocity(const std::string& path, const io::GridSpec& grid,
                             const std::vector<float>& values, const VdbWriteOptions& options = {});

// A Vec3s grid read back: the box of its active voxels as a dense array.
struct VdbVelocity {
    std::string gridName;
    std::string vectorType;             // "invariant", "covariant", "covariant-normalize",
                                        // "contravariant-relative", "contravariant-absolute"
    std::string gridClass;              // "unknown", "level set", "fog volume", "staggered"
    io::GridSpec grid;                  // origin = min corner of the active box's first voxel
    std::vector<int> indexMin{0, 0, 0}; // index coordinates of the box's first voxel
    std::vector<float> values;          // 3 per cell, x slowest (like sampleGrid)
    std::map<std::string, std::string> metadata; // every grid metadata item, as text
    bool uniformScale = true;                    // the transform is a plain scale + translation
};

// Reads the Vec3s grid named `gridName` (empty: the first Vec3s grid) from a .vdb file.
// Errors: Io when the file cannot be opened or is not a VDB file; Data when the grid is
// missing, is not Vec3s, has a non-linear or rotated transform, or is empty.
io::IoError readVdbVelocity(const std::string& path, const std::string& gridName, VdbVelocity& out);

} // namespace gale::geometry
