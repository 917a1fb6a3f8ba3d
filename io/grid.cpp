// Cell-centred grids: geometry from bounds, the .npy/.csv grid writers (atomic files) and
// frame-numbered file names.
#include "io/grid.h"

#include "io/atomic_file.h"

#include "io/pointset_detail.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>
#include <unistd.h>

namespace gale::io {

namespace {

// Cells needed to cover `length` with cells of size `voxel` (a hair of slack so that
// 1.0 / 0.1 counts as 10 cells, not 11).
long cellsToCover(double length, double voxel) {
    double n = length / voxel;
    return std::max(1L, static_cast<long>(std::ceil(n - 1e-9 * std::max(1.0, n))));
}

std::string axisName(int a) {
    return std::string(1, "xyz"[a]);
}



void appendFloatLE(std::string& out, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    const char b[4] = {static_cast<char>(u & 0xff), static_cast<char>((u >> 8) & 0xff),
                       static_cast<char>((u >> 16) & 0xff), static_cast<char>((u >> 24) & 0xff)};
    out.append(b, 4);
}

bool checkValues(const GridSpec& grid, const std::vector<float>& values, IoError& e) {
    if (values.size() == 3 * grid.cellCount()) return true;
    e.kind = IoError::Data;
    e.message = "the grid has " + std::to_string(grid.cellCount()) + " cells but " +
                std::to_string(values.size()) + " values were given (3 per cell)";
    return false;
}

} // namespace

bool gridFromBounds(const std::array<double, 6>& bounds, const std::vector<int>& res, double voxel,
                    GridSpec& out, std::string& error) {
    double length[3];
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(bounds[a]) || !std::isfinite(bounds[a + 3])) {
            error = "the bounds must be finite numbers";
            return false;
        }
        length[a] = bounds[a + 3] - bounds[a];
        if (!(length[a] > 0)) {
            error = "the bounds are empty along " + axisName(a) + " (" + axisName(a) +
                    "1 must be greater than " + axisName(a) + "0)";
            return false;
        }
    }
    GridSpec g;
    long counts[3] = {0, 0, 0};
    if (res.size() == 3) {
        for (int a = 0; a < 3; ++a) {
            if (res[static_cast<size_t>(a)] < 1) {
                error = "every resolution must be at least 1";
                return false;
            }
            counts[a] = res[static_cast<size_t>(a)];
            g.voxel[static_cast<size_t>(a)] = length[a] / counts[a];
        }
    } else if (res.size() == 1) {
        if (res[0] < 1) {
            error = "the resolution must be at least 1";
            return false;
        }
        const int longest = static_cast<int>(std::max_element(length, length + 3) - length);
        const double s = length[longest] / res[0];
        for (int a = 0; a < 3; ++a) {
            counts[a] = a == longest ? res[0] : cellsToCover(length[a], s);
            g.voxel[static_cast<size_t>(a)] = s;
        }
    } else if (res.empty() && voxel > 0 && std::isfinite(voxel)) {
        for (int a = 0; a < 3; ++a) {
            // Guard the conversion to long before counting.
            if (length[a] / voxel > 4.0 * static_cast<double>(kMaxGridCells)) {
                error = "the voxel size is too small for these bounds";
                return false;
            }
            counts[a] = cellsToCover(length[a], voxel);
            g.voxel[static_cast<size_t>(a)] = voxel;
        }
    } else {
        error = res.empty() ? "the voxel size must be a positive number"
                            : "the resolution is one number N or three (NX,NY,NZ)";
        return false;
    }
    double cells = 1.0;
    for (int a = 0; a < 3; ++a) {
        cells *= static_cast<double>(counts[a]);
        g.res[static_cast<size_t>(a)] = static_cast<int>(std::min<long>(counts[a], 1L << 30));
        g.origin[static_cast<size_t>(a)] = bounds[static_cast<size_t>(a)];
    }
    if (cells > static_cast<double>(kMaxGridCells)) {
        error = "the grid would have " + std::to_string(counts[0]) + "x" +
                std::to_string(counts[1]) + "x" + std::to_string(counts[2]) +
                " cells, more than the limit of " + std::to_string(kMaxGridCells) +
                ": use a coarser --res or a larger --voxel";
        return false;
    }
    out = g;
    return true;
}

bool gridFormatFromPath(const std::string& path, GridFormat& out) {
    const size_t dot = path.rfind('.');
    const size_t slash = path.find_last_of("/\\");
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return false;
    std::string ext = path.substr(dot);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".vdb")
        out = GridFormat::Vdb;
    else if (ext == ".npy")
        out = GridFormat::Npy;
    else if (ext == ".csv")
        out = GridFormat::Csv;
    else
        return false;
    return true;
}

IoError writeGridNpy(std::ostream& out, const GridSpec& grid, const std::vector<float>& values) {
    IoError e;
    if (!checkValues(grid, values, e)) return e;
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                         std::to_string(grid.res[0]) + ", " + std::to_string(grid.res[1]) + ", " +
                         std::to_string(grid.res[2]) + ", 3), }";
    // Magic (6) + version (2) + header length (2) + header, padded with spaces so the data
    // starts at a multiple of 64 bytes, ended by '\n'.
    const size_t total = 10 + header.size() + 1;
    header.append((64 - total % 64) % 64, ' ');
    header += '\n';
    std::string buf("\x93NUMPY\x01\x00", 8);
    buf += static_cast<char>(header.size() & 0xff);
    buf += static_cast<char>((header.size() >> 8) & 0xff);
    buf += header;
    for (size_t i = 0; i < values.size(); ++i) {
        appendFloatLE(buf, values[i]);
        if (buf.size() >= (1u << 20)) {
            out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
            buf.clear();
        }
    }
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (!out) return ioErrorAt("", "write failed", errno);
    return {};
}

IoError writeGridCsv(std::ostream& out, const GridSpec& grid, const std::vector<float>& values) {
    IoError e;
    if (!checkValues(grid, values, e)) return e;
    std::string buf = "x,y,z,vx,vy,vz\n";
    for (int i = 0; i < grid.res[0]; ++i)
        for (int j = 0; j < grid.res[1]; ++j)
            for (int k = 0; k < grid.res[2]; ++k) {
                const std::array<double, 3> c = grid.cellCenter(i, j, k);
                const float* v = values.data() + 3 * grid.index(i, j, k);
                for (int a = 0; a < 3; ++a) {
                    detail::appendNumber(buf, c[static_cast<size_t>(a)], false);
                    buf += ',';
                }
                for (int a = 0; a < 3; ++a) {
                    detail::appendNumber(buf, v[a], true);
                    buf += a < 2 ? ',' : '\n';
                }
                if (buf.size() >= (1u << 20)) {
                    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
                    buf.clear();
                }
            }
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (!out) return ioErrorAt("", "write failed", errno);
    return {};
}

IoError writeGridFile(const std::string& path, GridFormat format, const GridSpec& grid,
                      const std::vector<float>& values) {
    if (format == GridFormat::Vdb) {
        IoError e;
        e.kind = IoError::Data;
        e.file = path;
        e.message = "write .vdb files with writeVdbVelocity (geometry/vdb_io.h)";
        return e;
    }
    return writeFileAtomic(path, [&](const std::string& tmp) -> IoError {
        errno = 0;
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) return ioErrorAt(path, "cannot write", errno);
        IoError e = format == GridFormat::Npy ? writeGridNpy(f, grid, values)
                                              : writeGridCsv(f, grid, values);
        if (e) return e;
        f.flush();
        const int err = errno;
        f.close();
        if (f.fail()) return ioErrorAt(path, "cannot write", err);
        return {};
    });
}

} // namespace gale::io
