// Lift/drag forces and their SPD linearisations (spec/aero.md).
//
// Triangle, relative air velocity v, unit normal n oriented so s = v·n ≥ 0, r = |v|:
//   frozen:      F = ½ρA((C_D − C_L) s v + C_L r² n)
//   smooth-lift: F = ½ρA( C_D s v + C_L (s r n − (s²/r) v) )        (lift × cosθ, cosθ = s/r)
// Exact Jacobians at fixed geometry (n locally constant because the sign flip of the
// two-sided normal happens only at s = 0):
//   frozen:      ∂F/∂v = ½ρA[(C_D − C_L)(v nᵀ + s I) + 2 C_L n vᵀ]
//   smooth-lift: ∂F/∂v = ½ρA[C_D (v nᵀ + s I)
//                  + C_L (r n nᵀ + (s/r) n vᵀ − (2s/r) v nᵀ − (s²/r) I + (s²/r³) v vᵀ)]
// Paper substitution (both models reduce to it with v ≈ s n):
//   D = ½ρA s[(C_D − C_L) I + (C_D + C_L) n nᵀ]
// Bounded (default) and Projected: the symmetric part of the exact Jacobian made PSD; see
// aeroTriangle.
#include "solver/bodies/aero.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {

// The skew part is kept where |c_w| > kSkewGate (C_D + C_L) (see aeroTriangle).
constexpr double kSkewGate = 0.5;

// n oriented two-sided against v, and the area, from the area-weighted normal.
bool orientedNormal(const Vec3& vRel, const Vec3& areaNormal, Vec3& n, double& area) {
    area = areaNormal.norm();
    if (!(area > 0.0) || !std::isfinite(area)) return false;
    n = areaNormal / area;
    const double s = n.dot(vRel);
    if (s < 0.0) {
        n = -n;
    } else if (s == 0.0) {
        // Exactly edge-on the side is ambiguous: pick it from the normal alone (its largest
        // component positive), so that both windings of a triangle feel the same force.
        int big = 0;
        for (int k = 1; k < 3; ++k)
            if (std::abs(n[k]) > std::abs(n[big])) big = k;
        if (n[big] < 0.0) n = -n;
    }
    return true;
}

// A unit vector perpendicular to unit n.
Vec3 anyPerpendicular(const Vec3& n) {
    Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    return (a - a.dot(n) * n).normalized();
}

// The unit e ⟂ n in the plane of n and v, v = (v·n) n + q e with q ≥ 0 (any perpendicular
// and q = 0 when v is along n).
Vec3 inPlaneDirection(const Vec3& n, const Vec3& v, double vNorm, double& q) {
    const Vec3 e = v - v.dot(n) * n;
    q = e.norm();
    if (q > 1e-12 * (vNorm + 1e-300) && q > 0.0) return e / q;
    q = 0.0;
    return anyPerpendicular(n);
}

// The nearest PSD matrix to the symmetric S = [n e] M [n e]ᵀ + c b bᵀ (n, e, b orthonormal),
// M = [[a11, a12], [a12, a22]]: each part projected on its own.
// Eigenvalues of M: l1,2 = m ± r, m = (a11 + a22)/2, r = √(((a11 − a22)/2)² + a12²).
// Both ≥ 0: M is its own projection. Both ≤ 0: it projects to 0. Otherwise l1 > 0 > l2 and the
// projection is l1 u1u1ᵀ with the eigenprojector u1u1ᵀ = (M − l2 I₂)/(l1 − l2), l1 − l2 = 2r > 0
// (no eigenvector angle needed; exact for a12 = 0 and equal eigenvalues alike).
// With M⁺ = [[p11, p12], [p12, p22]] and b bᵀ = I − n nᵀ − e eᵀ:
//   out = max(c, 0) I + (p11 − c⁺) n nᵀ + p12 (n eᵀ + e nᵀ) + (p22 − c⁺) e eᵀ  (exactly symmetric).
// A NaN entry propagates (a non-finite state must stay visible).
Mat3 projectPlane(double a11, double a12, double a22, double c, const Vec3& n, const Vec3& e) {
    const double mean = 0.5 * (a11 + a22), half = 0.5 * (a11 - a22);
    const double rad = std::sqrt(half * half + a12 * a12);
    const double l1 = mean + rad, l2 = mean - rad;
    if (l1 <= 0.0) {
        a11 = a12 = a22 = 0.0;
    } else if (l2 < 0.0) {
        const double w = l1 / (2.0 * rad);
        a11 = w * (a11 - l2);
        a22 = w * (a22 - l2);
        a12 = w * a12;
    }
    const double cp = c <= 0.0 ? 0.0 : c;
    const double d11 = a11 - cp, d22 = a22 - cp;
    Mat3 out;
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            const double x = d11 * (n[i] * n[j]) + a12 * (n[i] * e[j] + e[i] * n[j]) + d22 * (e[i] * e[j]);
            out(i, j) = out(j, i) = i == j ? x + cp : x;
        }
    return out;
}

} // namespace

Mat3 projectPsdInPlane(const Mat3& j, const Vec3& n, const Vec3& v) {
    const Mat3 s = 0.5 * (j + j.transpose());
    double q;
    const Vec3 e = inPlaneDirection(n, v, v.norm(), q);
    const Vec3 b = n.cross(e);
    // In the orthonormal basis (n, e, b): a 2×2 block on (n, e) and c on b; no coupling of b.
    const Vec3 se = s * e;
    return projectPlane(n.dot(s * n), n.dot(se), e.dot(se), b.dot(s * b), n, e);
}

Mat3 aeroTriangleExactJacobian(const Vec3& vRel, const Vec3& areaNormal, double rho, double cl,
                               double cd, AeroModel model) {
    Vec3 n;
    double area;
    if (!orientedNormal(vRel, areaNormal, n, area)) return Mat3::Zero();
    const double k = 0.5 * rho * area;
    const double s = vRel.dot(n);
    const Mat3 I = Mat3::Identity();
    if (model == AeroModel::Frozen)
        return k * ((cd - cl) * (vRel * n.transpose() + s * I) + 2.0 * cl * n * vRel.transpose());
    const double r = vRel.norm();
    if (!(r > 0.0)) return Mat3::Zero();
    Mat3 j = cd * (vRel * n.transpose() + s * I);
    j += cl * (r * n * n.transpose() + (s / r) * n * vRel.transpose() -
               (2.0 * s / r) * vRel * n.transpose() - (s * s / r) * I +
               (s * s / (r * r * r)) * vRel * vRel.transpose());
    return k * j;
}

Mat3 aeroTriangleAreaJacobian(const Vec3& vRel, const Vec3& areaNormal, double rho, double cl,
                              double cd, AeroModel model) {
    // F = ½ρ((C_D − C_L)|p| v + C_L r² σ a) (frozen), ½ρ(C_D |p| v + C_L(r p a/A − p² v/(A r)))
    // (smooth-lift), differentiated in a at fixed v.
    const double area = areaNormal.norm();
    const double r2 = vRel.squaredNorm();
    if (!(area > 0.0) || !std::isfinite(area) || !(r2 > 0.0)) return Mat3::Zero();
    const double p = vRel.dot(areaNormal);
    if (p == 0.0) return Mat3::Zero();
    const double sigma = p > 0.0 ? 1.0 : -1.0;
    const Mat3 I = Mat3::Identity();
    const Mat3 vv = vRel * vRel.transpose();
    if (model == AeroModel::Frozen) return 0.5 * rho * sigma * ((cd - cl) * vv + cl * r2 * I);
    const double r = std::sqrt(r2);
    const Vec3 ah = areaNormal / area;
    const double s = std::abs(p) / area;
    const Mat3 lift = r * ah * vRel.transpose() + (sigma * s * r) * (I - ah * ah.transpose()) -
                      (2.0 * sigma * s / r) * vv + (s * s / r) * vRel * ah.transpose();
    return 0.5 * rho * (cd * sigma * vv + cl * lift);
}

const char* aeroJacobianName(AeroJacobian j) {
    switch (j) {
    case AeroJacobian::Bounded:
        return "bounded";
    case AeroJacobian::Projected:
        return "projected";
    case AeroJacobian::Paper:
        return "paper";
    case AeroJacobian::None:
        break;
    }
    return "none";
}

AeroResult aeroTriangle(const Vec3& vRel, const Vec3& areaNormal, double rho, double cl,
                        double cd, AeroModel model, AeroJacobian jacobian) {
    AeroResult out;
    Vec3 n;
    double area;
    if (!orientedNormal(vRel, areaNormal, n, area)) return out;
    const double r2 = vRel.squaredNorm();
    if (!(r2 > 0.0)) return out;
    const double k = 0.5 * rho * area; // kg/m
    const double s = vRel.dot(n);      // ≥ 0
    if (model == AeroModel::Frozen) {
        out.force = k * ((cd - cl) * s * vRel + cl * r2 * n);
    } else {
        const double r = std::sqrt(r2);
        out.force = k * (cd * s * vRel + cl * (s * r * n - (s * s / r) * vRel));
    }
    switch (jacobian) {
    case AeroJacobian::None:
        break;
    case AeroJacobian::Paper: {
        double iso = cd - cl;
        if (iso < 0.0) {
            iso = 0.0;
            out.clamped = true;
        }
        out.damping = k * s * (iso * Mat3::Identity() + (cd + cl) * n * n.transpose());
        break;
    }
    case AeroJacobian::Bounded:
    case AeroJacobian::Projected: {
        // The symmetric part of the exact Jacobian written out in the basis (n, e, b),
        // v = s n + q e, r² = s² + q², as M = [[a11, a12], [a12, a22]] on (n, e) and c on b:
        //   frozen:      M = k [[2 C_D s, (C_D + C_L) q/2], [·, (C_D − C_L) s]],
        //                c = k (C_D − C_L) s
        //   smooth-lift: M = k [[2 C_D s + C_L q⁴/r³, C_D q/2 + C_L s q (s² − q²)/(2r³)],
        //                       [·, C_D s − C_L s⁴/r³]],
        //                c = k (C_D s − C_L s²/r)
        // (smooth-lift in the bounded ratios σ = s/r, κ = q/r: q⁴/r³ = q κ³, s⁴/r³ = s σ³, ...).
        // Projected: projectPsdInPlane(aeroTriangleExactJacobian(..), n, v) in closed form.
        // Bounded: the coupling a12 moved onto the diagonal, diag(a11 + |a12|, a22 + |a12|) ⪰ M
        // (the difference |a12| [[1, −sgn], [−sgn, 1]] is PSD), then clamped as Projected is.
        // Where M is indefinite — a flag streaming in the wind, q ≫ s: a12 ≈ k(C_D + C_L)q/2
        // against diagonals ∝ s — Projected keeps a rank-one damping along one diagonal of
        // (n, e) and none along the other, so a normal push (lift, a gust) moves the cloth
        // along the flow, in-plane, undamped; neighbouring triangles pushed differently then
        // stretch the edges along the wind (the wind-onset flag at 256²: 2.7× after the onset;
        // Bounded 1.47×, bench/README.md). Bounded damps n and e each on its own; edge-on
        // (s = 0) it keeps the normal damping k(C_D + C_L)q/2 that makes Projected stable.
        double q;
        const double r = std::sqrt(r2);
        const Vec3 e = inPlaneDirection(n, vRel, r, q);
        // Skew parts (from the exact Jacobians above): ½(J − Jᵀ) = ½k c_w (v nᵀ − n vᵀ) with
        //   frozen: c_w = C_D − 3 C_L,   smooth-lift: c_w = C_D − 3 C_L s/r,
        // and (v nᵀ − n vᵀ) x = (n × v) × x.
        // Kept only where it is comparable to the symmetric damping, |c_w| > ½(C_D + C_L) (the
        // default C_L = 0.3, C_D = 1 gives 0.1 against 0.65: left out, the solve stays symmetric).
        const double cw = model == AeroModel::Frozen ? cd - 3.0 * cl : cd - 3.0 * cl * (s / r);
        if (std::abs(cw) > kSkewGate * (cd + cl)) out.skewAxis = 0.5 * k * cw * n.cross(vRel);
        double a11, a12, a22, c;
        if (model == AeroModel::Frozen) {
            a11 = 2.0 * k * cd * s;
            a12 = 0.5 * k * (cd + cl) * q;
            a22 = c = k * (cd - cl) * s;
        } else {
            const double sig = s / r, kap = q / r;
            a11 = k * (2.0 * cd * s + cl * q * kap * kap * kap);
            a12 = k * (0.5 * cd * q + 0.5 * cl * s * kap * (sig * sig - kap * kap));
            a22 = k * (cd * s - cl * s * sig * sig * sig);
            c = k * (cd * s - cl * s * sig);
        }
        if (jacobian == AeroJacobian::Bounded) {
            a11 += std::abs(a12);
            a22 += std::abs(a12);
            a12 = 0.0;
        }
        out.damping = projectPlane(a11, a12, a22, c, n, e);
        break;
    }
    }
    return out;
}

AeroResult aeroSegment(const Vec3& vRel, const Vec3& t, double length, double diameter,
                       double rho, double cn, double ct) {
    AeroResult out;
    if (!(length > 0.0) || !(diameter > 0.0)) return out;
    const double a = vRel.dot(t);
    const Vec3 vt = a * t;
    const Vec3 vn = vRel - vt;
    const double vnNorm = vn.norm();
    const double kn = 0.5 * rho * cn * diameter * length;               // normal: projected area d·L
    const double kt = 0.5 * rho * ct * 3.14159265358979323846 * diameter * length; // skin π d L
    out.force = kn * vnNorm * vn + kt * std::abs(a) * vt;
    // ∂(|v_n| v_n)/∂v = |v_n| P + v_n v_nᵀ/|v_n| (P = I − t tᵀ); ∂(|a| a t)/∂v = 2|a| t tᵀ.
    const Mat3 P = Mat3::Identity() - t * t.transpose();
    if (vnNorm > 0.0) out.damping = kn * (vnNorm * P + vn * vn.transpose() / vnNorm);
    out.damping += kt * 2.0 * std::abs(a) * t * t.transpose();
    return out;
}

} // namespace gale::solver
