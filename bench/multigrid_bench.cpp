// gale_bench_multigrid: the cloth system's multigrid preconditioner at production resolution
// (issue 26) — CG iterations, set-up and solve time per vertex and bytes per vertex from 32² to
// 256² (grid, irregular and plate sheets) at h = 1/24 and 1/240 s, on 1 and 2 threads, for smoothed
// aggregation with translations, with rotations, and with rotations and the K-cycle (the scene's
// "smoothed-rotations") against the plain aggregation baseline measured in the same run
// (and hypre's BoomerAMG on the same matrices when built with it); speed against error.
//   gale_bench_multigrid [--quick] [--only scaling|error] [--size N]
#include "solver/bodies/elastic.h"
#include "solver/linalg/linear.h"
#include "solver/linalg/multigrid.h"
#include "solver/linalg/test_sheets.h"
#include "solver/linalg/types.h"
#include "solver/mesh/mesh.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#ifdef GALE_HAVE_HYPRE
#include <HYPRE.h>
#include <HYPRE_krylov.h>
#include <HYPRE_parcsr_ls.h>
#include <mpi.h>
#endif

using namespace gale::solver;
using gale::solver::testing::ClothSystem;
using gale::solver::testing::makeClothSystem;
using gale::solver::testing::SheetOptions;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Variant {
    const char* name;
    bool smoothed, rotations;
    int sweeps;
    bool kCycle = false;
};

struct Outcome {
    int iterations = 0;
    double setup = 0.0, solve = 0.0; // seconds, best of the repeats
    double residual = 0.0;
    size_t bytes = 0, peakBytes = 0; // held between solves; the most during the set-up
    int levels = 0;
    VecX dv;
};

// One linear solve (multigrid PCG from zero), best time of `repeats`; the set-up (refresh) is
// timed apart by a solve with a zero iteration cap, the solve as the rest.
Outcome runSolve(const ClothSystem& s, const Variant& v, double tol, int threads, int repeats) {
    Outcome o;
    tbb::task_arena arena(threads);
    arena.execute([&] {
        FilteredSolver solver;
        solver.setPreconditioner(Preconditioner::Multigrid);
        BlockMultigrid::Settings& st = solver.multigrid().settings();
        st.smoothed = v.smoothed;
        st.smoothedMinRows = 0; // the variant's hierarchy at every size
        st.rotations = v.rotations;
        st.sweeps = v.sweeps;
        st.kCycle = v.kCycle;
        solver.multigrid().setPositions(s.x.data(), s.A.size());
        o.setup = o.solve = 1e30;
        {
            // The hierarchy's pattern (aggregates, colours) is built at the first solve only:
            // build it here, untimed, so each repeat's set-up and full solve refresh the same.
            VecX dv = VecX::Zero(s.b.size());
            solver.solve(s.A, s.c, s.b, dv, LinearSolverKind::Pcg, tol, 0);
        }
        for (int r = 0; r < repeats; ++r) {
            VecX dv = VecX::Zero(s.b.size());
            auto t0 = Clock::now();
            solver.solve(s.A, s.c, s.b, dv, LinearSolverKind::Pcg, tol, 0);
            const double setup = since(t0);
            dv.setZero();
            t0 = Clock::now();
            const SolveStatus ss =
                solver.solve(s.A, s.c, s.b, dv, LinearSolverKind::Pcg, tol, 2000);
            const double total = since(t0);
            o.setup = std::min(o.setup, setup);
            o.solve = std::min(o.solve, std::max(0.0, total - setup));
            o.iterations = ss.iterations;
            o.residual = ss.residual;
            o.dv = dv;
        }
        o.bytes = solver.multigrid().bytes();
        o.peakBytes = std::max(o.bytes, solver.multigrid().peakBytes());
        o.levels = solver.multigrid().levelCount();
    });
    return o;
}

#ifdef GALE_HAVE_HYPRE
// hypre BoomerAMG (nodal systems AMG, 3 unknowns per node) as the PCG preconditioner on the
// same filtered matrix Â (assembled here in scalar CSR), the same rhs and tolerance.
Outcome runHypre(const ClothSystem& s, double tol) {
    Outcome o;
    // Â = S A S + I − S and rhs = S (b − A z) via the library's own LDLᵀ path would hide the
    // matrix; build it directly.
    const int n = s.A.size(), n3 = 3 * n;
    std::vector<Mat3> S(n);
    for (int i = 0; i < n; ++i) S[i] = s.c.filter(i);
    VecX z = Eigen::Map<const VecX>(s.c.z.data(), n3), Az(n3);
    s.A.multiply(z.data(), Az.data());
    VecX rhs = s.b - Az;
    for (int i = 0; i < n; ++i) rhs.segment<3>(3 * i) = S[i] * rhs.segment<3>(3 * i);
    const auto& start = s.A.blockRowStart();
    const auto& cols = s.A.blockCols();
    auto t0 = Clock::now();
    HYPRE_IJMatrix ij;
    HYPRE_IJMatrixCreate(MPI_COMM_WORLD, 0, n3 - 1, 0, n3 - 1, &ij);
    HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR);
    HYPRE_IJMatrixInitialize(ij);
    std::vector<HYPRE_BigInt> cidx;
    std::vector<double> vals;
    for (int i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            cidx.clear();
            vals.clear();
            for (int k = start[i]; k < start[i + 1]; ++k) {
                const int j = cols[k];
                Mat3 B = S[i] * s.A.block(k) * S[j];
                if (i == j) B += Mat3::Identity() - S[i];
                for (int c = 0; c < 3; ++c) {
                    cidx.push_back(3 * j + c);
                    vals.push_back(B(a, c));
                }
            }
            HYPRE_Int ncols = static_cast<HYPRE_Int>(cidx.size());
            HYPRE_BigInt row = 3 * i + a;
            HYPRE_IJMatrixSetValues(ij, 1, &ncols, &row, cidx.data(), vals.data());
        }
    HYPRE_IJMatrixAssemble(ij);
    HYPRE_ParCSRMatrix A;
    HYPRE_IJMatrixGetObject(ij, reinterpret_cast<void**>(&A));
    auto makeVec = [&](const double* v, HYPRE_IJVector& iv) {
        HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, n3 - 1, &iv);
        HYPRE_IJVectorSetObjectType(iv, HYPRE_PARCSR);
        HYPRE_IJVectorInitialize(iv);
        std::vector<HYPRE_BigInt> idx(n3);
        for (int k = 0; k < n3; ++k) idx[k] = k;
        HYPRE_IJVectorSetValues(iv, n3, idx.data(), v);
        HYPRE_IJVectorAssemble(iv);
        HYPRE_ParVector p;
        HYPRE_IJVectorGetObject(iv, reinterpret_cast<void**>(&p));
        return p;
    };
    std::vector<double> zero(n3, 0.0);
    HYPRE_IJVector ib, ix;
    HYPRE_ParVector pb = makeVec(rhs.data(), ib), px = makeVec(zero.data(), ix);
    HYPRE_Solver pcg, amg;
    HYPRE_ParCSRPCGCreate(MPI_COMM_WORLD, &pcg);
    HYPRE_PCGSetTol(pcg, tol);
    HYPRE_PCGSetMaxIter(pcg, 2000);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_BoomerAMGCreate(&amg);
    HYPRE_BoomerAMGSetNumFunctions(amg, 3);
    HYPRE_BoomerAMGSetNodal(amg, 4);
    HYPRE_BoomerAMGSetCoarsenType(amg, 10); // HMIS
    HYPRE_BoomerAMGSetInterpType(amg, 6);   // extended+i
    HYPRE_BoomerAMGSetPMaxElmts(amg, 4);
    HYPRE_BoomerAMGSetAggNumLevels(amg, 1);
    HYPRE_BoomerAMGSetStrongThreshold(amg, 0.5);
    HYPRE_BoomerAMGSetRelaxType(amg, 6); // symmetric hybrid Gauss–Seidel
    HYPRE_BoomerAMGSetTol(amg, 0.0);
    HYPRE_BoomerAMGSetMaxIter(amg, 1);
    HYPRE_BoomerAMGSetPrintLevel(amg, 0);
    HYPRE_PCGSetPrecond(pcg, reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSolve),
                        reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSetup), amg);
    HYPRE_ParCSRPCGSetup(pcg, A, pb, px);
    o.setup = since(t0);
    t0 = Clock::now();
    HYPRE_ParCSRPCGSolve(pcg, A, pb, px);
    o.solve = since(t0);
    HYPRE_Int its;
    HYPRE_PCGGetNumIterations(pcg, &its);
    o.iterations = its;
    HYPRE_ParCSRPCGDestroy(pcg);
    HYPRE_BoomerAMGDestroy(amg);
    HYPRE_IJMatrixDestroy(ij);
    HYPRE_IJVectorDestroy(ib);
    HYPRE_IJVectorDestroy(ix);
    return o;
}
#endif

// The plate: the flat sheet with nothing across its springs (out of plane only the mass holds
// it) plus the cloth's own bending on its hinges (solver/bodies/elastic.h, Bergou et al. 2006:
// h² k_b (3 / (A0 + A1)) k kᵀ ⊗ I₃ per hinge, k the cotangent weights), 1e-5 N m as the
// wind-onset flag's. That is a slack cloth's system: out of plane a plate whose bending outgrows
// the mass as (1/dx)⁴ at a frame-size step (bench/README.md, "The cloth's own matrices").
ClothSystem makePlate(int n, double h, double bend) {
    SheetOptions o;
    o.flat = true;
    o.transverse = 0.0;
    ClothSystem s = makeClothSystem(n, h, o);
    std::vector<std::array<int, 3>> tris;
    for (size_t t = 0; t < s.triangles.size(); t += 3)
        tris.push_back({s.triangles[t], s.triangles[t + 1], s.triangles[t + 2]});
    const std::vector<HingeStencil> hinges = meshHinges(tris);
    // The pattern grows by the hinges' opposite corners.
    const int nv = s.A.size();
    std::vector<std::pair<int, int>> pairs;
    for (int i = 0; i < nv; ++i)
        for (int k = s.A.blockRowStart()[i]; k < s.A.blockRowStart()[i + 1]; ++k)
            if (s.A.blockCols()[k] > i) pairs.push_back({i, s.A.blockCols()[k]});
    for (const HingeStencil& hs : hinges) pairs.push_back({hs.v[2], hs.v[3]});
    BlockMatrix A;
    A.build(nv, pairs);
    for (int i = 0; i < nv; ++i)
        for (int k = s.A.blockRowStart()[i]; k < s.A.blockRowStart()[i + 1]; ++k)
            A.addBlock(A.slot(i, s.A.blockCols()[k]), s.A.block(k));
    for (const HingeStencil& hs : hinges) {
        Vec3 p[4];
        for (int q = 0; q < 4; ++q) p[q] = vec3At(s.x.data(), static_cast<size_t>(hs.v[q]));
        HingeRest rest;
        if (!makeHingeRest(p, rest)) continue;
        const double c = h * h * bend * rest.scale;
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                A.addBlock(A.slot(hs.v[a], hs.v[b]),
                           (c * rest.k[a] * rest.k[b]) * Mat3::Identity());
    }
    s.A = std::move(A);
    return s;
}

const Variant kPlain{"plain-translations", false, false, 1};
const Variant kSaTrans{"sa-translations", true, false, 1};
const Variant kSaRot{"sa-rotations", true, true, 1};
const Variant kSaRotK{"sa-rotations-k", true, true, 1, true}; // multigrid = "smoothed-rotations"

// ---- 1. iterations and cost against resolution ------------------------------------------------
void scalingBench(bool quick, int onlySize) {
    std::printf("== scaling: one filtered solve (pins + contact patch), tol 1e-3, zero start\n");
    std::printf("%-9s %-7s %5s %-19s %3s %5s %6s %9s %9s %9s %8s %8s %7s\n", "mesh", "h", "n",
                "preconditioner", "thr", "its", "levels", "setup_us/v", "solve_us/v", "total/base",
                "B/vertex", "peak_B/v", "maxdiff");
    const std::vector<int> sizes =
        quick ? std::vector<int>{32, 64} : std::vector<int>{32, 64, 128, 256};
    // The sheets: wavy edge springs on a grid or an irregular mesh, and the plate (makePlate).
    for (int sheet = 0; sheet < 3; ++sheet)
        for (double h : {1.0 / 24.0, 1.0 / 240.0})
            for (int n : sizes) {
                if (onlySize && n != onlySize) continue;
                const bool irregular = sheet == 1;
                const ClothSystem s =
                    sheet == 2 ? makePlate(n, h, 1e-5) : makeClothSystem(n, h, irregular, true);
                const double nv = static_cast<double>(s.A.size());
                const int repeats = n >= 256 ? 1 : 3;
                const Outcome base = runSolve(s, kPlain, 1e-3, 1, repeats);
                const double baseTotal = base.setup + base.solve;
                auto row = [&](const char* name, int threads, const Outcome& o, double diff) {
                    std::printf(
                        "%-9s 1/%-5.0f %5d %-19s %3d %5d %6d %9.3f %9.3f %9.2f %8.0f %8.0f %7.1e\n",
                        sheet == 2  ? "plate"
                        : irregular ? "irregular"
                                    : "grid",
                        1.0 / h, n, name, threads, o.iterations, o.levels, 1e6 * o.setup / nv,
                        1e6 * o.solve / nv, (o.setup + o.solve) / baseTotal, o.bytes / nv,
                        o.peakBytes / nv, diff);
                    std::fflush(stdout);
                };
                row(kPlain.name, 1, base, 0.0);
                for (const Variant* v : {&kSaTrans, &kSaRot, &kSaRotK}) {
                    const Outcome o1 = runSolve(s, *v, 1e-3, 1, repeats);
                    row(v->name, 1, o1, 0.0);
                    if (v == &kSaRotK) {
                        const Outcome o2 = runSolve(s, *v, 1e-3, 2, repeats);
                        row(v->name, 2, o2, (o2.dv - o1.dv).cwiseAbs().maxCoeff());
                    }
                }
#ifdef GALE_HAVE_HYPRE
                row("hypre-boomeramg", 1, runHypre(s, 1e-3), 0.0);
#endif
            }
}

// ---- 2. speed against error ---------------------------------------------------------------
void errorBench(bool quick) {
    const int n = quick ? 64 : 128;
    std::printf("\n== speed against error: %dx%d grid, h = 1/24 s; error = max |dv - dv_ref| / "
                "max |dv_ref| (reference: tol 1e-10)\n",
                n, n);
    const ClothSystem s = makeClothSystem(n, 1.0 / 24.0, false, true);
    const Outcome ref = runSolve(s, kSaRot, 1e-10, 1, 1);
    const double scale = ref.dv.cwiseAbs().maxCoeff();
    std::printf("%-19s %6s %6s %5s %10s %10s\n", "preconditioner", "sweeps", "tol", "its",
                "us/vertex", "error");
    for (const Variant& base : {kPlain, kSaRot})
        for (int sweeps : {1, 2})
            for (double tol : {1e-2, 1e-3, 1e-4, 1e-6}) {
                Variant v = base;
                v.sweeps = sweeps;
                const Outcome o = runSolve(s, v, tol, 1, 2);
                std::printf("%-19s %6d %6.0e %5d %10.3f %10.2e\n", v.name, sweeps, tol,
                            o.iterations, 1e6 * (o.setup + o.solve) / s.A.size(),
                            (o.dv - ref.dv).cwiseAbs().maxCoeff() / scale);
            }
}

} // namespace

int main(int argc, char** argv) {
    bool quick = false;
    std::string only;
    int onlySize = 0;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--quick"))
            quick = true;
        else if (!std::strcmp(argv[i], "--only") && i + 1 < argc)
            only = argv[++i];
        else if (!std::strcmp(argv[i], "--size") && i + 1 < argc)
            onlySize = std::atoi(argv[++i]);
        else {
            std::fprintf(
                stderr,
                "usage: gale_bench_multigrid [--quick] [--only scaling|error] [--size N]\n");
            return 2;
        }
    }
#ifdef GALE_HAVE_HYPRE
    MPI_Init(&argc, &argv);
    HYPRE_Init();
#endif
    if (only.empty() || only == "scaling") scalingBench(quick, onlySize);
    if (only.empty() || only == "error") errorBench(quick);
#ifdef GALE_HAVE_HYPRE
    HYPRE_Finalize();
    MPI_Finalize();
#endif
    return 0;
}
