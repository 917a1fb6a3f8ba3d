// Animated triangle meshes from per-frame files (`body.#.obj` -> body.0001.obj, ..., OBJ or PLY;
// the `#` rule of vdb() and meshvel(), geometry/file_policy.h): one topology for every frame,
// positions linear in time within a frame (frame F at t = (F − time_zero) / fps), held before the
// first and after the last. A plain file name is a one-frame (static) sequence. A pre-rolled copy
// (scene.preroll) eases from a rest pose to the sequence's pose and velocity at the shot's start.
#pragma once

#include <cmath>

#include "solver/linalg/types.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace gale::solver {

class MeshSequence {
public:
    // Loads every frame of `path` (resolved; a '#' run in the file name for a sequence). Null with
    // `error` naming the file: unreadable, a frame missing between the first and the last found
    // on disk, or a frame whose vertex count or faces differ from the first's.
    // Frame F is at t = (F − frameZero) / fps (scene.time_zero).
    static std::shared_ptr<const MeshSequence> load(const std::string& path, double fps,
                                                    std::string& error, double frameZero = 0.0);
    // From positions already in memory (frames[k] is frame firstFrame + k; tests, generators).
    MeshSequence(std::vector<std::array<int, 3>> triangles, std::vector<std::vector<double>> frames,
                 long firstFrame, double fps, double frameZero = 0.0);

    // A copy (sharing the frames) that, before `to` (s), eases from `rest` (3 per vertex; the rest
    // pose) held until `from` to this sequence's pose and velocity at `to` — a cubic Hermite in
    // time, x(u) = r + (3u² − 2u³)(p − r) + (u³ − u²)·T·v with u = (t − from)/T, T = to − from, p
    // and v the pose at `to` and the velocity of the frame after it — so that positions and
    // velocities are continuous where the shot starts (scene.preroll). Null with `error` when
    // `rest` has another vertex count or from ≥ to.
    std::shared_ptr<const MeshSequence> eased(std::vector<double> rest, double from, double to,
                                              std::string& error) const;

    size_t vertexCount() const { return mFrames->empty() ? 0 : mFrames->front().size() / 3; }
    const std::vector<std::array<int, 3>>& triangles() const { return mTriangles; }
    size_t frameCount() const { return mFrames->size(); }
    long firstFrame() const { return mFirstFrame; }
    long lastFrame() const { return mFirstFrame + static_cast<long>(mFrames->size()) - 1; }
    double frameZero() const { return mFrameZero; }
    // Seconds at frame F of the sequence.
    double frameTime(double frame) const { return (frame - mFrameZero) / mFps; }
    double fps() const { return mFps; }
    bool moving() const { return mFrames->size() > 1 || mEase; }
    const std::string& path() const { return mPath; }

    // Vertex positions at time t (3 per vertex), linear between the two frames around t·fps.
    void positionsAt(double t, std::vector<double>& out) const;
    // The positions of the first frame (the bind pose of attachments).
    const std::vector<double>& firstPositions() const { return mFrames->front(); }
    // One vertex at time t (the same interpolation as positionsAt).
    Vec3 vertexAt(int v, double t) const;
    // The triangles around vertex v (indices into triangles()) and v's corner in each (0–2).
    struct Corner {
        int triangle, corner;
    };
    const Corner* cornersBegin(int v) const { return mCorners.data() + mCornerStart[v]; }
    const Corner* cornersEnd(int v) const { return mCorners.data() + mCornerStart[v + 1]; }

private:
    // The pre-roll (eased()): x(t) = rest + h(u)·dp + g(u)·dv for t < to.
    struct Ease {
        double from = 0.0, to = 0.0;
        std::vector<double> rest, dp, dv; // r, p − r, T·v (3 per vertex)
    };
    // The sequence as loaded, without the pre-roll.
    void rawPositionsAt(double t, std::vector<double>& out) const;
    Vec3 rawVertexAt(int v, double t) const;

    void buildCorners();

    std::vector<std::array<int, 3>> mTriangles;
    std::vector<Corner> mCorners; // per vertex, its triangles (CSR over mCornerStart)
    std::vector<size_t> mCornerStart;
    std::shared_ptr<const std::vector<std::vector<double>>> mFrames;
    std::shared_ptr<const Ease> mEase;
    long mFirstFrame = 0;
    double mFps = 24.0;
    double mFrameZero = 0.0;
    std::string mPath;
};

// A point bound to a mesh's surface (attachments) so that it rides the skin smoothly: its
// closest triangle at the bind pose, the point y on that triangle's plane it projects to along the
// smoothed normal n_s (barycentric weights w, which may leave the triangle), and its height h
// along n_s: x = Σ wₖ pₖ + h·n_s, with n_s(w) = normalize(Σ ŵₖ Nₖ), Nₖ the angle-weighted vertex
// normals and ŵ the weights clamped to the triangle (Maya's "attract to matching mesh" and
// Houdini's "attach to geometry" ride a smooth frame the same way). Exactly the point's own
// position at the bind pose; a continuous function of the point across the triangles' edges (two
// neighbours bound to two triangles stay together as the skin bends), where a rigid offset in each
// triangle's own frame jumps at every crease. `alongFace`: n_s would not reach the point (vertex
// normals near the face's plane, or a point far above a curved surface), so the height is along
// the face normal instead.
struct SurfaceBinding {
    int triangle = -1;
    double w[3] = {0, 0, 0};
    double height = 0.0;
    bool alongFace = false;
    double distance = 0.0; // m: the point's distance to the surface at the bind pose
};
// `t` (s): the time of the pose it binds against, the body interpolated there (NaN: the
// sequence's first file).
SurfaceBinding bindToSurface(const MeshSequence& mesh, const Vec3& x, double t = NAN);
Vec3 boundPosition(const MeshSequence& mesh, const SurfaceBinding& b, double t);

} // namespace gale::solver
