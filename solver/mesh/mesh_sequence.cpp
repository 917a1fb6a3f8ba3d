// Mesh sequences: the frames found through geometry::findFiles (the one `#` rule), each read
// with loadMesh and checked against the first frame's topology.
#include "solver/mesh/mesh_sequence.h"

#include "geometry/file_policy.h"
#include "io/grid.h"
#include "solver/contact/ccd.h"
#include "solver/mesh/mesh.h"

#include <cmath>
#include <filesystem>

namespace gale::solver {

MeshSequence::MeshSequence(std::vector<std::array<int, 3>> triangles,
                           std::vector<std::vector<double>> frames, long firstFrame, double fps,
                           double frameZero)
    : mTriangles(std::move(triangles)), mFrames(std::move(frames)), mFirstFrame(firstFrame),
      mFps(fps), mFrameZero(frameZero) {}

std::shared_ptr<const MeshSequence> MeshSequence::load(const std::string& path, double fps,
                                                       std::string& error, double frameZero) {
    namespace fs = std::filesystem;
    const fs::path p(path);
    // A scene key's file: resolved by the scene already, and not sandboxed (its frame files may
    // be symbolic links into a cache elsewhere, as studio shot folders have them).
    geometry::FileAccess access;
    access.baseDir = p.parent_path().empty() ? "." : p.parent_path().string();
    access.rootDir = access.baseDir;
    access.sandboxed = false;
    geometry::FileRef ref;
    if (!geometry::findFiles(access, p.filename().string(), ref, error)) return nullptr;
    std::vector<std::vector<double>> frames;
    std::vector<std::array<int, 3>> triangles;
    for (size_t k = 0; k < ref.frames.size(); ++k) {
        const geometry::FrameFile& f = ref.frames[k];
        if (ref.sequence && k > 0 && f.frame != ref.frames[k - 1].frame + 1) {
            std::string missing;
            io::framePath(ref.pattern, ref.frames[k - 1].frame + 1, missing);
            error = "the mesh sequence '" + path + "' has no frame " +
                    std::to_string(ref.frames[k - 1].frame + 1) + " ('" + missing +
                    "' is missing, between frames " + std::to_string(ref.frames[k - 1].frame) +
                    " and " + std::to_string(f.frame) +
                    "): write every frame from the first to the last";
            return nullptr;
        }
        TriMesh m;
        std::string e;
        if (!loadMesh(f.path, m, e)) {
            error = e;
            return nullptr;
        }
        if (k == 0) {
            triangles = m.triangles;
            if (triangles.empty()) {
                error = f.path + ": the mesh has no triangles";
                return nullptr;
            }
        } else if (m.vertexCount() != frames[0].size() / 3 || m.triangles != triangles) {
            error =
                f.path + ": frame " + std::to_string(f.frame) + " has " +
                std::to_string(m.vertexCount()) + " vertices and " +
                std::to_string(m.triangles.size()) + " triangles, the first frame (" +
                ref.frames[0].path + ") " + std::to_string(frames[0].size() / 3) + " and " +
                std::to_string(triangles.size()) +
                (m.vertexCount() == frames[0].size() / 3 && m.triangles.size() == triangles.size()
                     ? " with other faces"
                     : "") +
                ": every frame of a sequence needs the same topology";
            return nullptr;
        }
        for (double x : m.positions)
            if (!std::isfinite(x)) {
                error = f.path + ": a vertex position is not finite";
                return nullptr;
            }
        frames.push_back(std::move(m.positions));
    }
    auto seq = std::make_shared<MeshSequence>(std::move(triangles), std::move(frames),
                                              ref.sequence ? ref.frames[0].frame : 0, fps,
                                              frameZero);
    seq->mPath = path;
    return seq;
}

void MeshSequence::positionsAt(double t, std::vector<double>& out) const {
    const double f = t * mFps - (static_cast<double>(mFirstFrame) - mFrameZero);
    const long last = static_cast<long>(mFrames.size()) - 1;
    if (last <= 0 || !(f > 0.0)) {
        out = mFrames.front();
        return;
    }
    if (f >= static_cast<double>(last)) {
        out = mFrames.back();
        return;
    }
    const long a = static_cast<long>(std::floor(f));
    const double w = f - static_cast<double>(a);
    const std::vector<double>& pa = mFrames[a];
    const std::vector<double>& pb = mFrames[a + 1];
    out.resize(pa.size());
    for (size_t i = 0; i < pa.size(); ++i) out[i] = pa[i] + w * (pb[i] - pa[i]);
}

Vec3 MeshSequence::vertexAt(int v, double t) const {
    const double f = t * mFps - (static_cast<double>(mFirstFrame) - mFrameZero);
    const long last = static_cast<long>(mFrames.size()) - 1;
    if (last <= 0 || !(f > 0.0)) return vec3At(mFrames.front().data(), v);
    if (f >= static_cast<double>(last)) return vec3At(mFrames.back().data(), v);
    const long a = static_cast<long>(std::floor(f));
    const double w = f - static_cast<double>(a);
    const Vec3 pa = vec3At(mFrames[a].data(), v), pb = vec3At(mFrames[a + 1].data(), v);
    return pa + w * (pb - pa);
}

namespace {
// The triangle's frame (ê₁, n̂ × ê₁, n̂) as columns.
Mat3 triangleFrame(const Vec3& a, const Vec3& b, const Vec3& c) {
    Mat3 f = Mat3::Identity();
    const Vec3 e = b - a, n = e.cross(c - a);
    if (!(e.norm() > 0.0) || !(n.norm() > 0.0)) return f;
    f.col(0) = e.normalized();
    f.col(2) = n.normalized();
    f.col(1) = f.col(2).cross(f.col(0));
    return f;
}
} // namespace

SurfaceBinding bindToSurface(const MeshSequence& mesh, const Vec3& x) {
    SurfaceBinding b;
    double best = INFINITY;
    const std::vector<double>& p = mesh.firstPositions();
    for (size_t k = 0; k < mesh.triangles().size(); ++k) {
        const auto& t = mesh.triangles()[k];
        double w[3];
        const double d2 = contact::pointTriangleDistance2(x, vec3At(p.data(), t[0]), vec3At(p.data(), t[1]),
                                                          vec3At(p.data(), t[2]), w);
        if (d2 < best) {
            best = d2;
            b.triangle = static_cast<int>(k);
            std::copy(w, w + 3, b.w);
        }
    }
    if (b.triangle < 0) return b;
    const auto& t = mesh.triangles()[b.triangle];
    const Vec3 a = vec3At(p.data(), t[0]), bb = vec3At(p.data(), t[1]), c = vec3At(p.data(), t[2]);
    const Vec3 q = b.w[0] * a + b.w[1] * bb + b.w[2] * c;
    b.local = triangleFrame(a, bb, c).transpose() * (x - q);
    return b;
}

Vec3 boundPosition(const MeshSequence& mesh, const SurfaceBinding& b, double t) {
    const auto& tri = mesh.triangles()[b.triangle];
    const Vec3 a = mesh.vertexAt(tri[0], t), bb = mesh.vertexAt(tri[1], t), c = mesh.vertexAt(tri[2], t);
    return b.w[0] * a + b.w[1] * bb + b.w[2] * c + triangleFrame(a, bb, c) * b.local;
}

} // namespace gale::solver
