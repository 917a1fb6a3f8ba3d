// gale_bench_bullet_flag: the peer of the issue-14 flag benchmark — aero.md's 24×24 gossamer flag
// (1 m × 1 m, 0.005 kg/m², pinned along the pole edge x = 0, uniform wind 3° off edge-on) as a
// Bullet soft body (Debian's libbullet-dev), stepped at a fixed step; prints one JSON line.
//   gale_bench_bullet_flag [--wind U] [--angle DEG] [--steps-per-frame N] [--frames F]
//                          [--fps R] [--res N] [--iterations P] [--lift K] [--drag K] [--obj DIR]
// Bullet's F_TwoSidedLiftDrag (btSoftBody.cpp, 3.24): drag ½ kDG ρ |v|² A cosθ along the flow
// (gale's drag term), lift ½ kLF ρ |v| A sinθ across it, only beyond 10° from broadside — one
// power of |v| below gale's ½ C_L ρ |v|² A, so --lift 0.3·U matches gale's lift at speed U.
// "bounded": every position finite and every link under 3× its rest length at every frame end
// (the over-stretch limit gale's own substep check uses).
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>

namespace {

struct Options {
    double wind = 20.0;     // m/s
    double angle = 3.0;     // degrees off edge-on, towards +z (the flag's normal)
    int stepsPerFrame = 64; // fixed Bullet steps per frame
    int frames = 48;        // frames simulated after the rest frame
    double fps = 24.0;
    int res = 24;       // vertices per side, as gale's grid res
    int iterations = 1; // Bullet's position-solver iterations (m_cfg.piterations)
    double lift = 0.3;  // kLF (gale's lift = 0.3)
    double drag = 1.0;  // kDG (gale's drag = 1.0)
    std::string objDir; // write DIR/flag.NNNN.obj per frame (frame 1 = rest) when set
};

bool parse(int argc, char** argv, Options& o) {
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (i + 1 >= argc) return false;
        const char* v = argv[++i];
        if (a == "--wind")
            o.wind = std::atof(v);
        else if (a == "--angle")
            o.angle = std::atof(v);
        else if (a == "--steps-per-frame")
            o.stepsPerFrame = std::atoi(v);
        else if (a == "--frames")
            o.frames = std::atoi(v);
        else if (a == "--fps")
            o.fps = std::atof(v);
        else if (a == "--res")
            o.res = std::atoi(v);
        else if (a == "--iterations")
            o.iterations = std::atoi(v);
        else if (a == "--lift")
            o.lift = std::atof(v);
        else if (a == "--drag")
            o.drag = std::atof(v);
        else if (a == "--obj")
            o.objDir = v;
        else
            return false;
    }
    return o.stepsPerFrame > 0 && o.frames > 0 && o.fps > 0 && o.res >= 2 && o.iterations > 0;
}

double cpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

// Largest |x_a − x_b| / rest length over the links (structural and the one diagonal per quad
// that CreatePatch adds, i.e. the triangles' edges); +inf when a position is not finite.
double maxLinkStretch(const btSoftBody& sb) {
    double worst = 0.0;
    for (int i = 0; i < sb.m_links.size(); ++i) {
        const btSoftBody::Link& l = sb.m_links[i];
        const double len = (l.m_n[0]->m_x - l.m_n[1]->m_x).length();
        if (!std::isfinite(len)) return INFINITY;
        if (l.m_rl > 0) worst = std::max(worst, len / l.m_rl);
    }
    return worst;
}

bool writeObj(const btSoftBody& sb, const std::string& dir, int frame) {
    char name[64];
    std::snprintf(name, sizeof name, "/flag.%04d.obj", frame);
    FILE* f = std::fopen((dir + name).c_str(), "w");
    if (!f) return false;
    for (int i = 0; i < sb.m_nodes.size(); ++i) {
        const btVector3& x = sb.m_nodes[i].m_x;
        std::fprintf(f, "v %.9g %.9g %.9g\n", double(x.x()), double(x.y()), double(x.z()));
    }
    for (int i = 0; i < sb.m_faces.size(); ++i) {
        const btSoftBody::Face& t = sb.m_faces[i];
        std::fprintf(f, "f %d %d %d\n", int(t.m_n[0] - &sb.m_nodes[0]) + 1,
                     int(t.m_n[1] - &sb.m_nodes[0]) + 1, int(t.m_n[2] - &sb.m_nodes[0]) + 1);
    }
    return std::fclose(f) == 0;
}

} // namespace

int main(int argc, char** argv) {
    Options o;
    if (!parse(argc, argv, o)) {
        std::fprintf(stderr, "usage: gale_bench_bullet_flag [--wind U] [--angle DEG] "
                             "[--steps-per-frame N] [--frames F] [--fps R] [--res N] "
                             "[--iterations P] [--lift K] [--drag K] [--obj DIR]\n");
        return 2;
    }
    const double cpu0 = cpuSeconds();
    const auto wall0 = std::chrono::steady_clock::now();

    // A soft-rigid world with no rigid bodies: the soft body's own step only.
    btSoftBodyRigidBodyCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    const btVector3 gravity(0, -9.81, 0);
    world.setGravity(gravity);
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    info.m_gravity = gravity;
    info.air_density = 1.2; // kg/m³, as the gale runs of the same benchmark (--set)
    info.water_density = 0;
    info.m_broadphase = &broadphase;
    info.m_dispatcher = &dispatcher;
    info.m_sparsesdf.Initialize();

    // gale's grid = { size = [1, 1], res = [N, N], origin = [0, 1, 0], axes = "xy" }: N × N
    // vertices, two triangles per quad (CreatePatch's gendiags).
    std::unique_ptr<btSoftBody> sb(btSoftBodyHelpers::CreatePatch(
        info, btVector3(0, 1, 0), btVector3(1, 1, 0), btVector3(0, 2, 0), btVector3(1, 2, 0), o.res,
        o.res, 0, true));
    sb->m_materials[0]->m_kLST = 1.0; // as stiff as Bullet's links go (gale: 2000 N/m)
    sb->m_materials[0]->m_kAST = 1.0;
    sb->m_cfg.piterations = o.iterations;
    sb->m_cfg.kDP = 0.0;
    sb->m_cfg.collisions = 0; // nothing to collide with; no self-collision either (as gale)
    sb->m_cfg.aeromodel = btSoftBody::eAeroModel::F_TwoSidedLiftDrag;
    sb->m_cfg.kLF = o.lift;
    sb->m_cfg.kDG = o.drag;
    sb->setTotalMass(0.005, true); // 0.005 kg/m² × 1 m², lumped by face area as gale's
    int pinned = 0;
    for (int i = 0; i < sb->m_nodes.size(); ++i)
        if (std::fabs(sb->m_nodes[i].m_x.x()) < 0.01) sb->setMass(i, 0), ++pinned;
    const double rad = o.angle * M_PI / 180.0;
    sb->setWindVelocity(btVector3(o.wind * std::cos(rad), 0, o.wind * std::sin(rad)));
    world.addSoftBody(sb.get());

    const double h = 1.0 / (o.fps * o.stepsPerFrame);
    bool written = o.objDir.empty() || writeObj(*sb, o.objDir, 1);
    const double setupCpu = cpuSeconds() - cpu0;
    double worst = maxLinkStretch(*sb);
    int firstUnbounded = 0;
    double tipMean = 0.0; // mean height of the free corner (x = 1, y = 2 at rest) over the frames
    const int tip = o.res * o.res - 1;
    const double loopCpu0 = cpuSeconds();
    const auto loop0 = std::chrono::steady_clock::now();
    int framesRun = 0;
    for (int f = 0; f < o.frames; ++f) {
        for (int s = 0; s < o.stepsPerFrame; ++s) world.stepSimulation(btScalar(h), 0, btScalar(h));
        ++framesRun;
        const double stretch = maxLinkStretch(*sb);
        worst = std::max(worst, stretch);
        tipMean += sb->m_nodes[tip].m_x.y() / o.frames;
        written = written && (o.objDir.empty() || writeObj(*sb, o.objDir, f + 2));
        if (!(stretch < 3.0) && firstUnbounded == 0) firstUnbounded = f + 2;
        if (!std::isfinite(stretch)) break; // nothing left to measure
    }
    const double loopWall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - loop0).count();
    const double loopCpu = cpuSeconds() - loopCpu0;
    const double processWall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    world.removeSoftBody(sb.get());
    if (!written) {
        std::fprintf(stderr, "gale_bench_bullet_flag: cannot write the frames to %s\n",
                     o.objDir.c_str());
        return 3;
    }
    std::printf(
        "{\"wind\": %g, \"angle\": %g, \"steps_per_frame\": %d, \"step\": %.9g, "
        "\"frames\": %d, \"frames_run\": %d, \"vertices\": %d, \"pinned\": %d, "
        "\"links\": %d, \"faces\": %d, \"bounded\": %s, \"first_unbounded_frame\": %d, "
        "\"max_stretch\": %.6g, \"tip_mean_y\": %.6g, \"ms_per_frame\": %.6g, "
        "\"cpu_ms_per_frame\": %.6g, \"setup_cpu_seconds\": %.6g, "
        "\"process_seconds\": %.6g, \"lift\": %g, \"drag\": %g, \"single_precision\": %s}\n",
        o.wind, o.angle, o.stepsPerFrame, h, o.frames, framesRun, sb->m_nodes.size(), pinned,
        sb->m_links.size(), sb->m_faces.size(), firstUnbounded == 0 ? "true" : "false",
        firstUnbounded, std::isfinite(worst) ? worst : -1.0, firstUnbounded == 0 ? tipMean : 0.0,
        1000 * loopWall / framesRun, 1000 * loopCpu / framesRun, setupCpu, processWall, o.lift,
        o.drag, sizeof(btScalar) == 4 ? "true" : "false");
    return 0;
}
