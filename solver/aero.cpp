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
#include "solver/aero.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {

// n oriented two-sided against v, and the area, from the area-weighted normal.
bool orientedNormal(const Vec3& vRel, const Vec3& areaNormal, Vec3& n, double& area) {
    area = areaNormal.norm();
    if (!(area > 0.0) || !std::isfinite(area)) return false;
    n = areaNormal / area;
    const double s = n.dot(vRel);
    // Exactly edge-on the side is ambiguous: pick it from the normal alone (its largest
    // component positive), so that both windings of a triangle feel the same force.
    int big = 0;
    for (int k = 1; k < 3; ++k)
        if (std::abs(n[k]) > std::abs(n[big])) big = k;
    if (s < 0.0 || (s == 0.0 && n[big] < 0.0))
        n = -n;
    return true;
}

// A unit vector perpendicular to unit n.
Vec3 anyPerpendicular(const Vec3& n) {
    Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    return (a - a.dot(n) * n).normalized();
}

} // namespace

Mat3 projectPsdInPlane(const Mat3& j, const Vec3& n, const Vec3& v) {
    const Mat3 s = 0.5 * (j + j.transpose());
    Vec3 e = v - v.dot(n) * n;
    const double en = e.norm();
    e = en > 1e-12 * (v.norm() + 1e-300) && en > 0.0 ? Vec3(e / en) : anyPerpendicular(n);
    const Vec3 b = n.cross(e);
    // In the orthonormal basis (n, e, b): a 2×2 block on (n, e) and c on b; no coupling of b.
    const double a11 = n.dot(s * n), a12 = n.dot(s * e), a22 = e.dot(s * e);
    const double c = b.dot(s * b);
    const double mean = 0.5 * (a11 + a22), half = 0.5 * (a11 - a22);
    const double rad = std::sqrt(half * half + a12 * a12);
    const double l1 = mean + rad, l2 = mean - rad;
    // Eigenvector of l1 in the (n, e) plane: (cos φ, sin φ) with tan 2φ = 2 a12 / (a11 − a22).
    const double phi = 0.5 * std::atan2(2.0 * a12, a11 - a22);
    const Vec3 u1 = std::cos(phi) * n + std::sin(phi) * e;
    const Vec3 u2 = -std::sin(phi) * n + std::cos(phi) * e;
    Mat3 out = std::max(l1, 0.0) * u1 * u1.transpose() + std::max(l2, 0.0) * u2 * u2.transpose() +
               std::max(c, 0.0) * b * b.transpose();
    return out;
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
    case AeroJacobian::Projected:
        out.damping = projectPsdInPlane(aeroTriangleExactJacobian(vRel, areaNormal, rho, cl, cd, model),
                                        n, vRel);
        break;
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
