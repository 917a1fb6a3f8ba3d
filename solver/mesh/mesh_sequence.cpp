// Mesh sequences: the frames found through geometry::findFiles (the one `#` rule), each read
// with loadMesh and checked against the first frame's topology.
#include "solver/mesh/mesh_sequence.h"

#include "geometry/file_policy.h"
#include "io/grid.h"
#include "solver/contact/ccd.h"
#include "solver/mesh/mesh.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace gale::solver {

MeshSequence::MeshSequence(std::vector<std::array<int, 3>> triangles,
                           std::vector<std::vector<double>> frames, long firstFrame, double fps,
                           double frameZero)
    : mTriangles(std::move(triangles)),
      mFrames(std::make_shared<const std::vector<std::vector<double>>>(std::move(frames))),
      mFirstFrame(firstFrame), mFps(fps), mFrameZero(frameZero) {
    buildCorners();
}

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

void MeshSequence::rawPositionsAt(double t, std::vector<double>& out) const {
    const std::vector<std::vector<double>>& frames = *mFrames;
    const double f = t * mFps - (static_cast<double>(mFirstFrame) - mFrameZero);
    const long last = static_cast<long>(frames.size()) - 1;
    if (last <= 0 || !(f > 0.0)) {
        out = frames.front();
        return;
    }
    if (f >= static_cast<double>(last)) {
        out = frames.back();
        return;
    }
    const long a = static_cast<long>(std::floor(f));
    const double w = f - static_cast<double>(a);
    const std::vector<double>& pa = frames[a];
    const std::vector<double>& pb = frames[a + 1];
    out.resize(pa.size());
    for (size_t i = 0; i < pa.size(); ++i) out[i] = pa[i] + w * (pb[i] - pa[i]);
}

Vec3 MeshSequence::rawVertexAt(int v, double t) const {
    const std::vector<std::vector<double>>& frames = *mFrames;
    const double f = t * mFps - (static_cast<double>(mFirstFrame) - mFrameZero);
    const long last = static_cast<long>(frames.size()) - 1;
    if (last <= 0 || !(f > 0.0)) return vec3At(frames.front().data(), v);
    if (f >= static_cast<double>(last)) return vec3At(frames.back().data(), v);
    const long a = static_cast<long>(std::floor(f));
    const double w = f - static_cast<double>(a);
    const Vec3 pa = vec3At(frames[a].data(), v), pb = vec3At(frames[a + 1].data(), v);
    return pa + w * (pb - pa);
}

namespace {
// The Hermite weights of the pre-roll at u = (t − from)/T ∈ [0, 1]: h(u) = 3u² − 2u³ on p − r
// (0 → 1, flat at both ends) and g(u) = u³ − u² on T·v (0 at both ends, slope 1 at u = 1).
void easeWeights(double u, double& h, double& g) {
    u = std::clamp(u, 0.0, 1.0);
    h = u * u * (3.0 - 2.0 * u);
    g = u * u * (u - 1.0);
}
} // namespace

void MeshSequence::positionsAt(double t, std::vector<double>& out) const {
    if (!mEase || !(t < mEase->to)) {
        rawPositionsAt(t, out);
        return;
    }
    double h = 0.0, g = 0.0;
    easeWeights((t - mEase->from) / (mEase->to - mEase->from), h, g);
    const Ease& e = *mEase;
    out.resize(e.rest.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = e.rest[i] + h * e.dp[i] + g * e.dv[i];
}

Vec3 MeshSequence::vertexAt(int v, double t) const {
    if (!mEase || !(t < mEase->to)) return rawVertexAt(v, t);
    double h = 0.0, g = 0.0;
    easeWeights((t - mEase->from) / (mEase->to - mEase->from), h, g);
    const Ease& e = *mEase;
    return vec3At(e.rest.data(), v) + h * vec3At(e.dp.data(), v) + g * vec3At(e.dv.data(), v);
}

std::shared_ptr<const MeshSequence> MeshSequence::eased(std::vector<double> rest, double from,
                                                        double to, std::string& error) const {
    if (rest.size() != mFrames->front().size()) {
        error = "the rest pose has " + std::to_string(rest.size() / 3) +
                " vertices, the sequence " + std::to_string(vertexCount()) +
                ": it needs the sequence's topology";
        return nullptr;
    }
    if (!(from < to)) {
        error = "the pre-roll must end after it starts";
        return nullptr;
    }
    for (double x : rest)
        if (!std::isfinite(x)) {
            error = "a vertex of the rest pose is not finite";
            return nullptr;
        }
    auto e = std::make_shared<Ease>();
    e->from = from;
    e->to = to;
    // p: the pose at `to`; v: the velocity of the frame after it (0 where the sequence is held).
    std::vector<double> p, next;
    rawPositionsAt(to, p);
    const double frame = 1.0 / mFps;
    rawPositionsAt(to + frame, next);
    const double span = to - from;
    e->dp.resize(p.size());
    e->dv.resize(p.size());
    for (size_t i = 0; i < p.size(); ++i) {
        e->dp[i] = p[i] - rest[i];
        e->dv[i] = span * (next[i] - p[i]) / frame;
    }
    e->rest = std::move(rest);
    auto seq = std::make_shared<MeshSequence>(*this);
    seq->mEase = std::move(e);
    return seq;
}

void MeshSequence::buildCorners() {
    const size_t nv = vertexCount();
    mCornerStart.assign(nv + 1, 0);
    for (const auto& t : mTriangles)
        for (int v : t)
            if (v >= 0 && static_cast<size_t>(v) < nv) ++mCornerStart[v + 1];
    for (size_t v = 0; v < nv; ++v) mCornerStart[v + 1] += mCornerStart[v];
    mCorners.assign(mCornerStart[nv], Corner{0, 0});
    std::vector<size_t> fill(mCornerStart.begin(), mCornerStart.end() - 1);
    for (size_t k = 0; k < mTriangles.size(); ++k)
        for (int c = 0; c < 3; ++c) {
            const int v = mTriangles[k][c];
            if (v >= 0 && static_cast<size_t>(v) < nv)
                mCorners[fill[v]++] = Corner{static_cast<int>(k), c};
        }
}

namespace {

Vec3 unitFaceNormal(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = (b - a).cross(c - a);
    const double len = n.norm();
    return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

// The angle-weighted normal of vertex v with positions from `pos(vertex)`.
template <class Pos>
Vec3 angleWeightedNormal(const MeshSequence& m, int v, const Pos& pos) {
    Vec3 sum = Vec3::Zero();
    for (const MeshSequence::Corner* c = m.cornersBegin(v); c != m.cornersEnd(v); ++c) {
        const auto& t = m.triangles()[c->triangle];
        const Vec3 p = pos(t[c->corner]), a = pos(t[(c->corner + 1) % 3]),
                   b = pos(t[(c->corner + 2) % 3]);
        const Vec3 ea = a - p, eb = b - p;
        const double la = ea.norm(), lb = eb.norm();
        if (!(la > 0.0) || !(lb > 0.0)) continue;
        const double angle = std::acos(std::clamp(ea.dot(eb) / (la * lb), -1.0, 1.0));
        sum += angle * unitFaceNormal(p, a, b);
    }
    const double len = sum.norm();
    return len > 0.0 ? Vec3(sum / len) : Vec3::Zero();
}

// n_s(w): the vertex normals of triangle `tri` blended by the weights clamped to the triangle.
template <class Pos>
Vec3 smoothNormal(const MeshSequence& m, int tri, const double w[3], const Pos& pos) {
    double c[3], sum = 0.0;
    for (int k = 0; k < 3; ++k) sum += (c[k] = std::max(w[k], 0.0));
    Vec3 n = Vec3::Zero();
    const auto& t = m.triangles()[tri];
    for (int k = 0; k < 3; ++k)
        if (c[k] > 0.0) n += (c[k] / sum) * angleWeightedNormal(m, t[k], pos);
    const double len = n.norm();
    return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

// Barycentric weights of y's projection onto the plane of (a, b, c) (outside it too).
void planeWeights(const Vec3& y, const Vec3& a, const Vec3& b, const Vec3& c, double w[3]) {
    const Vec3 e0 = b - a, e1 = c - a, e2 = y - a;
    const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
    const double d20 = e2.dot(e0), d21 = e2.dot(e1), den = d00 * d11 - d01 * d01;
    if (!(den > 0.0)) {
        w[0] = 1.0;
        w[1] = w[2] = 0.0;
        return;
    }
    w[1] = (d11 * d20 - d01 * d21) / den;
    w[2] = (d00 * d21 - d01 * d20) / den;
    w[0] = 1.0 - w[1] - w[2];
}

template <class Pos>
Vec3 bound(const MeshSequence& m, const SurfaceBinding& b, const Pos& pos) {
    const auto& t = m.triangles()[b.triangle];
    const Vec3 a = pos(t[0]), bb = pos(t[1]), c = pos(t[2]);
    const Vec3 y = b.w[0] * a + b.w[1] * bb + b.w[2] * c;
    const Vec3 n = b.alongFace ? unitFaceNormal(a, bb, c) : smoothNormal(m, b.triangle, b.w, pos);
    return y + b.height * n;
}

} // namespace

SurfaceBinding bindToSurface(const MeshSequence& mesh, const Vec3& x, double when) {
    SurfaceBinding b;
    double best = INFINITY;
    std::vector<double> at;
    if (std::isfinite(when)) {
        const size_t nv = mesh.firstPositions().size() / 3;
        at.resize(3 * nv);
        for (size_t v = 0; v < nv; ++v) vec3At(at.data(), v) = mesh.vertexAt(static_cast<int>(v), when);
    }
    const std::vector<double>& p = std::isfinite(when) ? at : mesh.firstPositions();
    const auto pos = [&](int v) { return Vec3(vec3At(p.data(), v)); };
    for (size_t k = 0; k < mesh.triangles().size(); ++k) {
        const auto& t = mesh.triangles()[k];
        double w[3];
        const double d2 = contact::pointTriangleDistance2(x, pos(t[0]), pos(t[1]), pos(t[2]), w);
        if (d2 < best) {
            best = d2;
            b.triangle = static_cast<int>(k);
            std::copy(w, w + 3, b.w);
        }
    }
    if (b.triangle < 0) return b;
    b.distance = std::sqrt(best);
    const auto& t = mesh.triangles()[b.triangle];
    const Vec3 a = pos(t[0]), bb = pos(t[1]), c = pos(t[2]);
    const Vec3 nf = unitFaceNormal(a, bb, c);
    // x = y(w) + h·n_s(w) with y on the triangle's plane: a fixed point in w, from the closest
    // point's weights (it contracts by about h/R, R the surface's radius of curvature there).
    const double scale = std::max({1.0, x.norm(), (bb - a).norm(), (c - a).norm()});
    for (int it = 0; it < 20; ++it) {
        const Vec3 ns = smoothNormal(mesh, b.triangle, b.w, pos);
        const double cosine = ns.dot(nf);
        if (!(cosine > 0.2)) break;
        b.height = (x - a).dot(nf) / cosine;
        planeWeights(x - b.height * ns, a, bb, c, b.w);
        if ((bound(mesh, b, pos) - x).norm() <= 1e-12 * scale) return b;
    }
    if ((bound(mesh, b, pos) - x).norm() <= 1e-9 * scale && b.height == b.height) return b;
    // Along the face normal: exact by construction.
    b.alongFace = true;
    b.height = (x - a).dot(nf);
    planeWeights(x - b.height * nf, a, bb, c, b.w);
    return b;
}

Vec3 boundPosition(const MeshSequence& mesh, const SurfaceBinding& b, double t) {
    return bound(mesh, b, [&](int v) { return mesh.vertexAt(v, t); });
}

} // namespace gale::solver
