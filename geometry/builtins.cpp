// The geometry built-ins: sdf(), sdfgrad(), shadow(), vdb() and meshvel(). Their file names are
// constant strings checked at compile time by validate hooks (path policy, loading, grid types:
// errors at the argument's file:line:col); kernels then sample cached volumes per block.
#include "geometry/builtins.h"
#include "geometry/cache.h"
#include "geometry/file_policy.h"
#include "geometry/geometry.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <mutex>
#include <shared_mutex>
#include <unordered_map>
#include <utility>

namespace gale::geometry {

namespace {

using runtime::kBlockSize;
using runtime::KernelFrame;
using runtime::Operand;

// What the built-ins of one function table share: the file policy and the references their
// validate hooks resolved (by name as written), read by the kernels.
struct GeometryContext {
    FileAccess access;
    mutable std::shared_mutex mutex;
    mutable std::unordered_map<std::string, std::shared_ptr<const FileRef>> refs;
    mutable std::atomic<bool> reported{false};

    // Resolves `name` now (picking up files added since) and remembers it.
    std::shared_ptr<const FileRef> resolve(const std::string& name, std::string& error) const {
        auto ref = std::make_shared<FileRef>();
        if (!findFiles(access, name, *ref, error)) return nullptr;
        std::unique_lock<std::shared_mutex> lock(mutex);
        refs[name] = ref;
        return ref;
    }
    // The reference the compiler resolved (resolved now when it did not, e.g. a program
    // compiled against another table).
    std::shared_ptr<const FileRef> find(const std::string& name, std::string& error) const {
        {
            std::shared_lock<std::shared_mutex> lock(mutex);
            auto it = refs.find(name);
            if (it != refs.end()) return it->second;
        }
        return resolve(name, error);
    }
};

double smoothstep(double lo, double hi, double x) {
    if (x <= lo) return 0.0;
    if (x >= hi) return 1.0;
    const double u = (x - lo) / (hi - lo);
    return u * u * (3.0 - 2.0 * u);
}

// ---- kernel helpers ----

// An evaluation-time failure (a frame that fails to load): NaN results, and the message once
// per table on the evaluation's message stream (gale eval prints it).
template <class T>
void fail(const KernelFrame<T>& f, const GeometryContext* ctx, int first, int count,
          const std::string& message) {
    for (int k = 0; k < f.outWidth; ++k)
        for (int i = first; i < first + count; ++i)
            f.outComp(k)[i] = std::numeric_limits<T>::quiet_NaN();
    if (f.messages && ctx && !ctx->reported.exchange(true))
        *f.messages += "gale: error: " + message + "\n";
}

template <class T>
void gather3(const Operand<T>& op, int n, double* out) {
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) out[3 * i + k] = static_cast<double>(op.at(k, i));
}

// Calls fn(first, count, frame) over runs of lanes sharing one frame number (one run when
// $frame is uniform, as it is for fields).
template <class T, class F>
void forFrameRuns(const KernelFrame<T>& f, int frameArg, F&& fn) {
    if (frameArg >= f.nargs) {
        fn(0, f.n, 0.0);
        return;
    }
    const Operand<T>& fr = f.args[frameArg];
    if (fr.uniform()) {
        fn(0, f.n, static_cast<double>(fr.at(0, 0)));
        return;
    }
    for (int i0 = 0; i0 < f.n;) {
        const T v = fr.at(0, i0);
        int i1 = i0 + 1;
        while (i1 < f.n && fr.at(0, i1) == v) ++i1;
        fn(i0, i1 - i0, static_cast<double>(v));
        i0 = i1;
    }
}

std::string loadMessage(const FileRef& ref, const FrameFile& file, const io::IoError& e) {
    std::string what = "'" + ref.name + "'";
    if (ref.sequence) what += " (frame " + std::to_string(file.frame) + ")";
    return "cannot load " + what + ": " + (e.file.empty() ? file.path : e.file) + ": " + e.message;
}

// ---- sdf, sdfgrad ----

// args: mesh, P, voxel, $frame
template <bool Gradient>
struct SdfK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const auto* ctx = static_cast<const GeometryContext*>(f.user);
        std::string error;
        std::shared_ptr<const FileRef> ref = ctx ? ctx->find(f.args[0].string(0), error) : nullptr;
        if (!ref) return fail(f, ctx, 0, f.n, error);
        const double voxel = static_cast<double>(f.args[2].at(0, 0));
        double xyz[3 * kBlockSize], out[3 * kBlockSize];
        gather3(f.args[1], f.n, xyz);
        forFrameRuns(f, 3, [&](int i0, int count, double frame) {
            const FrameFile& file = nearestFrame(*ref, frame);
            std::shared_ptr<const SdfVolume> sdf;
            if (io::IoError e = cachedSdf(file, voxel, sdf))
                return fail(f, ctx, i0, count, loadMessage(*ref, file, e));
            if (Gradient)
                sdf->sample(xyz + 3 * i0, static_cast<size_t>(count), nullptr, out + 3 * i0);
            else
                sdf->sample(xyz + 3 * i0, static_cast<size_t>(count), out + i0, nullptr);
            for (int k = 0; k < f.outWidth; ++k)
                for (int i = i0; i < i0 + count; ++i)
                    f.outComp(k)[i] = static_cast<T>(Gradient ? out[3 * i + k] : out[i]);
        });
    }
};

// ---- shadow ----

// args: mesh, P, dir, length, voxel, $frame
struct ShadowK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const auto* ctx = static_cast<const GeometryContext*>(f.user);
        std::string error;
        std::shared_ptr<const FileRef> ref = ctx ? ctx->find(f.args[0].string(0), error) : nullptr;
        if (!ref) return fail(f, ctx, 0, f.n, error);
        const double voxel = static_cast<double>(f.args[4].at(0, 0));
        double xyz[3 * kBlockSize], dir[3 * kBlockSize], length[kBlockSize], out[kBlockSize];
        gather3(f.args[1], f.n, xyz);
        gather3(f.args[2], f.n, dir);
        for (int i = 0; i < f.n; ++i) length[i] = static_cast<double>(f.args[3].at(0, i));
        forFrameRuns(f, 5, [&](int i0, int count, double frame) {
            const FrameFile& file = nearestFrame(*ref, frame);
            std::shared_ptr<const SdfVolume> sdf;
            if (io::IoError e = cachedSdf(file, voxel, sdf))
                return fail(f, ctx, i0, count, loadMessage(*ref, file, e));
            sdf->shadow(xyz + 3 * i0, dir + 3 * i0, length + i0, static_cast<size_t>(count),
                        out + i0);
            for (int i = i0; i < i0 + count; ++i) f.outComp(0)[i] = static_cast<T>(out[i]);
        });
    }
};

// ---- vdb ----

// args: file, grid, P, interp, $frame
struct VdbK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const auto* ctx = static_cast<const GeometryContext*>(f.user);
        std::string error;
        std::shared_ptr<const FileRef> ref = ctx ? ctx->find(f.args[0].string(0), error) : nullptr;
        if (!ref) return fail(f, ctx, 0, f.n, error);
        const std::string& grid = f.args[1].string(0);
        const double code = static_cast<double>(f.args[3].at(0, 0)); // not cast to int: may be NaN
        const VolumeInterp interp = code == 0   ? VolumeInterp::Nearest
                                    : code == 2 ? VolumeInterp::Quadratic
                                                : VolumeInterp::Trilinear;
        double xyz[3 * kBlockSize], va[3 * kBlockSize], vb[3 * kBlockSize];
        gather3(f.args[2], f.n, xyz);
        forFrameRuns(f, 4, [&](int i0, int count, double frame) {
            size_t a = 0, b = 0;
            double w = 0.0;
            bracketFrames(*ref, frame, a, b, w);
            std::shared_ptr<const VelocityVolume> volA, volB;
            if (io::IoError e = cachedVelocity(ref->frames[a], grid, volA))
                return fail(f, ctx, i0, count, loadMessage(*ref, ref->frames[a], e));
            volA->sample(xyz + 3 * i0, static_cast<size_t>(count), interp, va + 3 * i0);
            if (w > 0.0) {
                if (io::IoError e = cachedVelocity(ref->frames[b], grid, volB))
                    return fail(f, ctx, i0, count, loadMessage(*ref, ref->frames[b], e));
                volB->sample(xyz + 3 * i0, static_cast<size_t>(count), interp, vb + 3 * i0);
                for (int i = 3 * i0; i < 3 * (i0 + count); ++i) va[i] += w * (vb[i] - va[i]);
            }
            for (int k = 0; k < 3; ++k)
                for (int i = i0; i < i0 + count; ++i)
                    f.outComp(k)[i] = static_cast<T>(va[3 * i + k]);
        });
    }
};

// ---- meshvel ----

// One frame of a moving mesh: its vertices, their velocity (m per frame, central differences
// of the neighbouring frames present on disk) and its closest-triangle index.
struct FrameMotion {
    std::shared_ptr<const TriangleMesh> mesh;
    std::vector<std::array<float, 3>> velocity;
    std::shared_ptr<const ClosestTriangleIndex> index;
};

io::IoError frameMotion(const FileRef& ref, size_t j, double voxel, int bandVoxels,
                        std::shared_ptr<const FrameMotion>& out) {
    const size_t lo = j > 0 ? j - 1 : j, hi = j + 1 < ref.frames.size() ? j + 1 : j;
    char voxelText[32];
    std::snprintf(voxelText, sizeof voxelText, "%.17g", voxel);
    const std::string key = "motion|" + ref.frames[j].key + "|" + ref.frames[lo].key + "|" +
                            ref.frames[hi].key + "|" + voxelText + "|" + std::to_string(bandVoxels);
    return GeometryCache::global().get<FrameMotion>(
        key,
        [&](std::shared_ptr<const FrameMotion>& v, size_t& bytes) -> io::IoError {
            auto m = std::make_shared<FrameMotion>();
            std::shared_ptr<const TriangleMesh> a, b;
            if (io::IoError e = cachedMesh(ref.frames[j], m->mesh)) return e;
            if (io::IoError e = cachedMesh(ref.frames[lo], a)) return e;
            if (io::IoError e = cachedMesh(ref.frames[hi], b)) return e;
            for (const auto* other : {a.get(), b.get()}) {
                if (other->points.size() != m->mesh->points.size() ||
                    other->triangles != m->mesh->triangles) {
                    io::IoError e;
                    e.kind = io::IoError::Data;
                    e.file = ref.frames[j].path;
                    e.message = "the frames of '" + ref.name +
                                "' do not share one mesh (vertex count or faces differ between "
                                "frame " +
                                std::to_string(ref.frames[j].frame) +
                                " and its neighbours); meshvel() needs the same mesh moving";
                    return e;
                }
            }
            const double span = static_cast<double>(ref.frames[hi].frame - ref.frames[lo].frame);
            m->velocity.assign(m->mesh->points.size(), {0.0f, 0.0f, 0.0f});
            if (span > 0.0)
                for (size_t i = 0; i < m->velocity.size(); ++i)
                    for (int k = 0; k < 3; ++k)
                        m->velocity[i][static_cast<size_t>(k)] = static_cast<float>(
                            (static_cast<double>(b->points[i][static_cast<size_t>(k)]) -
                             a->points[i][static_cast<size_t>(k)]) /
                            span);
            if (io::IoError e = cachedTriangleIndex(ref.frames[j], voxel, bandVoxels, m->index))
                return e;
            bytes = m->velocity.size() * sizeof(m->velocity[0]);
            v = std::move(m);
            return {};
        },
        out);
}

std::array<double, 3> lerp3(const std::array<float, 3>& a, const std::array<float, 3>& b,
                            double w) {
    return {a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2])};
}

// args: mesh, P, falloff, voxel, $frame, $fps
struct MeshVelK {
    template <class T>
    static void run(const KernelFrame<T>& f) {
        const auto* ctx = static_cast<const GeometryContext*>(f.user);
        std::string error;
        std::shared_ptr<const FileRef> ref = ctx ? ctx->find(f.args[0].string(0), error) : nullptr;
        if (!ref) return fail(f, ctx, 0, f.n, error);
        const double voxel = static_cast<double>(f.args[3].at(0, 0));
        const double falloff = std::max(static_cast<double>(f.args[2].at(0, 0)), voxel);
        const double fps = f.nargs > 5 ? static_cast<double>(f.args[5].at(0, 0)) : 24.0;
        // A uniform (non-constant) voxel or falloff is only known now: check it before it
        // becomes a voxel count (a NaN or out-of-range value converted to int is undefined).
        if (!(voxel > 0.0 && std::isfinite(voxel) && std::isfinite(falloff) &&
              falloff / voxel <= 1e6))
            return fail(f, ctx, 0, f.n,
                        "meshvel(): voxel must be a positive number of metres and falloff at "
                        "most a million voxels");
        const int band = static_cast<int>(std::ceil(falloff / voxel));
        double xyz[3 * kBlockSize];
        int32_t cand[8 * kBlockSize];
        gather3(f.args[1], f.n, xyz);
        forFrameRuns(f, 4, [&](int i0, int count, double frame) {
            auto zero = [&] {
                for (int k = 0; k < 3; ++k)
                    for (int i = i0; i < i0 + count; ++i) f.outComp(k)[i] = T(0);
            };
            // Outside the frames on disk the mesh holds still.
            if (!(frame >= ref->frames.front().frame && frame <= ref->frames.back().frame))
                return zero();
            size_t a = 0, b = 0;
            double w = 0.0;
            bracketFrames(*ref, frame, a, b, w);
            std::shared_ptr<const FrameMotion> ma, mb;
            if (io::IoError e = frameMotion(*ref, a, voxel, band, ma))
                return fail(f, ctx, i0, count, loadMessage(*ref, ref->frames[a], e));
            if (io::IoError e = frameMotion(*ref, b, voxel, band, mb))
                return fail(f, ctx, i0, count, loadMessage(*ref, ref->frames[b], e));
            if (ma->mesh->points.size() != mb->mesh->points.size() ||
                ma->mesh->triangles != mb->mesh->triangles)
                return fail(f, ctx, i0, count,
                            "the frames of '" + ref->name + "' do not share one mesh");
            (w > 0.5 ? mb : ma)
                ->index->candidates(xyz + 3 * i0, static_cast<size_t>(count), cand + 8 * i0);
            const auto& tris = ma->mesh->triangles;
            for (int i = i0; i < i0 + count; ++i) {
                const std::array<double, 3> p{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
                double best = std::numeric_limits<double>::infinity();
                std::array<double, 3> bestW{};
                int32_t bestT = -1;
                for (int c = 0; c < 8; ++c) {
                    const int32_t t = cand[8 * i + c];
                    if (t < 0 || static_cast<size_t>(t) >= tris.size() || t == bestT) continue;
                    const auto& tri = tris[static_cast<size_t>(t)];
                    const auto pa = lerp3(ma->mesh->points[tri[0]], mb->mesh->points[tri[0]], w);
                    const auto pb = lerp3(ma->mesh->points[tri[1]], mb->mesh->points[tri[1]], w);
                    const auto pc = lerp3(ma->mesh->points[tri[2]], mb->mesh->points[tri[2]], w);
                    std::array<double, 3> bw;
                    const auto q = closestPointOnTriangle(p, pa, pb, pc, bw);
                    const double d2 = (p[0] - q[0]) * (p[0] - q[0]) +
                                      (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
                    if (d2 < best) {
                        best = d2;
                        bestW = bw;
                        bestT = t;
                    }
                }
                if (bestT < 0) {
                    for (int k = 0; k < 3; ++k) f.outComp(k)[i] = T(0);
                    continue;
                }
                const double fade = 1.0 - smoothstep(0.0, falloff, std::sqrt(best));
                const auto& tri = tris[static_cast<size_t>(bestT)];
                for (int k = 0; k < 3; ++k) {
                    double v = 0.0;
                    for (int c = 0; c < 3; ++c) {
                        const double va =
                            ma->velocity[tri[static_cast<size_t>(c)]][static_cast<size_t>(k)];
                        const double vb =
                            mb->velocity[tri[static_cast<size_t>(c)]][static_cast<size_t>(k)];
                        v += bestW[static_cast<size_t>(c)] * (va + w * (vb - va));
                    }
                    f.outComp(k)[i] = static_cast<T>(v * fps * fade);
                }
            }
        });
    }
};

// ---- validate hooks ----

const GeometryContext& contextOf(const lang::CallSite& site) {
    static const GeometryContext fallback;
    return site.data ? *static_cast<const GeometryContext*>(site.data) : fallback;
}

// A constant string argument; reports and returns null otherwise.
const std::string* constantString(lang::CallSite& site, size_t arg, const char* what,
                                  const char* example) {
    const std::string* s = arg < site.constStrings.size() ? site.constStrings[arg] : nullptr;
    if (!s)
        site.sink->error(site.argSpans[arg], "the " + std::string(what) + " of '" +
                                                 std::string(site.name) +
                                                 "' must be a constant string, e.g. " + example);
    return s;
}

// A numeric argument that sets how a volume is built: not varying, and > 0 when constant.
bool buildSetting(lang::CallSite& site, size_t arg, const char* what) {
    if (arg >= site.argTypes.size()) return true;
    if (site.argTypes[arg].lifetime == lang::Lifetime::Varying) {
        site.sink->error(site.argSpans[arg],
                         "'" + std::string(what) + "' of '" + std::string(site.name) +
                             "' must be uniform (a number or a parameter), not varying: one "
                             "volume is built per value");
        return false;
    }
    const std::vector<double>& v = site.constValues[arg];
    if (!v.empty() && !(v[0] > 0.0 && std::isfinite(v[0]))) {
        site.sink->error(site.argSpans[arg], "'" + std::string(what) + "' of '" +
                                                 std::string(site.name) +
                                                 "' must be a positive number of metres");
        return false;
    }
    return true;
}

std::shared_ptr<const FileRef> resolveArg(lang::CallSite& site, const std::string& name) {
    std::string error;
    std::shared_ptr<const FileRef> ref = contextOf(site).resolve(name, error);
    if (!ref) site.sink->error(site.argSpans[0], error);
    return ref;
}

// A file of `ref` that failed to load (`e` set) is reported at the file argument; true when it
// loaded.
bool loaded(lang::CallSite& site, const FileRef& ref, const FrameFile& file, const io::IoError& e) {
    if (!e) return true;
    site.sink->error(site.argSpans[0], loadMessage(ref, file, e));
    return false;
}

// What the mesh built-ins check first: argument 0 a constant string naming a mesh the file policy
// allows and finds, and each build setting (argument, name) uniform and positive. Every problem
// of the name and the settings is reported; the file is resolved only when there is none. Null
// on any problem.
std::shared_ptr<const FileRef>
meshArgument(lang::CallSite& site, const char* example,
             std::initializer_list<std::pair<size_t, const char*>> settings) {
    const std::string* name = constantString(site, 0, "mesh", example);
    bool ok = name != nullptr;
    for (const auto& [arg, what] : settings) ok = buildSetting(site, arg, what) && ok;
    return ok ? resolveArg(site, *name) : nullptr;
}

// sdf, sdfgrad, shadow: the mesh loads; with a constant voxel, the first frame's SDF is built.
bool validateMeshSdf(lang::CallSite& site, size_t voxelArg) {
    std::shared_ptr<const FileRef> ref = meshArgument(site, "\"body.obj\"", {{voxelArg, "voxel"}});
    if (!ref) return false;
    const FrameFile& first = ref->frames.front();
    std::shared_ptr<const TriangleMesh> mesh;
    if (!loaded(site, *ref, first, cachedMesh(first, mesh))) return false;
    const std::vector<double>& voxel = site.constValues[voxelArg];
    std::shared_ptr<const SdfVolume> sdf;
    return voxel.empty() || loaded(site, *ref, first, cachedSdf(first, voxel[0], sdf));
}

bool validateSdf(lang::CallSite& site) {
    return validateMeshSdf(site, 2);
}
bool validateShadow(lang::CallSite& site) {
    return validateMeshSdf(site, 4);
}

bool validateVdb(lang::CallSite& site) {
    const std::string* name = constantString(site, 0, "file", "\"wind.vdb\"");
    const std::string* grid = constantString(site, 1, "grid name", "\"vel\"");
    bool ok = name && grid;
    const std::vector<double>& interp = site.constValues[3];
    if (interp.empty() || !(interp[0] == 0.0 || interp[0] == 1.0 || interp[0] == 2.0)) {
        site.sink->error(site.argSpans[3], "'interp' of 'vdb' must be a constant 0 (nearest), 1 "
                                           "(trilinear) or 2 (quadratic)");
        ok = false;
    }
    if (!ok) return false;
    std::shared_ptr<const FileRef> ref = resolveArg(site, *name);
    if (!ref) return false;
    // Every frame's header names the grid with a vector type; the first frame loads fully.
    for (const FrameFile& file : ref->frames)
        if (!loaded(site, *ref, file, checkVdbGrid(file.path, *grid))) return false;
    std::shared_ptr<const VelocityVolume> volume;
    return loaded(site, *ref, ref->frames.front(),
                  cachedVelocity(ref->frames.front(), *grid, volume));
}

bool validateMeshVel(lang::CallSite& site) {
    std::shared_ptr<const FileRef> ref =
        meshArgument(site, "\"body.#.obj\"", {{2, "falloff"}, {3, "voxel"}});
    if (!ref) return false;
    if (!ref->sequence) {
        site.sink->error(site.argSpans[0],
                         "meshvel() needs a per-frame mesh sequence with a frame number (\"body.#.obj\", "
                         "\"body.%04d.obj\" or \"body.$F4.obj\"); '" +
                             ref->name + "' is one mesh, which does not move");
        return false;
    }
    std::shared_ptr<const TriangleMesh> mesh;
    return loaded(site, *ref, ref->frames.front(), cachedMesh(ref->frames.front(), mesh));
}

void addGeometryBuiltinsWith(runtime::FunctionTable& t, std::shared_ptr<GeometryContext> ctx) {
    std::shared_ptr<const void> data = ctx;
    auto finish = [&](runtime::Builtin b, bool (*validate)(lang::CallSite&),
                      std::vector<lang::FunctionInfo::Implicit> implicit) {
        b.info.validate = validate;
        b.info.implicitArgs = std::move(implicit);
        b.info.hookData = ctx.get();
        b.data = data;
        t.add(std::move(b));
    };
    finish(runtime::kernelBuiltin<SdfK<false>>(
               "sdf", "FP[1] sdf(STRING mesh, FP[3] P, FP[1] voxel = 0.02)",
               "signed distance (m, negative inside) from P to a closed OBJ/PLY mesh, from a "
               "narrow-band SDF of that voxel size (cached); 'body.#.obj' follows $frame"),
           &validateSdf, {{"frame", 0.0}});
    finish(runtime::kernelBuiltin<SdfK<true>>(
               "sdfgrad", "FP[3] sdfgrad(STRING mesh, FP[3] P, FP[1] voxel = 0.02)",
               "unit gradient of sdf() at P: the outward direction away from the mesh"),
           &validateSdf, {{"frame", 0.0}});
    finish(runtime::kernelBuiltin<ShadowK>(
               "shadow",
               "FP[1] shadow(STRING mesh, FP[3] P, FP[3] dir, FP[1] length, FP[1] voxel = 0.02)",
               "wind shadow of a mesh: 1 in free air, 0 inside and right behind it along the "
               "wind direction dir, back to 1 at `length` m downwind"),
           &validateShadow, {{"frame", 0.0}});
    finish(runtime::kernelBuiltin<VdbK>(
               "vdb", "FP[3] vdb(STRING file, STRING grid, FP[3] P, FP[1] interp = 1)",
               "a vector grid of a .vdb file sampled at P in world space (interp 0 nearest, 1 "
               "trilinear, 2 quadratic); 'wind.#.vdb' blends the frames around $frame"),
           &validateVdb, {{"frame", 0.0}});
    finish(runtime::kernelBuiltin<MeshVelK>(
               "meshvel", "FP[3] meshvel(STRING mesh, FP[3] P, FP[1] falloff, FP[1] voxel = 0.02)",
               "velocity (m/s) of the closest surface point of a per-frame mesh sequence "
               "('body.#.obj', at $frame and $fps), fading to 0 at `falloff` m from it"),
           &validateMeshVel, {{"frame", 0.0}, {"fps", 24.0}});
}

} // namespace

void addGeometryBuiltins(runtime::FunctionTable& t, const FileAccess& access) {
    auto ctx = std::make_shared<GeometryContext>();
    ctx->access = access;
    addGeometryBuiltinsWith(t, std::move(ctx));
}

std::shared_ptr<const runtime::FunctionTable>
withFileAccess(const std::shared_ptr<const runtime::FunctionTable>& table,
               const FileAccess& access) {
    auto copy = std::make_shared<runtime::FunctionTable>(
        table ? *table : *runtime::FunctionTable::standard());
    addGeometryBuiltins(*copy, access);
    return copy;
}

} // namespace gale::geometry
