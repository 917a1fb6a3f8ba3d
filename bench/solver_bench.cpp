// gale_bench_solver: speed against error for the implicit cloth solver, next to an explicit
// symplectic-Euler baseline measured in the same run; cost per vertex per step and CG
// iterations for 32², 64², 128² cloth; aero.md's edge-on stability matrix; 2 threads against 1.
//   gale_bench_solver [--quick] [--out DIR] [--only plate|flag|scaling|stability|threads]
//   [--size N] [--solver NAME] [--threads T]  (DIR gets CSV tables and SVG plots; --only runs
//   one section; --size N and --solver NAME keep only those rows of the scaling table, --size N
//   and --threads T only the multicolour T-thread run of the threads table, e.g. to profile one)
#include "solver/linalg/bsr_kernels.h"
#include "solver/bodies/cloth.h"
#include "solver/linalg/linear.h"
#include "solver/linalg/multigrid.h"
#include "solver/linalg/types.h"
#include "solver/world/world.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

using namespace gale::solver;
using gale::fields::Param;

namespace {

using Clock = std::chrono::steady_clock;
const double kRho = 1.225;

class Wind : public gale::fields::Field {
public:
    using Fn = std::function<Vec3(const Vec3&, double)>;
    explicit Wind(Fn fn) : mFn(std::move(fn)) {}
    // Points in parallel chunks on the caller's arena, as the library's fields sample
    // (per point, so the same values on any number of threads).
    gale::fields::SampleStatus sample(const double* p, size_t n, const gale::fields::SampleTime& when,
                                      double* out) const override {
        parallelChunks(n, 1024, [&](size_t i0, size_t i1) {
            for (size_t i = i0; i < i1; ++i) {
                const Vec3 v = mFn(Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), when.time);
                out[3 * i] = v.x(), out[3 * i + 1] = v.y(), out[3 * i + 2] = v.z();
            }
        });
        return {};
    }
    std::string describe() const override { return "bench wind"; }

private:
    Fn mFn;
};

// A gusty, swirling wind along +x (smooth in space and time).
gale::fields::FieldPtr gusty(double U) {
    return std::make_shared<Wind>([U](const Vec3& x, double t) {
        return Vec3(U * (1.0 + 0.3 * std::sin(3.0 * t + 2.0 * x.y())), 0.2 * U * std::cos(5.0 * t + 3.0 * x.x()),
                    0.25 * U * std::sin(7.0 * t + x.x() + x.y()));
    });
}

struct Integrator {
    const char* name;
    bool explicitEuler;
    double tol;
    Preconditioner pre = Preconditioner::Multigrid; // of PCG (the default: multigrid)
};

struct FlagSpec {
    int n = 32;
    double size = 1.0, sigma = 0.1, stretch = 2000.0, wind = 10.0;
    double damping = 0.002; // Rayleigh β (s)
    bool gustyWind = true;
    AeroModel model = AeroModel::Frozen;
    AeroJacobian jacobian = AeroJacobian::Bounded; // the default
};

std::unique_ptr<World> makeFlag(const FlagSpec& f, double fps, int substeps, bool explicitEuler,
                                double tol, int maxHalvings = 0,
                                LinearSolverKind solver = LinearSolverKind::Pcg, int threads = 1,
                                bool raw = false) {
    WorldSettings ws;
    if (raw) ws.retryNewtonIterations = 0;
    ws.threads = threads;
    ws.fps = fps;
    ws.substeps = substeps;
    ws.maxHalvings = maxHalvings;
    auto w = std::make_unique<World>(ws);
    w->setWind(f.gustyWind ? gusty(f.wind)
                           : std::make_shared<Wind>([U = f.wind](const Vec3&, double) { return Vec3(U, 0, 0); }));
    ClothMaterial m;
    m.density = f.sigma;
    m.stretch = Param(f.stretch);
    m.shear = Param(f.stretch / 10);
    m.bend = Param(1e-4);
    m.damping = Param(f.damping);
    m.aeroModel = f.model;
    auto c = std::make_unique<Cloth>("flag", makeGrid(f.size, f.size, f.n, f.n, Vec3(0, 1, 0)), m);
    c->options().explicitEuler = explicitEuler;
    c->options().cgTolerance = tol;
    c->options().cgMaxIterations = 20000;
    c->options().aeroJacobian = f.jacobian;
    c->options().linearSolver = solver;
    if (raw) c->options().rotationProjection = RotationProjection::Off;
    PinSet pins;
    for (int j = 0; j < f.n; ++j) pins.vertices.push_back(j * f.n);
    c->addPins(pins);
    w->addBody(std::move(c));
    return w;
}

struct RunResult {
    bool blewUp = false;
    double seconds = 0.0;
    double cpuSeconds = 0.0; // process CPU time (the machine may be shared)
    long iterations = 0;
    long substeps = 0;
    long recovered = 0; // substeps in trouble at the smallest step, recovered by Body::recover
    VecX x;
};

double cpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Runs `frames` frames; counts wall and CPU time of all of them.
RunResult runFrames(World& w, int frames) {
    RunResult r;
    for (int f = 1; f <= frames; ++f) {
        const double c0 = cpuSeconds();
        const FrameStats fs = w.advanceFrame(f);
        r.cpuSeconds += cpuSeconds() - c0;
        r.seconds += fs.wallSeconds;
        r.iterations += fs.bodies[0].iterations;
        r.substeps += fs.bodies[0].substeps;
        r.recovered += fs.bodies[0].recovered;
        const VecX& x = w.bodies()[0]->positions();
        if (fs.failed || !x.allFinite() || x.cwiseAbs().maxCoeff() > 100.0) {
            r.blewUp = true;
            break;
        }
    }
    r.x = w.bodies()[0]->positions();
    return r;
}

std::string tolText(double t) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", t);
    return buf;
}

double rms(const VecX& a, const VecX& b) { return std::sqrt((a - b).squaredNorm() / (a.size() / 3)); }

// ---- a tiny SVG log-log plot ---------------------------------------------------------------

struct Series {
    std::string name;
    std::vector<double> x, y;
};

void writePlot(const std::string& path, const std::string& title, const std::string& xlabel, const std::string& ylabel,
               const std::vector<Series>& series) {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const Series& s : series)
        for (size_t i = 0; i < s.x.size(); ++i) {
            if (!(s.x[i] > 0) || !(s.y[i] > 0)) continue;
            x0 = std::min(x0, std::log10(s.x[i])), x1 = std::max(x1, std::log10(s.x[i]));
            y0 = std::min(y0, std::log10(s.y[i])), y1 = std::max(y1, std::log10(s.y[i]));
        }
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) y1 = y0 + 1;
    x0 = std::floor(x0), x1 = std::ceil(x1), y0 = std::floor(y0), y1 = std::ceil(y1);
    const double W = 640, H = 420, L = 70, R = 170, T = 40, B = 50;
    auto px = [&](double v) { return L + (std::log10(v) - x0) / (x1 - x0) * (W - L - R); };
    auto py = [&](double v) { return H - B - (std::log10(v) - y0) / (y1 - y0) * (H - T - B); };
    std::ofstream o(path);
    o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
    o << "<text x='" << W / 2 << "' y='20' text-anchor='middle' font-size='14'>" << title << "</text>\n";
    for (double e = x0; e <= x1; ++e)
        o << "<line x1='" << px(std::pow(10, e)) << "' y1='" << T << "' x2='" << px(std::pow(10, e)) << "' y2='" << H - B
          << "' stroke='#ddd'/><text x='" << px(std::pow(10, e)) << "' y='" << H - B + 15
          << "' text-anchor='middle'>1e" << e << "</text>\n";
    for (double e = y0; e <= y1; ++e)
        o << "<line x1='" << L << "' y1='" << py(std::pow(10, e)) << "' x2='" << W - R << "' y2='" << py(std::pow(10, e))
          << "' stroke='#ddd'/><text x='" << L - 5 << "' y='" << py(std::pow(10, e)) + 4
          << "' text-anchor='end'>1e" << e << "</text>\n";
    o << "<text x='" << (L + W - R) / 2 << "' y='" << H - 10 << "' text-anchor='middle'>" << xlabel << "</text>\n";
    o << "<text x='15' y='" << (T + H - B) / 2 << "' transform='rotate(-90 15 " << (T + H - B) / 2
      << ")' text-anchor='middle'>" << ylabel << "</text>\n";
    const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};
    for (size_t k = 0; k < series.size(); ++k) {
        const Series& s = series[k];
        std::string pts;
        for (size_t i = 0; i < s.x.size(); ++i)
            if (s.x[i] > 0 && s.y[i] > 0) pts += std::to_string(px(s.x[i])) + "," + std::to_string(py(s.y[i])) + " ";
        o << "<polyline fill='none' stroke='" << colors[k % 6] << "' stroke-width='2' points='" << pts << "'/>\n";
        for (size_t i = 0; i < s.x.size(); ++i)
            if (s.x[i] > 0 && s.y[i] > 0)
                o << "<circle cx='" << px(s.x[i]) << "' cy='" << py(s.y[i]) << "' r='3' fill='" << colors[k % 6] << "'/>\n";
        o << "<text x='" << W - R + 10 << "' y='" << T + 15 + 16 * k << "' fill='" << colors[k % 6] << "'>" << s.name
          << "</text>\n";
    }
    o << "</svg>\n";
}

// ---- 1. analytic plate ------------------------------------------------------------------------

void plateBench(bool quick, const std::string& out) {
    // aero.md reference 1: free gossamer plate, broadside, U = 10 m/s, σ = 0.005 kg/m², C_D = 1.2:
    // k = ρ C_D / (2σ) = 147 1/m, the linearised drag rate ρ C_D U / σ = 2940 1/s (explicit needs
    // h < 6.8e-4 s). Error of the displacement at T = 0.25 s against x(t) = Ut − ln(1 + kUt)/k.
    const double U = 10.0, sigma = 0.005, cd = 1.2, T = 0.25;
    const double k = kRho * cd / (2 * sigma);
    const double exact = U * T - std::log(1 + k * U * T) / k;
    std::printf("\n## Analytic plate (aero.md case 1): gossamer plate, U = %g m/s, sigma = %g kg/m^2, T = %g s\n", U,
                sigma, T);
    std::printf("exact displacement %.6f m; 8x8 mesh\n\n", exact);
    std::printf("| integrator | CG tol | substeps | h (s) | error (m) | wall (ms) | CG its/step |\n|---|---|---|---|---|---|---|\n");
    std::vector<Series> series;
    std::ofstream csv(out.empty() ? "/dev/null" : out + "/plate.csv");
    csv << "integrator,tol,substeps,h,error,wall_ms,its_per_step\n";
    const std::vector<Integrator> ints = {{"implicit", false, 1e-2}, {"implicit", false, 1e-6}, {"explicit", true, 0}};
    for (const Integrator& in : ints) {
        Series s;
        s.name = std::string(in.name) + (in.explicitEuler ? " (sympl. Euler)" : " tol " + tolText(in.tol));
        for (int n : {16, 64, 256, 1024, 4096, 16384}) {
            if (quick && n > 1024) continue;
            WorldSettings ws;
            ws.gravity = Vec3::Zero();
            ws.maxHalvings = 0;
            World w(ws);
            w.setWind(std::make_shared<Wind>([U](const Vec3&, double) { return Vec3(0, 0, U); }));
            ClothMaterial m;
            m.density = sigma;
            m.drag.value = Param(cd);
            m.lift.value = Param(0.3);
            m.damping = Param(0.0);
            auto c = std::make_unique<Cloth>("plate", makeGrid(1, 1, 8, 8), m);
            c->options().explicitEuler = in.explicitEuler;
            c->options().cgTolerance = in.tol > 0 ? in.tol : 1e-3;
            w.addBody(std::move(c));
            const FrameStats fs = w.advance(0.0, T, n);
            Vec3 cen = Vec3::Zero();
            const VecX& x = w.bodies()[0]->positions();
            for (size_t i = 0; i < w.bodies()[0]->vertexCount(); ++i) cen += vec3At(x.data(), i);
            cen /= static_cast<double>(w.bodies()[0]->vertexCount());
            const bool blew = fs.failed || !x.allFinite() || std::abs(cen.z()) > 100;
            const double err = std::abs(cen.z() - exact);
            std::printf("| %s | %s | %d | %.3g | %s | %.2f | %.1f |\n", in.name,
                        in.explicitEuler ? "-" : tolText(in.tol).c_str(), n, T / n,
                        blew ? "blew up" : std::to_string(err).c_str(), fs.wallSeconds * 1e3,
                        double(fs.bodies[0].iterations) / n);
            csv << in.name << "," << in.tol << "," << n << "," << T / n << "," << (blew ? -1 : err) << ","
                << fs.wallSeconds * 1e3 << "," << double(fs.bodies[0].iterations) / n << "\n";
            if (!blew) {
                s.x.push_back(fs.wallSeconds * 1e3);
                s.y.push_back(err);
            }
        }
        series.push_back(s);
    }
    if (!out.empty())
        writePlot(out + "/plate_error_vs_time.svg", "Gossamer plate in 10 m/s wind: error vs wall time", "wall time (ms)",
                  "displacement error at 0.25 s (m)", series);
}

// ---- 2. flag against a fine-step reference ----------------------------------------------------

void flagBench(bool quick, const std::string& out) {
    std::ofstream csv(out.empty() ? "/dev/null" : out + "/flag.csv");
    csv << "model,integrator,tol,h,rms_error,wall_ms,its_per_step\n";
    for (AeroModel model : {AeroModel::SmoothLift, AeroModel::Frozen}) {
        const char* modelName = model == AeroModel::Frozen ? "frozen" : "smooth-lift";
        FlagSpec f;
        f.n = 24;
        f.sigma = 0.1;
        f.wind = 10.0;
        f.model = model;
        const double T = 0.25;
        const int frames = 6; // 24 fps
        std::printf("\n## Flag vs a fine-step reference (%s lift): 24x24, 1 m, sigma = %g kg/m^2, stretch %g N/m, "
                    "Rayleigh damping 0.002 s, gusty %g m/s, T = %g s\n",
                    modelName, f.sigma, f.stretch, f.wind, T);
        // Reference: h = 1/(24*4*64) with a tight tolerance.
        auto ref = makeFlag(f, 24.0, 4 * 64, false, 1e-9);
        const RunResult r0 = runFrames(*ref, frames);
        std::printf("reference: h = 1/%d s, CG tol 1e-9, %.2f s wall\n\n", 24 * 4 * 64, r0.seconds);
        std::printf("| integrator | CG tol | h (s) | RMS error (m) | wall (ms) | CG its/step |\n|---|---|---|---|---|---|\n");
        std::vector<Series> series;
        const Preconditioner J = Preconditioner::BlockJacobi;
        std::vector<Integrator> ints = {{"implicit Jacobi", false, 1e-1, J}, {"implicit Jacobi", false, 1e-3, J},
                                        {"implicit Jacobi", false, 1e-6, J}, {"implicit MG", false, 1e-1},
                                        {"implicit MG", false, 1e-3},        {"implicit MG", false, 1e-6},
                                        {"explicit", true, 0}};
        if (model == AeroModel::Frozen) ints = {{"implicit", false, 1e-3}, {"explicit", true, 0}};
        for (const Integrator& in : ints) {
            Series s;
            s.name = std::string(in.name) + (in.explicitEuler ? " (sympl. Euler)" : " tol " + tolText(in.tol));
            // Explicit: the membrane with Rayleigh damping needs h < 2/(β ω²) ≈ 1e-5 s here.
            for (int sub : {1, 2, 4, 8, 16, 64, 256, 1024, 4096}) {
                if (quick && sub > 16) continue;
                if (!in.explicitEuler && sub > 16) continue;
                auto w = makeFlag(f, 24.0, sub, in.explicitEuler, in.tol > 0 ? in.tol : 1e-3);
                w->bodies()[0]->options().preconditioner = in.pre;
                const RunResult r = runFrames(*w, frames);
                const double err = r.blewUp ? -1 : rms(r.x, r0.x);
                std::printf("| %s | %s | 1/%d | %s | %.1f | %.1f |\n", in.name,
                            in.explicitEuler ? "-" : tolText(in.tol).c_str(), 24 * sub,
                            r.blewUp ? "blew up" : std::to_string(err).c_str(), r.seconds * 1e3,
                            r.substeps ? double(r.iterations) / r.substeps : 0.0);
                csv << modelName << "," << in.name << "," << in.tol << "," << 1.0 / (24 * sub) << "," << err << ","
                    << r.seconds * 1e3 << "," << (r.substeps ? double(r.iterations) / r.substeps : 0.0) << "\n";
                if (!r.blewUp) {
                    s.x.push_back(r.seconds * 1e3);
                    s.y.push_back(err);
                }
            }
            series.push_back(s);
        }
        if (!out.empty())
            writePlot(out + "/flag_" + modelName + "_error_vs_time.svg",
                      std::string("24x24 flag (") + modelName + " lift), 0.25 s: RMS error vs wall time",
                      "wall time (ms)", "RMS position error vs h/64 reference (m)", series);
    }
}

// ---- 3. cost per vertex per step --------------------------------------------------------------

struct SolverChoice {
    const char* name;
    LinearSolverKind kind;
    Preconditioner pre;
};
const SolverChoice kSolvers[] = {{"pcg, block Jacobi", LinearSolverKind::Pcg, Preconditioner::BlockJacobi},
                                 {"pcg, multigrid", LinearSolverKind::Pcg, Preconditioner::Multigrid},
                                 {"direct", LinearSolverKind::Direct, Preconditioner::BlockJacobi}};

void setSolver(World& w, const SolverChoice& s) {
    Body& b = *w.bodies()[0];
    b.options().linearSolver = s.kind;
    b.options().preconditioner = s.pre;
}

void scalingBench(bool quick, int onlySize, const std::string& onlySolver) {
    std::printf("\n## Cost per vertex per step, one thread: flag 1 m, sigma 0.1 kg/m^2, stretch 2000 N/m, gusty 12 m/s,"
                " h = 1/240 s, CG tol 1e-3, block-Jacobi and multigrid PCG and the sparse LDL^T in the same run"
                " (CPU: process CPU time, robust on a shared machine)\n\n");
    std::printf("| cloth | solver | us/vertex/step (CPU) | us/vertex/step (wall) | ms/step (CPU) | CG its/step |\n"
                "|---|---|---|---|---|---|\n");
    for (int n : {32, 64, 128})
        for (const SolverChoice& s : kSolvers) {
            if (onlySize > 0 && n != onlySize) continue;
            if (!onlySolver.empty() && std::string(s.name).find(onlySolver) == std::string::npos) continue;
            if (quick && n == 128) continue;
            if (n == 128 && s.kind == LinearSolverKind::Direct) continue;
            FlagSpec f;
            f.n = n;
            f.wind = 12.0;
            auto w = makeFlag(f, 240.0, 1, false, 1e-3, 0);
            setSolver(*w, s);
            runFrames(*w, n == 128 ? 6 : 24); // warm-up: the flag starts moving
            const RunResult r = runFrames(*w, n == 128 ? 12 : 48);
            const double per = r.seconds / std::max<long>(r.substeps, 1);
            const double cpu = r.cpuSeconds / std::max<long>(r.substeps, 1);
            std::printf("| %dx%d | %s | %.2f | %.2f | %.2f | %.1f |\n", n, n, s.name, cpu * 1e6 / (n * n),
                        per * 1e6 / (n * n), cpu * 1e3, double(r.iterations) / std::max<long>(r.substeps, 1));
        }
    // The knobs of the multigrid solve at 64x64: the vector kernels (AVX2 + FMA against the
    // portable ones) and the precision of CG's products (single from kSinglePrecisionTolerance
    // up, double just below it), with the position difference after the run.
    if ((onlySize <= 0 || onlySize == 64) && (onlySolver.empty() || onlySolver == "multigrid")) {
        struct Knob {
            const char* name;
            bool wide;
            double tol;
        };
        const bool wideAvailable = wideKernels();
        const Knob knobs[] = {{"AVX2 + FMA kernels, single-precision products", true, kSinglePrecisionTolerance},
                              {"AVX2 + FMA kernels, double-precision products", true, 0.99 * kSinglePrecisionTolerance},
                              {"portable kernels, single-precision products", false, kSinglePrecisionTolerance}};
        std::printf("\n64x64 multigrid knobs (CG tol %g; RMS position difference against the first row after 72 steps):\n\n"
                    "| kernels, CG products | us/vertex/step (CPU) | CG its/step | RMS difference (m) |\n|---|---|---|---|\n",
                    kSinglePrecisionTolerance);
        VecX first;
        for (const Knob& k : knobs) {
            if (k.wide && !wideAvailable) continue;
            setWideKernels(k.wide);
            FlagSpec f;
            f.n = 64;
            f.wind = 12.0;
            auto w = makeFlag(f, 240.0, 1, false, k.tol, 0);
            setSolver(*w, kSolvers[1]);
            runFrames(*w, 24);
            const RunResult r = runFrames(*w, 48);
            if (first.size() == 0) first = r.x;
            std::printf("| %s | %.2f | %.1f | %.2e |\n", k.name, r.cpuSeconds / r.substeps * 1e6 / (64 * 64),
                        double(r.iterations) / r.substeps, rms(r.x, first));
        }
        setWideKernels(wideAvailable);
    }
    // The real-time check: 32x32 at 24 fps with 4 substeps (h = 1/96 s).
    if ((onlySize > 0 && onlySize != 32) || !onlySolver.empty()) return;
    std::printf("\n");
    for (int k = 0; k < 2; ++k) {
        FlagSpec f;
        f.n = 32;
        f.wind = 12.0;
        auto w = makeFlag(f, 24.0, 4, false, 1e-3, 6);
        setSolver(*w, kSolvers[k]);
        runFrames(*w, 6);
        const RunResult r = runFrames(*w, 48);
        std::printf("32x32 at 24 fps, 4 substeps (robust stepping on), %s: %.2f ms CPU (%.2f ms wall) per frame = "
                    "%.2fx real time by CPU (%.1f CG its/substep)\n",
                    kSolvers[k].name, r.cpuSeconds / 48 * 1e3, r.seconds / 48 * 1e3, (1.0 / 24) / (r.cpuSeconds / 48),
                    double(r.iterations) / r.substeps);
    }
}

// ---- 5. two threads against one (issue 14) ---------------------------------------------------

// The same flag (24 fps, 4 substeps, multigrid PCG at tolerance 1e-3) in three configurations
// measured in the same run: the lexicographic (natural-order, sequential) Gauss–Seidel smoother
// on 1 thread — the smoother before issue 14 — and the multicolour smoother on 1 and 2
// threads. Wall time per substep (best of the repeats), CG iterations per substep, the ratios,
// and whether the 1- and 2-thread multicolour runs ended on the same bits (they must).
void threadsBench(bool quick, int onlySize, int onlyThreads) {
    const int repeats = quick ? 1 : 5;
    std::printf(
        "\n## Two threads against one (issue 14): flag 1 m, sigma 0.1 kg/m^2, stretch 2000 N/m, "
        "gusty 12 m/s, "
        "24 fps x 4 substeps, multigrid PCG, CG tol 1e-3; wall ms per substep, best of %d\n\n",
        repeats);
    std::printf("| cloth | frames | lexicographic GS, 1 thread: ms (its) | multicolour, 1 thread: "
                "ms (its) | "
                "multicolour, 2 threads: ms | 1-thread cost of multicolour | 2-thread speed-up | "
                "same bits |\n"
                "|---|---|---|---|---|---|---|---|\n");
    const BlockMultigrid::Settings initial = BlockMultigrid::defaults();
    struct Config {
        bool multicolour;
        int threads;
    };
    const Config configs[] = {{false, 1}, {true, 1}, {true, 2}};
    for (int n : {32, 64, 128}) {
        if (onlySize > 0 && n != onlySize) continue;
        if (quick && n == 128) continue;
        const int frames = n == 128 ? 8 : 24;
        double best[3] = {1e300, 1e300, 1e300}, its[3] = {0, 0, 0};
        VecX x[3];
        for (int rep = 0; rep < repeats; ++rep)
            for (int k = 0; k < 3; ++k) {
                if (onlyThreads > 0 &&
                    (!configs[k].multicolour || configs[k].threads != onlyThreads))
                    continue;
                BlockMultigrid::defaults().multicolour = configs[k].multicolour;
                FlagSpec f;
                f.n = n;
                f.wind = 12.0;
                auto w =
                    makeFlag(f, 24.0, 4, false, 1e-3, 0, LinearSolverKind::Pcg, configs[k].threads);
                w->bodies()[0]->options().preconditioner = Preconditioner::Multigrid;
                const RunResult r = runFrames(*w, frames);
                best[k] = std::min(best[k], r.seconds / std::max<long>(r.substeps, 1));
                its[k] = double(r.iterations) / std::max<long>(r.substeps, 1);
                x[k] = r.x;
            }
        BlockMultigrid::defaults() = initial;
        if (onlyThreads > 0) { // one configuration, for profiling
            std::printf("| %dx%d | %d | multicolour, %d thread(s): %.2f ms/step (%.1f its) |\n", n,
                        n, frames, onlyThreads, best[onlyThreads] * 1e3, its[onlyThreads]);
            continue;
        }
        const bool same = x[1].size() == x[2].size() &&
                          std::memcmp(x[1].data(), x[2].data(), sizeof(double) * x[1].size()) == 0;
        std::printf("| %dx%d | %d | %.2f (%.1f) | %.2f (%.1f) | %.2f | %.2fx | **%.2fx** (%.2fx vs "
                    "lexicographic) | %s |\n",
                    n, n, frames, best[0] * 1e3, its[0], best[1] * 1e3, its[1], best[2] * 1e3,
                    best[1] / best[0], best[1] / best[2], best[0] / best[2], same ? "yes" : "NO");
    }
}

// ---- 4. edge-on stability (aero.md) -----------------------------------------------------------

void stabilityBench(bool quick) {
    std::printf("\n## Edge-on stability (aero.md): 24x24 gossamer flag (0.005 kg/m^2, 2000 N/m), "
                "uniform edge-on wind, 0.5 s, raw integrator (no substep halving, no Newton retry, "
                "no rotation projection). 'ok' = finite and within 5 m of the pole; 'recovered N' "
                "= N substeps in trouble (over-stretch, a velocity jump) that the last resort "
                "(Body::recover: strain limiting) brought back\n\n");
    struct Variant {
        const char* name;
        AeroModel model;
        AeroJacobian jac;
        bool explicitEuler;
    };
    const Variant variants[] = {
        {"frozen, Jacobian left out", AeroModel::Frozen, AeroJacobian::None, false},
        {"frozen, paper substitution", AeroModel::Frozen, AeroJacobian::Paper, false},
        {"frozen, projected", AeroModel::Frozen, AeroJacobian::Projected, false},
        {"frozen, bounded (default)", AeroModel::Frozen, AeroJacobian::Bounded, false},
        {"smooth-lift, paper substitution", AeroModel::SmoothLift, AeroJacobian::Paper, false},
        {"explicit symplectic Euler", AeroModel::Frozen, AeroJacobian::Projected, true},
    };
    for (double U : {20.0, 40.0}) {
        std::printf("| %g m/s | 1/24 | 1/48 | 1/96 | 1/192 | 1/384 |\n|---|---|---|---|---|---|\n", U);
        for (const Variant& v : variants) {
            std::printf("| %s |", v.name);
            for (int fps : {24, 48, 96, 192, 384}) {
                if (quick && fps > 96) {
                    std::printf(" - |");
                    continue;
                }
                FlagSpec f;
                f.n = 24;
                f.sigma = 0.005;
                f.wind = U;
                f.gustyWind = false;
                f.model = v.model;
                f.jacobian = v.jac;
                // The raw integrator: no halving, no in-substep Newton retry and no rotation
                // projection, which would each hide what the linearisation does.
                auto w =
                    makeFlag(f, fps, 1, v.explicitEuler, 1e-3, 0, LinearSolverKind::Pcg, 1, true);
                const RunResult r = runFrames(*w, fps / 2);
                double far = 0.0;
                for (long i = 0; i < r.x.size() / 3; ++i)
                    far = std::max(far, (vec3At(r.x.data(), i) - Vec3(0, 1.5, 0)).norm());
                if (r.blewUp || !(far < 5.0))
                    std::printf(" blew up |");
                else if (r.recovered > 0)
                    std::printf(" recovered %ld of %d |", r.recovered, fps / 2);
                else
                    std::printf(" ok |");
            }
            std::printf("\n");
        }
        std::printf("\n");
    }
}

} // namespace

int main(int argc, char** argv) {
    bool quick = false;
    std::string out, only;
    int onlySize = 0, onlyThreads = 0;
    std::string onlySolver;
    const char* usage = "usage: gale_bench_solver [--quick] [--out DIR] [--only "
                        "plate|flag|scaling|stability|threads] [--size 32|64|128]\n"
                        "       [--solver Jacobi|multigrid|direct] [--threads 1|2]\n";
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--quick")) quick = true;
        else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) out = argv[++i];
        else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
        else if (!std::strcmp(argv[i], "--size") && i + 1 < argc) onlySize = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--solver") && i + 1 < argc) onlySolver = argv[++i];
        else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
            onlyThreads = std::atoi(argv[++i]);
        else {
            std::fprintf(stderr, "%s", usage);
            return 2;
        }
    }
    std::printf("# gale_bench_solver%s\n", quick ? " (--quick)" : "");
    if (only.empty() || only == "plate") plateBench(quick, out);
    if (only.empty() || only == "flag") flagBench(quick, out);
    if (only.empty() || only == "scaling") scalingBench(quick, onlySize, onlySolver);
    if (only.empty() || only == "stability") stabilityBench(quick);
    if (only.empty() || only == "threads") threadsBench(quick, onlySize, onlyThreads);
    return 0;
}
