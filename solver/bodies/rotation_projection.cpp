// The rotation-length projection (rotation_projection.h): Gauss–Newton on
//   min ½ (x − x₁)ᵀ M (x − x₁)  subject to  C_e(x) = |x_b − x_a| − T_e ≤ 0,
// T_e = max(L_e, d̂₀·d₁) (the rest length, or the length the linearised step saw). Each
// iteration solves (J W Jᵀ + α I) λ = C on the active edges (C_e > tolerance · L_e) by
// Jacobi-preconditioned CG and moves x ← x − s W Jᵀ λ, W_i = P_i S_i P_i / m_i (S the constraint
// filter: pins fixed, contacts in their plane; P a collider's plane near the vertex), the step s
// halved until the merit Σ max(C, 0)² falls. The work is on the active edges and their vertices
// only (a few hundred edges of a sheet where it turns about a contact ring or a whip's front).
#include "solver/bodies/rotation_projection.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {
constexpr int kMaxIterations = 6; // Gauss–Newton iterations
// ... and up to LateIterations::iterations more while an edge is still beyond its target by
// LateIterations::excess, or by kLateTolerances times the tolerance where that is more. An edge
// joins the active set only once a neighbour's move has lengthened it, so a chain turning about
// a contact (a flap over a box's edge, 6 edges long) needs about an iteration per edge: at 6 its
// outer edge was left 1.45× rest. (The defaults, 2 % and 18 (24 in all), are a strand's: below
// 2 % the vertices the later iterations move along a curved collider's tangent plane end inside
// it, for the push-out after the solve, which stretches the strand (hair dropped on a sphere at
// μ = 0.5: 1.029 → 1.082 at 0.5 %); a cloth's are Body's kClothLate. In free air, at a
// tolerance of 3 %, the later iterations for every edge beyond 3 % cost the wind-onset flag
// 25–35 % of its median frame; for those beyond 15 % the cost is within the noise, and its
// stretch still 1.40 → 1.19.)
constexpr double kLateTolerances = 5.0;
constexpr int kMaxLimitIterations = 30;  // ... with a stretch limit (a bound, not a correction)
constexpr int kMaxCg = 60;               // CG iterations per Gauss–Newton iteration
constexpr double kCgTolerance = 1e-3;    // relative residual of each linear solve
constexpr double kRegularisation = 1e-2; // α relative to the mean diagonal of J W Jᵀ
constexpr int kMaxCuts = 10;             // step halvings of the merit's line search
} // namespace

RotationProjectionStats
projectRotationLength(const std::vector<std::array<int, 2>>& edges, const std::vector<double>& rest,
                      const VecX& mass, const Constraints& constraints, const VecX& x0,
                      const VecX& v0, const VecX& y, double h, VecX& dv, double tolerance,
                      const std::function<Vec3(int)>& hold, bool rotations, double stretchLimit,
                      const std::vector<double>* caps, const std::vector<double>* floors,
                      const LateIterations& late) {
    RotationProjectionStats stats;
    const size_t n = static_cast<size_t>(mass.size());
    VecX x = x0 + h * (v0 + dv) + y;
    const auto at = [](const VecX& v, int i) { return Vec3(v.segment<3>(3 * i)); };
    // Targets from the linearised end state, and how many edges are beyond them.
    std::vector<double> target(edges.size()), len(edges.size()); // len: |x_b − x_a| at x
    int beyond = 0;
    double worst = 0.0;
    // Shorter than its floor by more than the tolerance (floors given).
    const auto belowFloor = [&](size_t e, double l) {
        return floors && l < (*floors)[e] - tolerance * rest[e];
    };
    for (size_t e = 0; e < edges.size(); ++e) {
        const auto [a, b] = edges[e];
        const Vec3 d0 = at(x0, b) - at(x0, a), d1 = at(x, b) - at(x, a);
        const double l0 = d0.norm();
        len[e] = d1.norm();
        target[e] = !rotations ? INFINITY : l0 > 0.0 ? std::max(rest[e], d0.dot(d1) / l0) : rest[e];
        // Below the cap by the tolerance: an edge is left alone within it of its target.
        if (stretchLimit > 0.0)
            target[e] = std::min(target[e], (stretchLimit - tolerance) * rest[e]);
        if (caps) target[e] = std::min(target[e], (*caps)[e]);
        if (!(rest[e] > 0.0)) continue; // a degenerate edge: left alone
        const double excess = (len[e] - target[e]) / rest[e];
        worst = std::max(worst, excess);
        if (excess > tolerance || belowFloor(e, len[e])) ++beyond;
    }
    stats.excessBefore = stats.excessAfter = worst;
    stats.activeEdges = beyond;
    if (beyond == 0) return stats;
    // W per vertex (3×3), computed when an edge of it first becomes active.
    std::vector<Mat3> wOf(n);
    std::vector<uint8_t> known(n, 0);
    const auto weight = [&](int v) -> const Mat3& {
        const size_t i = static_cast<size_t>(v);
        if (!known[i]) {
            known[i] = 1;
            const double m = mass[static_cast<long>(i)];
            wOf[i] = m > 0.0 ? Mat3(constraints.filter(i) / m) : Mat3(Mat3::Zero());
            const Vec3 nn = constraints.kind[i] == 0 && hold ? hold(v) : Vec3(Vec3::Zero());
            if (nn.squaredNorm() > 0.0) {
                const Mat3 plane = Mat3::Identity() - nn * nn.transpose();
                wOf[i] = plane * wOf[i] * plane;
            }
        }
        return wOf[i];
    };
    // The merit Σ max(C, 0)² over every edge (a move may lengthen an edge that was not active),
    // tracked by its change: a move of some vertices changes only the edges incident to them
    // (incidence in CSR, built once a call), so each trial of the line search costs the moved
    // vertices' edges, not a pass over the mesh.
    const auto penalty = [&](size_t e, double l) {
        const double ex = l - target[e];
        const double under = floors ? (*floors)[e] - l : 0.0;
        return !(rest[e] > 0.0) ? 0.0 : ex > 0.0 ? ex * ex : under > 0.0 ? under * under : 0.0;
    };
    std::vector<int> incStart(n + 1, 0), incEdges(2 * edges.size());
    for (const auto& e : edges) {
        ++incStart[static_cast<size_t>(e[0]) + 1];
        ++incStart[static_cast<size_t>(e[1]) + 1];
    }
    for (size_t i = 0; i < n; ++i) incStart[i + 1] += incStart[i];
    {
        std::vector<int> fill(incStart.begin(), incStart.end() - 1);
        for (size_t e = 0; e < edges.size(); ++e)
            for (int v : edges[e])
                incEdges[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(e);
    }
    std::vector<int> touched; // edges incident to the moved vertices, each once
    std::vector<uint8_t> seen(edges.size(), 0);
    std::vector<double> trialLen; // their lengths at the trial positions
    std::vector<int> slot(n, -1), verts;
    std::vector<Mat3> w;

    std::vector<int> active;
    std::vector<Vec3> dir, u;
    std::vector<double> c, lambda, r, z, p, q, diag;
    const bool bound = stretchLimit > 0.0 || caps; // a bound, not a correction
    const int maxIterations = bound ? kMaxLimitIterations : kMaxIterations + late.iterations;
    for (int it = 0; it < maxIterations; ++it) {
        active.clear();
        dir.clear();
        c.clear();
        for (int v : verts) slot[static_cast<size_t>(v)] = -1;
        verts.clear();
        w.clear();
        double most = 0.0; // the largest relative excess of an active edge
        for (size_t e = 0; e < edges.size(); ++e) {
            // (Shorter than its floor: a negative excess, the same step lengthens it.)
            double excess = len[e] - target[e];
            if (belowFloor(e, len[e]))
                excess = len[e] - (*floors)[e];
            else if (!(excess > tolerance * rest[e]))
                continue;
            if (!(len[e] > 0.0) || !(rest[e] > 0.0)) continue;
            most = std::max(most, std::abs(excess) / rest[e]);
            const auto [a, b] = edges[e];
            active.push_back(static_cast<int>(e));
            dir.push_back((at(x, b) - at(x, a)) / len[e]);
            c.push_back(excess);
            for (int v : edges[e])
                if (slot[static_cast<size_t>(v)] < 0) {
                    slot[static_cast<size_t>(v)] = static_cast<int>(verts.size());
                    verts.push_back(v);
                    w.push_back(weight(v));
                }
        }
        if (active.empty()) break;
        if (it >= kMaxIterations && !bound &&
            !(most > std::max(late.excess, kLateTolerances * tolerance)))
            break;
        u.resize(verts.size());
        ++stats.iterations;
        const size_t m = active.size();
        const auto ends = [&](size_t k) {
            const auto [a, b] = edges[static_cast<size_t>(active[k])];
            return std::array<int, 2>{slot[static_cast<size_t>(a)], slot[static_cast<size_t>(b)]};
        };
        diag.assign(m, 0.0);
        double mean = 0.0;
        for (size_t k = 0; k < m; ++k) {
            const auto [sa, sb] = ends(k);
            diag[k] = dir[k].dot((w[sa] + w[sb]) * dir[k]);
            mean += diag[k];
        }
        const double alpha = kRegularisation * mean / static_cast<double>(m);
        for (double& d : diag) d += alpha;
        // u = W Jᵀ v (per vertex of the active edges).
        const auto spread = [&](const std::vector<double>& v) {
            std::fill(u.begin(), u.end(), Vec3::Zero());
            for (size_t k = 0; k < m; ++k) {
                const auto [sa, sb] = ends(k);
                u[sa] -= v[k] * dir[k];
                u[sb] += v[k] * dir[k];
            }
            for (size_t k = 0; k < verts.size(); ++k) u[k] = w[k] * u[k];
        };
        // out = (J W Jᵀ + α I) v.
        const auto apply = [&](const std::vector<double>& v, std::vector<double>& out) {
            spread(v);
            out.resize(m);
            for (size_t k = 0; k < m; ++k) {
                const auto [sa, sb] = ends(k);
                out[k] = dir[k].dot(u[sb] - u[sa]) + alpha * v[k];
            }
        };
        lambda.assign(m, 0.0);
        r = c;
        z.resize(m);
        double rz = 0.0, r0 = 0.0;
        for (size_t k = 0; k < m; ++k) {
            z[k] = diag[k] > 0.0 ? r[k] / diag[k] : 0.0;
            rz += r[k] * z[k];
            r0 += r[k] * r[k];
        }
        p = z;
        r0 = std::sqrt(r0);
        for (int cg = 0; cg < kMaxCg && r0 > 0.0; ++cg) {
            apply(p, q);
            double pq = 0.0;
            for (size_t k = 0; k < m; ++k) pq += p[k] * q[k];
            if (!(pq > 0.0)) break;
            const double step = rz / pq;
            double rr = 0.0;
            for (size_t k = 0; k < m; ++k) {
                lambda[k] += step * p[k];
                r[k] -= step * q[k];
                rr += r[k] * r[k];
            }
            ++stats.cgIterations;
            if (std::sqrt(rr) <= kCgTolerance * r0) break;
            double rzNew = 0.0;
            for (size_t k = 0; k < m; ++k) {
                z[k] = diag[k] > 0.0 ? r[k] / diag[k] : 0.0;
                rzNew += r[k] * z[k];
            }
            const double beta = rzNew / rz;
            rz = rzNew;
            for (size_t k = 0; k < m; ++k) p[k] = z[k] + beta * p[k];
        }
        // The step −W Jᵀ λ on the vertices of the active edges, halved until the merit falls:
        // its change over the edges incident to them, Σ φ_e(trial) − φ_e(x).
        spread(lambda);
        touched.clear();
        for (int v : verts)
            for (int k = incStart[static_cast<size_t>(v)]; k < incStart[static_cast<size_t>(v) + 1];
                 ++k) {
                const int e = incEdges[static_cast<size_t>(k)];
                if (!seen[static_cast<size_t>(e)]) {
                    seen[static_cast<size_t>(e)] = 1;
                    touched.push_back(e);
                }
            }
        for (int e : touched) seen[static_cast<size_t>(e)] = 0;
        trialLen.resize(touched.size());
        const auto trialAt = [&](int v, double s) {
            const int k = slot[static_cast<size_t>(v)];
            return k >= 0 ? Vec3(at(x, v) - s * u[static_cast<size_t>(k)]) : at(x, v);
        };
        double s = 1.0;
        bool lowered = false;
        for (int cut = 0; cut <= kMaxCuts; ++cut, s *= 0.5) {
            double change = 0.0;
            for (size_t k = 0; k < touched.size(); ++k) {
                const size_t e = static_cast<size_t>(touched[k]);
                trialLen[k] = (trialAt(edges[e][1], s) - trialAt(edges[e][0], s)).norm();
                change += penalty(e, trialLen[k]) - penalty(e, len[e]);
            }
            if (change < 0.0) {
                lowered = true;
                break;
            }
        }
        if (!lowered) break;
        for (size_t k = 0; k < verts.size(); ++k)
            x.segment<3>(3 * verts[k]) = at(x, verts[k]) - s * u[k];
        for (size_t k = 0; k < touched.size(); ++k)
            len[static_cast<size_t>(touched[k])] = trialLen[k];
    }
    worst = 0.0; // (len holds every edge's length at x: the accepted moves updated theirs)
    for (size_t e = 0; e < edges.size(); ++e)
        if (rest[e] > 0.0) worst = std::max(worst, (len[e] - target[e]) / rest[e]);
    stats.excessAfter = worst;
    if (!x.allFinite()) return stats; // Δv left as the linearised step's
    for (size_t v = 0; v < n; ++v)
        if (known[v]) dv.segment<3>(3 * v) = (at(x, v) - at(x0, v) - at(y, v)) / h - at(v0, v);
    return stats;
}

} // namespace gale::solver
