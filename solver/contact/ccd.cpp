// Closest points and additive CCD (ACCD, Li, Kaufman & Jiang 2021). The advancement argument:
// with the corners moving linearly and the common mean motion removed (distance is translation
// invariant), every point of either primitive moves at most l_p = max|Δp_i| + max|Δq_j| over the
// unit step (a convex combination of its corners' displacements), so the distance d(t) is
// l_p-Lipschitz. From a time t with gap g = d − ξ > 0, advancing by f g / l_p (f = 0.9) keeps
// d ≥ ξ + (1 − f) g: never past contact; contact is reported once g < gapTolerance. Floating point:
// d is computed from coordinates of size X with an absolute error below ~16 ε X (ε = 2⁻⁵³), and l_p
// is rounded up by (1 + 1e-12), so a step stays conservative while the gap exceeds ~100 ε X (2e-14
// m at X = 1 m), far below the gapTolerance (1e-6 m) that ends the iteration; a start gap below
// 1e-12 X counts as contact at t = 0. An exhausted iteration budget (grazing motion) reports
// contact at the clear time reached.
#include "solver/contact/ccd.h"

#include <algorithm>
#include <cmath>

namespace gale::solver::contact {

double pointTriangleDistance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                              double w[3]) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    auto done = [&](double w0, double w1, double w2) {
        w[0] = w0;
        w[1] = w1;
        w[2] = w2;
        return (p - (w0 * a + w1 * b + w2 * c)).squaredNorm();
    };
    // A degenerate triangle: the closest point of its three edges.
    const double area2 = ab.cross(ac).squaredNorm();
    if (!(area2 > 1e-30 * std::max(ab.squaredNorm(), ac.squaredNorm()) *
                      std::max(ab.squaredNorm(), ac.squaredNorm())) ||
        !(area2 > 0.0)) {
        double best = INFINITY, s = 0.0, u = 0.0;
        const Vec3* v[3] = {&a, &b, &c};
        for (int e = 0; e < 3; ++e) {
            const Vec3& x0 = *v[e];
            const Vec3& x1 = *v[(e + 1) % 3];
            const double d = segmentSegmentDistance2(p, p, x0, x1, s, u);
            if (d < best) {
                best = d;
                double ww[3] = {0, 0, 0};
                ww[e] = 1.0 - u;
                ww[(e + 1) % 3] += u;
                w[0] = ww[0];
                w[1] = ww[1];
                w[2] = ww[2];
            }
        }
        return best;
    }
    if (d1 <= 0.0 && d2 <= 0.0) return done(1, 0, 0);
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) return done(0, 1, 0);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double v = d1 / (d1 - d3);
        return done(1 - v, v, 0);
    }
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) return done(0, 0, 1);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double v = d2 / (d2 - d6);
        return done(1 - v, 0, v);
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return done(0, 1 - v, v);
    }
    const double denom = 1.0 / (va + vb + vc);
    const double v = vb * denom, u = vc * denom;
    return done(1 - v - u, v, u);
}

double segmentSegmentDistance2(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                               double& s, double& u) {
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    const double tiny = 1e-30;
    if (a <= tiny && e <= tiny) {
        s = u = 0.0;
        return r.squaredNorm();
    }
    if (a <= tiny) {
        s = 0.0;
        u = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = d1.dot(r);
        if (e <= tiny) {
            u = 0.0;
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = d1.dot(d2), denom = a * e - b * b; // ≥ 0
            // Parallel (denom ~ 0): any s works; take s = 0 and clamp u, then s again.
            s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            u = (b * s + f) / e;
            if (u < 0.0) {
                u = 0.0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (u > 1.0) {
                u = 1.0;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return (p0 + s * d1 - (q0 + u * d2)).squaredNorm();
}

namespace {

// ACCD on a pair of primitives with corners x (4 of them), displacements dx, split into the
// first `firstCount` (one primitive) and the rest; dist2(x) the squared distance.
template <class Dist2>
bool accd(Vec3 x[4], Vec3 dx[4], int firstCount, const CcdOptions& opt, Dist2 dist2, double& toi) {
    Vec3 mean = Vec3::Zero();
    for (int i = 0; i < 4; ++i) mean += dx[i];
    mean /= 4.0;
    double scale = 1.0, la = 0.0, lb = 0.0;
    for (int i = 0; i < 4; ++i) {
        dx[i] -= mean;
        (i < firstCount ? la : lb) = std::max(i < firstCount ? la : lb, dx[i].norm());
        scale = std::max(scale, x[i].cwiseAbs().maxCoeff());
    }
    const double lp = (la + lb) * (1.0 + 1e-12);
    double xi = opt.thickness;
    double d = std::sqrt(dist2(x));
    if (opt.shrinkWithinThickness && d <= xi) xi = 0.5 * d;
    toi = 0.0;
    if (!(d > xi + 1e-12 * scale)) return true; // within the thickness at the start
    if (!(lp > 0.0)) return false;              // no relative motion: the distance is constant
    double t = 0.0;
    double step = opt.stepFraction * (d - xi) / lp;
    for (int it = 0; it < opt.maxIterations; ++it) {
        // The rest of the step is inside the safe advance: no contact before t = 1.
        if (t + step >= 1.0) return false;
        for (int i = 0; i < 4; ++i) x[i] += step * dx[i];
        t += step;
        d = std::sqrt(dist2(x));
        if (d - xi < opt.gapTolerance) {
            toi = t;
            return true;
        }
        step = opt.stepFraction * (d - xi) / lp;
    }
    toi = t; // not resolved within the budget: report contact at a time known to be clear
    return true;
}

} // namespace

bool vertexTriangleCcd(const Vec3& p0, const Vec3& p1, const Vec3& a0, const Vec3& a1,
                       const Vec3& b0, const Vec3& b1, const Vec3& c0, const Vec3& c1,
                       const CcdOptions& opt, double& toi) {
    Vec3 x[4] = {p0, a0, b0, c0}, dx[4] = {p1 - p0, a1 - a0, b1 - b0, c1 - c0};
    return accd(
        x, dx, 1, opt,
        [](const Vec3* y) {
            double w[3];
            return pointTriangleDistance2(y[0], y[1], y[2], y[3], w);
        },
        toi);
}

bool edgeEdgeCcd(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, const Vec3& r0,
                 const Vec3& r1, const Vec3& s0, const Vec3& s1, const CcdOptions& opt,
                 double& toi) {
    Vec3 x[4] = {p0, q0, r0, s0}, dx[4] = {p1 - p0, q1 - q0, r1 - r0, s1 - s0};
    return accd(
        x, dx, 2, opt,
        [](const Vec3* y) {
            double s, u;
            return segmentSegmentDistance2(y[0], y[1], y[2], y[3], s, u);
        },
        toi);
}

} // namespace gale::solver::contact
