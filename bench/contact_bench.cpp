// Moving mesh contact (issue 15): cost per substep against a body of 5k, 20k and 80k triangles —
// the tree's refit against a full rebuild (measured in the same run), the broad phase (tree
// queries) and the narrow phase (CCD) of the continuous pass, and the whole cloth step with the
// body against the same step without it; then speed against error for the collision thickness
// and the substeps (a ball at 5 m/s into a free sheet: the closest approach to the surface and
// the cost per frame). With --scene, a scene file instead (e.g. examples/09_walking_cape): its
// frames simulated, and the continuous pass's cost split by pair — cloth vertex–body triangle
// and edge–edge together, and the body vertex–cloth triangle pair apart.
// The step's cost is measured without per-primitive clocks (as a user's run has it); the broad
// and narrow phase split comes from a second run with them.
// Usage: gale_bench_contact [steps=24] [--tris N]
//        gale_bench_contact --scene SCENE.toml [--set KEY=VALUE]...
#include "geometry/geometry.h"
#include "run/sim_run.h"
#include "solver/bodies/cloth.h"
#include "solver/collider/collider.h"
#include "solver/collider/moving_collider.h"
#include "solver/world/world.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>

using namespace gale::solver;

namespace {

double seconds(const std::function<void()>& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Sphere {
    std::vector<std::array<int, 3>> tris;
    std::vector<double> pos;
};
// A UV sphere of radius r with about `triangles` triangles.
Sphere sphere(double r, int triangles) {
    const int nlon = static_cast<int>(std::sqrt(triangles)), nlat = triangles / (2 * nlon) + 1;
    const gale::geometry::TriangleMesh m = gale::geometry::uvSphereMesh({0, 0, 0}, r, nlat, nlon);
    Sphere s;
    for (const auto& p : m.points) s.pos.insert(s.pos.end(), {p[0], p[1], p[2]});
    for (const auto& t : m.triangles)
        s.tris.push_back({static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])});
    return s;
}

// The sphere flying along +z at `speed` (m/s) from z0, turning `spin` (rad/s) about its
// vertical axis (y) as it goes.
std::shared_ptr<const MeshSequence> flying(const Sphere& s, double z0, double speed, int frames,
                                           double fps, double spin = 0.0) {
    std::vector<std::vector<double>> pos;
    for (int f = 0; f <= frames; ++f) {
        std::vector<double> p = s.pos;
        const double a = spin * f / fps, ca = std::cos(a), sa = std::sin(a);
        for (size_t i = 0; i + 2 < p.size(); i += 3) {
            const double x = s.pos[i], z = s.pos[i + 2];
            p[i] = ca * x + sa * z;
            p[i + 2] = -sa * x + ca * z + z0 + speed * f / fps;
        }
        pos.push_back(std::move(p));
    }
    return std::make_shared<MeshSequence>(s.tris, pos, 0, fps);
}

struct Run {
    // Frames after the first (the steady state: trees refitted, the solver set up) and their
    // substeps, and the first frame (the trees built once, the solver's one-time set-up).
    double secondsPerFrame = 0.0, laterSeconds = 0.0, firstFrame = 0.0, closest = INFINITY;
    MovingContactStats stats;
    int substeps = 0, laterSubsteps = 0; // all, and those after the first frame
};

// Seconds a substep after the first frame.
double stepSeconds(const Run& r) {
    return r.laterSeconds / std::max(1, r.laterSubsteps);
}

// A 0.6 m sheet of res² vertices hit by the ball (radius 0.2 m) at 5 m/s; `withBody` false:
// the same sheet without the collider (the baseline).
Run ballRun(const Sphere& ball, int res, int substeps, double thickness, int frames, bool withBody,
            bool detailedTiming = false, double spin = 0.0) {
    const double fps = 24.0;
    Collider c;
    c.shape = ColliderShape::Mesh;
    c.thickness = thickness;
    c.moving = std::make_shared<MovingMeshContact>(flying(ball, -0.35, 5.0, frames + 1, fps, spin));
    c.moving->setDetailedTiming(detailedTiming);
    ClothMaterial mat;
    auto cloth =
        std::make_unique<Cloth>("sheet", makeGrid(0.6, 0.6, res, res, Vec3(-0.3, -0.3, 0.0)), mat);
    Cloth* sheet = cloth.get();
    WorldSettings ws;
    ws.fps = fps;
    ws.substeps = substeps;
    World world(ws);
    world.addBody(std::move(cloth));
    if (withBody) world.addCollider(c);
    Run r;
    for (int f = 1; f <= frames; ++f) {
        FrameStats fs;
        const double s = seconds([&] { fs = world.advanceFrame(f); });
        r.substeps += fs.bodies[0].substeps;
        if (f == 1) {
            r.firstFrame = s;
        } else {
            r.laterSeconds += s;
            r.laterSubsteps += fs.bodies[0].substeps;
        }
        if (!withBody) continue;
        c.moving->prepare(f / fps, f / fps); // the body at the frame's end
        for (size_t i = 0; i < sheet->vertexCount(); ++i) {
            ContactPoint cp;
            if (c.moving->closest(vec3At(sheet->positions().data(), i), true, 0.1, cp))
                r.closest = std::min(r.closest, cp.distance);
        }
    }
    r.secondsPerFrame = r.laterSeconds / std::max(1, frames - 1);
    r.stats = c.moving->stats();
    return r;
}

// The scene's frames, then per moving collider the pass's statistics: time in the sweep (broad
// and narrow phase) and the body vertex–cloth triangle pair's share of it, candidates and hits
// by pair, against the frames' wall time.
int sceneRun(const std::string& path, const std::vector<std::string>& sets) {
    gale::run::SimSetup setup;
    setup.scene = path;
    setup.sets = sets;
    gale::run::SimRun sim;
    std::string report;
    const gale::run::RunError err = sim.load(setup, report);
    std::fputs(report.c_str(), stderr);
    if (err) {
        std::fprintf(stderr, "%s\n", err.text().c_str());
        return 1;
    }
    for (const Collider& c : sim.world().colliders())
        if (c.moving) c.moving->setDetailedTiming(true);
    double wall = 0.0;
    int substeps = 0;
    for (int f = sim.first() + 1; f <= sim.last(); ++f) {
        gale::solver::FrameStats fs;
        wall += seconds([&] { fs = sim.advance(f); });
        for (const auto& b : fs.bodies) substeps += b.substeps;
        if (fs.failed) {
            std::fprintf(stderr, "frame %d failed\n", f);
            return 1;
        }
    }
    std::printf("%s: %d frames, %.1f ms a frame, %d body substeps\n", path.c_str(),
                sim.last() - sim.first(), 1e3 * wall / std::max(1, sim.last() - sim.first()),
                substeps);
    std::printf("| collider | refit ms | steps refitted / trees kept | sweep ms (broad + narrow) | "
                "body vertex-cloth face ms | "
                "share | candidates | face candidates | vertex hits | edge hits | face hits | "
                "unresolved |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Collider& c : sim.world().colliders()) {
        if (!c.moving) continue;
        const MovingContactStats& st = c.moving->stats();
        const double sweep = st.broadSeconds + st.narrowSeconds;
        std::printf("| %s | %.1f | %lld / %lld | %.1f | %.1f | %.2f | %lld | %lld | %lld | %lld | "
                    "%lld | %lld |\n",
                    c.name.c_str(), 1e3 * st.refitSeconds, st.refits, st.kept, 1e3 * sweep,
                    1e3 * st.faceSeconds, sweep > 0.0 ? st.faceSeconds / sweep : 0.0, st.candidates,
                    st.faceCandidates, st.vertexHits, st.edgeHits, st.faceHits, st.unresolved);
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    if (argc > 2 && std::strcmp(argv[1], "--scene") == 0) {
        std::vector<std::string> sets;
        for (int i = 3; i + 1 < argc; i += 2)
            if (std::strcmp(argv[i], "--set") == 0) sets.push_back(argv[i + 1]);
        return sceneRun(argv[2], sets);
    }
    const int frames = argc > 1 ? std::atoi(argv[1]) : 24;
    // `--tris N`: the ball table's row of N triangles only (5000, 20000 or 80000).
    const int onlyTris = argc > 3 && std::strcmp(argv[2], "--tris") == 0 ? std::atoi(argv[3]) : 0;
    std::printf("## Contact cost per substep (ball r = 0.2 m at 5 m/s into a 0.6 m sheet, 48x48, "
                "1 substep/frame, %d frames)\n\n",
                frames);
    std::printf("Per substep after the first (the first frame, which builds the trees and sets "
                "the solver up, in the last two columns); broad, narrow and body vertex-face ms "
                "from a second run with per-primitive clocks\n\n");
    std::printf("| body triangles | prepare ms (refit, or trees kept) | rebuild ms | "
                "prepare/rebuild | broad ms | narrow ms | "
                "candidates/substep "
                "| step ms with body | step ms without | ratio | body vertex-face ms | tree build "
                "ms | first frame ms with / without "
                "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int tris : {5000, 20000, 80000}) {
        if (onlyTris > 0 && tris != onlyTris) continue;
        const Sphere ball = sphere(0.2, tris);
        // The step's cost as a user's run has it (no per-primitive clocks); its split into
        // broad and narrow phase from a second run with them.
        const Run with = ballRun(ball, 48, 1, 0.005, frames, true);
        const Run split = ballRun(ball, 48, 1, 0.005, frames, true, true);
        const Run without = ballRun(ball, 48, 1, 0.005, frames, false);
        // Rebuild for comparison: a fresh tree over the same boxes each time.
        MovingMeshContact probe(flying(ball, 0.0, 5.0, 2, 24.0));
        probe.prepare(0.0, 1.0 / 24.0);
        const double refit =
            with.stats.refitSeconds / std::max<long long>(1, with.stats.refits + with.stats.kept);
        double rebuild = 1e30;
        for (int k = 0; k < 3; ++k) {
            MovingMeshContact fresh(flying(ball, 0.0, 5.0, 2, 24.0));
            rebuild = std::min(rebuild, seconds([&] { fresh.prepare(0.0, 1.0 / 24.0); }));
        }
        const double steps = static_cast<double>(std::max(1, with.substeps));
        std::printf("| %zu | %.3f | %.3f | %.2f | %.3f | %.3f | %.0f | %.2f | %.2f | %.2fx | %.3f "
                    "| %.1f | %.1f / %.1f |\n",
                    ball.tris.size(), 1e3 * refit, 1e3 * rebuild, refit / rebuild,
                    1e3 * split.stats.broadSeconds / steps, 1e3 * split.stats.narrowSeconds / steps,
                    with.stats.candidates / steps, 1e3 * stepSeconds(with),
                    1e3 * stepSeconds(without), stepSeconds(with) / stepSeconds(without),
                    1e3 * split.stats.faceSeconds / steps, 1e3 * with.stats.buildSeconds,
                    1e3 * with.firstFrame, 1e3 * without.firstFrame);
    }
    // The same ball turning once a second about its vertical axis (15° a step: its surface
    // moves up to 5 cm a step against its centre, so its trees are refitted every step).
    std::printf("\nThe ball turning once a second as it flies (trees refitted every step)\n\n");
    std::printf("| body triangles | refit ms | candidates/substep | step ms with body | step ms "
                "without | ratio |\n|---|---|---|---|---|---|\n");
    for (int tris : {5000, 20000, 80000}) {
        if (onlyTris > 0 && tris != onlyTris) continue;
        const Sphere ball = sphere(0.2, tris);
        const Run with = ballRun(ball, 48, 1, 0.005, frames, true, false, 2.0 * M_PI);
        const Run without = ballRun(ball, 48, 1, 0.005, frames, false);
        const double steps = static_cast<double>(std::max(1, with.substeps));
        std::printf("| %zu | %.3f | %.0f | %.2f | %.2f | %.2fx |\n", ball.tris.size(),
                    1e3 * with.stats.refitSeconds / std::max<long long>(1, with.stats.refits),
                    with.stats.candidates / steps, 1e3 * stepSeconds(with),
                    1e3 * stepSeconds(without), stepSeconds(with) / stepSeconds(without));
    }
    if (onlyTris > 0) return 0;
    std::printf(
        "\n## Speed against error: thickness and substeps (5k-triangle ball, 32x32 sheet)\n\n");
    std::printf("| thickness m | substeps | ms/frame | closest approach m | closest / thickness | "
                "unresolved |\n"
                "|---|---|---|---|---|---|\n");
    const Sphere ball = sphere(0.2, 5000);
    for (double th : {0.002, 0.005, 0.02})
        for (int sub : {1, 2, 4}) {
            const Run r = ballRun(ball, 32, sub, th, frames, true);
            std::printf("| %.3f | %d | %.2f | %.4f | %.2f | %lld |\n", th, sub,
                        1e3 * r.secondsPerFrame, r.closest, r.closest / th, r.stats.unresolved);
        }
    return 0;
}
