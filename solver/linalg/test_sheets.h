// Cloth-like filtered systems for the multigrid tests and benchmark (header only, not part of
// the library): a 1 m sheet of triangles, regular or irregular, its backward-Euler matrix
// M + h²K from edge springs, pins along the top and a plane-contact patch.
#pragma once

#include "solver/linalg/linear.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace gale::solver::testing {

struct ClothSystem {
    BlockMatrix A;
    Constraints c;
    VecX b;
    std::vector<int> constrained;
    std::vector<double> x; // positions, 3 per vertex
    std::vector<int> triangles;
};

// An n×n-vertex sheet of 1 m, σ = 0.1 kg/m² (lumped by triangle area), slightly wavy out of
// plane; edge springs of stiffness k = 2000 N/m along each triangle edge (and 1% across it, a
// stand-in for the geometric stiffness of a tense membrane); A = M + h²K.
// irregular: the vertices graded (spacing varies 3:1 across the sheet) and jittered by up to
// 0.3 of a cell, and each quad cut along a random diagonal, so valences run from 3 to 8 and
// triangle areas vary about tenfold. constraints: the top row pinned (S = 0, a prescribed z),
// a 4×4 patch in plane contact (S = I − nnᵀ).
struct SheetOptions {
    bool irregular = false;
    bool constraints = true;
    unsigned seed = 5;
    double transverse = 0.01; // the springs' stiffness across them, a fraction of k
    bool flat = false;        // else the sheet is slightly wavy out of plane
};

// flat with transverse = 0: out of plane the springs hold nothing, only the mass does; with a
// cloth's bending added (the multigrid benchmark's `plate`) that is a slack cloth's system.
inline ClothSystem makeClothSystem(int n, double h, const SheetOptions& o) {
    const bool irregular = o.irregular, constraints = o.constraints;
    const unsigned seed = o.seed;
    ClothSystem s;
    const double k = 2000.0, sigma = 0.1;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    auto id = [n](int i, int j) { return j * n + i; };
    const int nv = n * n;
    s.x.resize(3 * static_cast<size_t>(nv));
    auto grade = [&](double t) { return irregular ? (t + 0.5 * t * t) / 1.5 : t; };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double a = static_cast<double>(i) / (n - 1), b = static_cast<double>(j) / (n - 1);
            if (irregular && i > 0 && i < n - 1) a += 0.3 * u(rng) / (n - 1);
            if (irregular && j > 0 && j < n - 1) b += 0.3 * u(rng) / (n - 1);
            const double x = grade(a), y = grade(b);
            const int v = id(i, j);
            s.x[3 * v] = x;
            s.x[3 * v + 1] = y;
            s.x[3 * v + 2] = o.flat ? 0.0 : 0.05 * std::sin(6.0 * x) * std::cos(5.0 * y);
        }
    for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            if (!irregular || u(rng) < 0.0)
                s.triangles.insert(s.triangles.end(), {a, b, c, a, c, d});
            else
                s.triangles.insert(s.triangles.end(), {a, b, d, b, c, d});
        }
    std::vector<std::pair<int, int>> pairs;
    std::vector<double> mass(nv, 0.0);
    auto pos = [&](int v) { return Vec3(s.x[3 * v], s.x[3 * v + 1], s.x[3 * v + 2]); };
    for (size_t t = 0; t < s.triangles.size(); t += 3) {
        const int* tri = &s.triangles[t];
        const double area =
            0.5 * (pos(tri[1]) - pos(tri[0])).cross(pos(tri[2]) - pos(tri[0])).norm();
        for (int q = 0; q < 3; ++q) {
            mass[tri[q]] += sigma * area / 3.0;
            const int p = tri[q], r = tri[(q + 1) % 3];
            pairs.push_back({std::min(p, r), std::max(p, r)});
        }
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    s.A.build(nv, pairs);
    for (int v = 0; v < nv; ++v) s.A.addDiagonal(s.A.diagonalSlot(v), mass[v]);
    for (const auto& p : pairs) {
        const Vec3 d = (pos(p.second) - pos(p.first)).normalized();
        const Mat3 B =
            h * h * k * (d * d.transpose() + o.transverse * (Mat3::Identity() - d * d.transpose()));
        s.A.addBlock(s.A.slot(p.first, p.first), B);
        s.A.addBlock(s.A.slot(p.second, p.second), B);
        s.A.addBlock(s.A.slot(p.first, p.second), B, -1.0);
        s.A.addBlock(s.A.slot(p.second, p.first), B, -1.0);
    }
    s.b.resize(3 * nv);
    for (int q = 0; q < 3 * nv; ++q) s.b[q] = 1e-3 * u(rng);
    s.c.reset(nv);
    if (constraints) {
        for (int i = 0; i < n; ++i) {
            const int v = id(i, n - 1);
            s.c.kind[v] = 1;
            vec3At(s.c.z.data(), v) = Vec3(0.01 * u(rng), 0.0, 0.02);
        }
        const Vec3 nrm = Vec3(0.1, -0.2, 1.0).normalized();
        for (int j = n / 8; j < n / 8 + 4; ++j)
            for (int i = n / 4; i < n / 4 + 4; ++i) {
                const int v = id(i, j);
                s.c.kind[v] = 2;
                vec3At(s.c.normal.data(), v) = nrm;
                vec3At(s.c.z.data(), v) = 0.01 * nrm;
            }
    }
    for (int v = 0; v < nv; ++v)
        if (s.c.kind[v]) s.constrained.push_back(v);
    return s;
}

inline ClothSystem makeClothSystem(int n, double h, bool irregular, bool constraints,
                                   unsigned seed = 5) {
    SheetOptions o;
    o.irregular = irregular;
    o.constraints = constraints;
    o.seed = seed;
    return makeClothSystem(n, h, o);
}

} // namespace gale::solver::testing
