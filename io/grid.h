// Regular, cell-centred grids (what `gale sample` writes and `gale viz` draws): grid geometry
// from bounds and a resolution or voxel size, the grid writers for .npy and .csv (atomic
// files) and frame-numbered file names. Sampling a field on a grid is fields/grid_sample.h.
#pragma once

#include "io/atomic_file.h"
#include "io/pointset.h"

#include <array>
#include <cstddef>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace gale::io {

// A box of nx*ny*nz cells. Cell (i,j,k) covers [origin + (i,j,k)*voxel, origin + (i+1,j+1,k+1)
// * voxel] and is sampled at its centre origin + (i+0.5, j+0.5, k+0.5) * voxel.
struct GridSpec {
    std::array<double, 3> origin{0.0, 0.0, 0.0}; // min corner of cell (0,0,0)
    std::array<double, 3> voxel{1.0, 1.0, 1.0};  // cell size per axis (metres)
    std::array<int, 3> res{1, 1, 1};             // cells per axis

    size_t cellCount() const {
        return static_cast<size_t>(res[0]) * static_cast<size_t>(res[1]) *
               static_cast<size_t>(res[2]);
    }
    // Flat index of cell (i,j,k), x slowest: ((i*ny + j)*nz + k).
    size_t index(int i, int j, int k) const {
        return (static_cast<size_t>(i) * static_cast<size_t>(res[1]) + static_cast<size_t>(j)) *
                   static_cast<size_t>(res[2]) +
               static_cast<size_t>(k);
    }
    std::array<double, 3> cellCenter(int i, int j, int k) const {
        return {origin[0] + (i + 0.5) * voxel[0], origin[1] + (j + 0.5) * voxel[1],
                origin[2] + (k + 0.5) * voxel[2]};
    }
    // True when every cell has the same size on all three axes.
    bool cubicVoxels() const { return voxel[0] == voxel[1] && voxel[1] == voxel[2]; }
};

// The largest grid the commands accept (cells); 12 bytes each in memory.
constexpr size_t kMaxGridCells = size_t(1) << 30;

// Grid over bounds {x0,y0,z0,x1,y1,z1} (x1 > x0 etc.), anchored at the min corner.
//  - res = {N}: cubic voxels of size (longest side)/N; every other axis gets the fewest cells
//    that cover it, ceil(length/voxel).
//  - res = {NX,NY,NZ}: exactly those counts, voxel size length/count per axis.
//  - voxel > 0 (with res empty): cubic voxels of that size, ceil(length/voxel) cells per axis
//    (the last cell may reach past the max corner by less than one voxel).
// False with `error` set (a sentence) on degenerate bounds, counts < 1, or too many cells.
bool gridFromBounds(const std::array<double, 6>& bounds, const std::vector<int>& res, double voxel,
                    GridSpec& out, std::string& error);

// Writers for a sampled grid (`values` float32, 3 per cell, x slowest, as
// fields::sampleGrid leaves them).
//  - npy: little-endian float32 array of shape (nx, ny, nz, 3), C order (x slowest).
//  - csv: header `x,y,z,vx,vy,vz`, one row per cell in the same order; positions are the
//    cell centres (shortest round-trip doubles), velocities shortest round-trip floats.
enum class GridFormat { Vdb, Npy, Csv };
// Format from a path's extension (.vdb .npy .csv, any case); false if none of them.
bool gridFormatFromPath(const std::string& path, GridFormat& out);

IoError writeGridNpy(std::ostream& out, const GridSpec& grid, const std::vector<float>& values);
IoError writeGridCsv(std::ostream& out, const GridSpec& grid, const std::vector<float>& values);

// npy or csv to a file, atomically.
IoError writeGridFile(const std::string& path, GridFormat format, const GridSpec& grid,
                      const std::vector<float>& values);

// `pattern` with its one frame token replaced by the frame number (io/frame_pattern.h): a run
// of '#' zero-padded to the run's length, or to 4 digits for a single '#' (`wind.#.vdb` ->
// `wind.0012.vdb`, `v.##.npy` -> `v.12.npy`, frame -3 -> `-0003`), `%04d`, `$F4`. False when the
// name has no token or more than one.
bool framePath(const std::string& pattern, long frame, std::string& out);

} // namespace gale::io
