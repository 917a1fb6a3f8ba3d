// Triangle meshes for the geometry fields (no OpenVDB here): reading OBJ/PLY with polygons fanned
// into triangles, generated spheres and boxes, OBJ writing, the closest point on a triangle and
// the automatic narrow-band width.
#include "geometry/geometry.h"

#include "io/atomic_file.h"

#include <algorithm>
#include <cmath>

namespace gale::geometry {

namespace {

io::IoError meshError(const std::string& path, const std::string& message) {
    io::IoError e;
    e.kind = io::IoError::Data;
    e.file = path;
    e.message = message;
    return e;
}

} // namespace

std::array<double, 6> TriangleMesh::bounds() const {
    if (points.empty()) return {0, 0, 0, 0, 0, 0};
    std::array<double, 6> b{points[0][0], points[0][1], points[0][2],
                            points[0][0], points[0][1], points[0][2]};
    for (const auto& p : points)
        for (int a = 0; a < 3; ++a) {
            b[a] = std::min(b[a], static_cast<double>(p[a]));
            b[3 + a] = std::max(b[3 + a], static_cast<double>(p[a]));
        }
    return b;
}

io::IoError readTriangleMesh(const std::string& path, TriangleMesh& out) {
    io::PointFormat format;
    if (!io::formatFromPath(path, format) ||
        (format != io::PointFormat::Obj && format != io::PointFormat::Ply &&
         format != io::PointFormat::PlyAscii))
        return meshError(path, "a mesh must be an .obj or .ply file");
    io::PointSet ps;
    if (io::IoError e = io::readPoints(path, ps)) return e;
    const int axes[3] = {ps.find("x"), ps.find("y"), ps.find("z")};
    if (axes[0] < 0 || axes[1] < 0 || axes[2] < 0)
        return meshError(path, "the mesh has no x, y, z vertex positions");
    if (ps.faces.empty())
        return meshError(path, "the mesh has no faces (sdf(), shadow() and meshvel() need a "
                               "surface of triangles or polygons, not just points)");
    TriangleMesh mesh;
    const size_t n = ps.size();
    mesh.points.resize(n);
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            const double v = ps.columns[static_cast<size_t>(axes[a])][i];
            if (!std::isfinite(v) || std::abs(v) > 1e30)
                return meshError(path, "vertex " + std::to_string(i) + " is not finite");
            mesh.points[i][static_cast<size_t>(a)] = static_cast<float>(v);
        }
    for (size_t f = 0; f < ps.faces.size(); ++f) {
        const std::vector<int>& face = ps.faces[f];
        if (face.size() < 3)
            return meshError(path, "face " + std::to_string(f) + " has " +
                                       std::to_string(face.size()) +
                                       " corner(s); a face needs at least 3");
        for (int v : face)
            if (v < 0 || static_cast<size_t>(v) >= n)
                return meshError(path, "face " + std::to_string(f) + " names vertex " +
                                           std::to_string(v) + ", but the mesh has " +
                                           std::to_string(n) + " vertices");
        // A fan from the first corner (exact for the convex quads and n-gons DCC tools write).
        for (size_t k = 1; k + 1 < face.size(); ++k)
            mesh.triangles.push_back({static_cast<uint32_t>(face[0]),
                                      static_cast<uint32_t>(face[k]),
                                      static_cast<uint32_t>(face[k + 1])});
    }
    out = std::move(mesh);
    return {};
}

TriangleMesh uvSphereMesh(const std::array<double, 3>& c, double radius, int rings, int segments) {
    rings = std::max(rings, 2);
    segments = std::max(segments, 3);
    const double pi = 3.14159265358979323846;
    TriangleMesh m;
    auto add = [&](double x, double y, double z) {
        m.points.push_back({static_cast<float>(c[0] + radius * x),
                            static_cast<float>(c[1] + radius * y),
                            static_cast<float>(c[2] + radius * z)});
    };
    add(0, 1, 0); // north pole: vertex 0
    for (int r = 1; r < rings; ++r) {
        const double theta = pi * r / rings;
        for (int s = 0; s < segments; ++s) {
            const double phi = 2.0 * pi * s / segments;
            add(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
        }
    }
    add(0, -1, 0); // south pole
    const uint32_t south = static_cast<uint32_t>(m.points.size() - 1);
    auto ring = [&](int r, int s) {
        return static_cast<uint32_t>(1 + (r - 1) * segments + (s % segments));
    };
    for (int s = 0; s < segments; ++s) m.triangles.push_back({0, ring(1, s), ring(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            m.triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
            m.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
        }
    for (int s = 0; s < segments; ++s)
        m.triangles.push_back({south, ring(rings - 1, s + 1), ring(rings - 1, s)});
    return m;
}

TriangleMesh boxMesh(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
    TriangleMesh m;
    for (int i = 0; i < 8; ++i)
        m.points.push_back({static_cast<float>(i & 1 ? hi[0] : lo[0]),
                            static_cast<float>(i & 2 ? hi[1] : lo[1]),
                            static_cast<float>(i & 4 ? hi[2] : lo[2])});
    // Two triangles per face, counter-clockwise seen from outside.
    const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads) {
        m.triangles.push_back({q[0], q[1], q[2]});
        m.triangles.push_back({q[0], q[2], q[3]});
    }
    return m;
}

io::IoError writeTriangleMeshObj(const std::string& path, const TriangleMesh& mesh) {
    std::string text;
    text.reserve(mesh.points.size() * 32 + mesh.triangles.size() * 24);
    for (const auto& p : mesh.points)
        text += "v " + io::formatNumber(p[0]) + ' ' + io::formatNumber(p[1]) + ' ' +
                io::formatNumber(p[2]) + '\n';
    for (const auto& t : mesh.triangles)
        text += "f " + std::to_string(t[0] + 1) + ' ' + std::to_string(t[1] + 1) + ' ' +
                std::to_string(t[2] + 1) + '\n';
    return io::writeBytesAtomic(path, text);
}

std::array<double, 3> closestPointOnTriangle(const std::array<double, 3>& p,
                                             const std::array<double, 3>& a,
                                             const std::array<double, 3>& b,
                                             const std::array<double, 3>& c,
                                             std::array<double, 3>& w) {
    // Ericson, Real-Time Collision Detection 5.1.5: Voronoi regions of the vertices, the edges
    // and the face.
    auto sub = [](const std::array<double, 3>& x, const std::array<double, 3>& y) {
        return std::array<double, 3>{x[0] - y[0], x[1] - y[1], x[2] - y[2]};
    };
    auto dot = [](const std::array<double, 3>& x, const std::array<double, 3>& y) {
        return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    };
    auto at = [&](double wa, double wb, double wc) {
        w = {wa, wb, wc};
        return std::array<double, 3>{wa * a[0] + wb * b[0] + wc * c[0],
                                     wa * a[1] + wb * b[1] + wc * c[1],
                                     wa * a[2] + wb * b[2] + wc * c[2]};
    };
    const auto ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return at(1, 0, 0);
    const auto bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return at(0, 1, 0);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double v = d1 / (d1 - d3);
        return at(1 - v, v, 0);
    }
    const auto cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return at(0, 0, 1);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double v = d2 / (d2 - d6);
        return at(1 - v, 0, v);
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(0, 1 - v, v);
    }
    const double sum = va + vb + vc;
    if (!(sum > 0.0)) return at(1, 0, 0); // degenerate triangle
    const double v = vb / sum, u = vc / sum;
    return at(1 - v - u, v, u);
}

int automaticBandVoxels(const TriangleMesh& mesh, double voxel) {
    const std::array<double, 6> b = mesh.bounds();
    const double dx = b[3] - b[0], dy = b[4] - b[1], dz = b[5] - b[2];
    const double diagonal = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(voxel > 0.0)) return 3;
    const double v = std::ceil(0.25 * diagonal / voxel);
    return static_cast<int>(std::clamp(v, 3.0, 64.0));
}

} // namespace gale::geometry
