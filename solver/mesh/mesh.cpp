// Mesh generation, loading through the fields layer's point-set readers, and topology.
#include "solver/mesh/mesh.h"

#include "io/pointset.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace gale::solver {

TriMesh makeGrid(double width, double height, int nx, int ny, const Vec3& origin,
                 const Vec3& axisU, const Vec3& axisV) {
    TriMesh m;
    nx = std::max(nx, 2);
    ny = std::max(ny, 2);
    const double du = width / (nx - 1), dv = height / (ny - 1);
    m.positions.resize(3 * static_cast<size_t>(nx) * ny);
    m.uv.resize(2 * static_cast<size_t>(nx) * ny);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const size_t k = static_cast<size_t>(j) * nx + i;
            const Vec3 p = origin + (i * du) * axisU + (j * dv) * axisV;
            vec3At(m.positions.data(), k) = p;
            m.uv[2 * k] = i * du;
            m.uv[2 * k + 1] = j * dv;
        }
    for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
            if ((i + j) % 2 == 0) {
                m.triangles.push_back({a, b, d});
                m.triangles.push_back({a, d, c});
            } else {
                m.triangles.push_back({a, b, c});
                m.triangles.push_back({b, d, c});
            }
        }
    m.uvIsMaterialSpace = true;
    return m;
}

bool loadMesh(const std::string& path, TriMesh& out, std::string& error, int* dropped) {
    io::PointSet ps;
    io::IoError e = io::readPoints(path, ps);
    if (e) {
        error = e.brief(); // the caller's diagnostic says "error:" once
        return false;
    }
    const int ix = ps.find("x"), iy = ps.find("y"), iz = ps.find("z");
    if (ix < 0 || iy < 0 || iz < 0) {
        error = path + ": the mesh has no x, y, z vertex coordinates";
        return false;
    }
    const size_t n = ps.size();
    out = TriMesh{};
    out.positions.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        out.positions[3 * i] = ps.columns[ix][i];
        out.positions[3 * i + 1] = ps.columns[iy][i];
        out.positions[3 * i + 2] = ps.columns[iz][i];
        // (OBJ's reader checks its v lines; a PLY's binary floats can still hold NaN or ∞.)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(out.positions[3 * i + k])) {
                error = path + ": vertex " + std::to_string(i + 1) + " (counting from 1) has a " +
                        "non-finite " + "xyz"[k] + " (" + std::to_string(out.positions[3 * i + k]) +
                        "): re-export the mesh";
                return false;
            }
    }
    for (size_t c = 0; c < ps.names.size(); ++c) {
        const std::string& name = ps.names[c];
        if (name == "x" || name == "y" || name == "z") continue;
        out.attributes[name] = ps.columns[c];
    }
    int u = ps.find("u"), v = ps.find("v");
    if (u < 0 || v < 0) {
        u = ps.find("s");
        v = ps.find("t");
    }
    if (u >= 0 && v >= 0) {
        out.uv.resize(2 * n);
        for (size_t i = 0; i < n; ++i) {
            out.uv[2 * i] = ps.columns[u][i];
            out.uv[2 * i + 1] = ps.columns[v][i];
        }
    }
    int bad = 0;
    for (const std::vector<int>& f : ps.faces) {
        bool ok = f.size() >= 3;
        for (int idx : f) ok = ok && idx >= 0 && static_cast<size_t>(idx) < n;
        if (!ok) {
            ++bad;
            continue;
        }
        for (size_t k = 1; k + 1 < f.size(); ++k) {
            std::array<int, 3> t{f[0], f[k], f[k + 1]};
            if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
                ++bad;
                continue;
            }
            out.triangles.push_back(t);
        }
    }
    if (dropped) *dropped = bad;
    if (out.triangles.empty()) {
        error = path + ": the mesh has no usable faces (it needs triangles or polygons)";
        return false;
    }
    return true;
}

namespace {
inline uint64_t edgeKey(int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}
} // namespace

std::vector<std::array<int, 2>> meshEdges(const std::vector<std::array<int, 3>>& triangles) {
    std::vector<uint64_t> keys;
    keys.reserve(3 * triangles.size());
    for (const auto& t : triangles)
        for (int k = 0; k < 3; ++k) keys.push_back(edgeKey(t[k], t[(k + 1) % 3]));
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<std::array<int, 2>> edges;
    edges.reserve(keys.size());
    for (uint64_t k : keys) edges.push_back({static_cast<int>(k >> 32), static_cast<int>(k & 0xffffffffu)});
    return edges;
}

std::vector<HingeStencil> meshHinges(const std::vector<std::array<int, 3>>& triangles) {
    // (edge key, opposite corner), sorted: the triangles sharing an edge become neighbours.
    std::vector<std::pair<uint64_t, int>> items;
    items.reserve(3 * triangles.size());
    for (const auto& t : triangles)
        for (int k = 0; k < 3; ++k) items.push_back({edgeKey(t[k], t[(k + 1) % 3]), t[(k + 2) % 3]});
    std::sort(items.begin(), items.end());
    std::vector<HingeStencil> out;
    for (size_t i = 0; i < items.size();) {
        size_t j = i;
        while (j < items.size() && items[j].first == items[i].first) ++j;
        if (j - i == 2 && items[i].second != items[i + 1].second) {
            const uint64_t k = items[i].first;
            out.push_back({{static_cast<int>(k >> 32), static_cast<int>(k & 0xffffffffu),
                            items[i].second, items[i + 1].second}});
        }
        i = j;
    }
    return out;
}

} // namespace gale::solver
