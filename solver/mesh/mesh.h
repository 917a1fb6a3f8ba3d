// Triangle meshes for cloth: a generated grid or an OBJ/PLY file (polygons fan-triangulated),
// per-vertex attributes (PLY properties: painted maps), and the topology the forces need
// (unique edges, interior-edge bending stencils, degenerate-triangle counts).
#pragma once

#include "solver/linalg/types.h"

#include <array>
#include <map>
#include <string>
#include <vector>

namespace gale::solver {

struct TriMesh {
    std::vector<double> positions;                    // 3 per vertex, rest shape (m)
    std::vector<std::array<int, 3>> triangles;        // vertex indices, any winding
    std::vector<double> uv;                           // 2 per vertex or empty
    std::map<std::string, std::vector<double>> attributes; // per-vertex scalars (PLY properties)
    // Rest-space material directions (warp/weft) of a generated grid; empty for loaded meshes,
    // which use world X projected on each triangle (world Y where X is nearly normal).
    bool uvIsMaterialSpace = false; // uv in metres along warp and weft (grid generator)

    size_t vertexCount() const { return positions.size() / 3; }
    Vec3 position(size_t i) const { return vec3At(positions.data(), i); }
};

// An nx × ny vertex grid of size w × h metres in the plane through `origin` spanned by unit
// axes `axisU` (width, the u direction) and `axisV` (height). Vertex (i, j) has index j*nx + i
// and uv = (i w/(nx−1), j h/(ny−1)); each quad is split along alternating diagonals.
TriMesh makeGrid(double width, double height, int nx, int ny, const Vec3& origin = Vec3::Zero(),
                 const Vec3& axisU = Vec3::UnitX(), const Vec3& axisV = Vec3::UnitY());

// Reads an OBJ or PLY mesh (by extension). Polygons with more than three corners are fan-split;
// faces with repeated indices are dropped (counted in `dropped`); an index out of range is an
// error of the point reader. On failure
// returns false with `error` = "file:line:col: message" style text.
bool loadMesh(const std::string& path, TriMesh& out, std::string& error, int* dropped = nullptr);

// Unique undirected edges (i < j), in a deterministic order.
std::vector<std::array<int, 2>> meshEdges(const std::vector<std::array<int, 3>>& triangles);

// A bending stencil: edge (v[0], v[1]) shared by exactly two triangles with opposite corners
// v[2] and v[3]. Non-manifold edges (more than two triangles) contribute no stencil.
struct HingeStencil {
    std::array<int, 4> v;
};
std::vector<HingeStencil> meshHinges(const std::vector<std::array<int, 3>>& triangles);

// Twice the area vector ((x1 − x0) × (x2 − x0)) of triangle t from flat positions.
inline Vec3 triangleCross(const double* x, const std::array<int, 3>& t) {
    const Vec3 a = vec3At(x, t[0]), b = vec3At(x, t[1]), c = vec3At(x, t[2]);
    return (b - a).cross(c - a);
}

} // namespace gale::solver
