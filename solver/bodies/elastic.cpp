// Baraff–Witkin membrane, Bergou quadratic bending and hair springs (equations in elastic.h).
#include "solver/bodies/elastic.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

bool makeMembraneRest(const Vec3 uv[3], MembraneRest& out) {
    out = MembraneRest{};
    // Dm = [uv1 − uv0, uv2 − uv0] (2×2); F = Ds Dm⁻¹ with Ds = [x1 − x0, x2 − x0].
    const double a = uv[1].x() - uv[0].x(), b = uv[2].x() - uv[0].x();
    const double c = uv[1].y() - uv[0].y(), d = uv[2].y() - uv[0].y();
    const double det = a * d - b * c;
    const double scale = std::max({std::abs(a), std::abs(b), std::abs(c), std::abs(d)});
    if (!(std::abs(det) > 1e-10 * scale * scale) || !std::isfinite(det)) return false;
    const double inv00 = d / det, inv01 = -b / det, inv10 = -c / det, inv11 = a / det;
    // Row k of Dm⁻¹ gives ∂F/∂x_{k+1}: g_1 = (inv00, inv01), g_2 = (inv10, inv11).
    out.g = {-(inv00 + inv10), -(inv01 + inv11), inv00, inv01, inv10, inv11};
    out.area = 0.5 * std::abs(det);
    return true;
}

void materialCoordinates(const Vec3 x[3], const Vec3& warp, Vec3 uv[3]) {
    const Vec3 e1 = x[1] - x[0], e2 = x[2] - x[0];
    Vec3 n = e1.cross(e2);
    const double nn = n.norm();
    if (!(nn > 0.0)) {
        for (int i = 0; i < 3; ++i) uv[i] = Vec3::Zero();
        return;
    }
    n /= nn;
    Vec3 u = warp - warp.dot(n) * n;
    if (u.norm() < 0.3 * warp.norm()) {
        const Vec3 alt = Vec3::UnitY();
        u = alt - alt.dot(n) * n;
        if (u.norm() < 0.3) u = e1;
    }
    u.normalize();
    const Vec3 v = n.cross(u);
    for (int i = 0; i < 3; ++i) {
        const Vec3 p = x[i] - x[0];
        uv[i] = Vec3(p.dot(u), p.dot(v), 0.0);
    }
}

bool membraneFactors(const MembraneRest& rest, const Vec3 x[3], double kStretch, double kShear,
                     MembraneFactors& out) {
    if (!(rest.area > 0.0)) return false;
    // w_u = Σ a_i x_i, w_v = Σ b_i x_i with a_i = g[2i], b_i = g[2i+1].
    const double* g = rest.g.data();
    const Vec3 wu = g[0] * x[0] + g[2] * x[1] + g[4] * x[2];
    const Vec3 wv = g[1] * x[0] + g[3] * x[1] + g[5] * x[2];
    const double A = rest.area;
    const double lu = wu.norm(), lv = wv.norm();
    const Vec3 hu = lu > 0.0 ? Vec3(wu / lu) : Vec3::Zero();
    const Vec3 hv = lv > 0.0 ? Vec3(wv / lv) : Vec3::Zero();
    const double shear = wu.dot(wv);
    out.energy = A * (0.5 * kStretch * ((lu - 1.0) * (lu - 1.0) + (lv - 1.0) * (lv - 1.0)) +
                      0.5 * kShear * shear * shear);
    // ∂E/∂w_u, ∂E/∂w_v (per unit area).
    const Vec3 gu = kStretch * (lu - 1.0) * hu + kShear * shear * wv;
    const Vec3 gv = kStretch * (lv - 1.0) * hv + kShear * shear * wu;
    // Hessian blocks in (w_u, w_v) space:
    //   H_uu = S_u + k_sh w_v w_vᵀ,  H_vv = S_v + k_sh w_u w_uᵀ,  H_uv = H_vuᵀ = k_sh w_v w_uᵀ,
    //   S_u = k_s (ŵ_u ŵ_uᵀ + t_u (I − ŵ_u ŵ_uᵀ)) = k_s ((1 − t_u) ŵ_u ŵ_uᵀ + t_u I)  (S_v alike).
    // Chain rule, K_ij = A (a_i a_j H_uu + a_i b_j H_uv + b_i a_j H_vu + b_i b_j H_vv); the shear
    // terms are the outer product of s_i = ∂(w_u·w_v)/∂x_i = a_i w_v + b_i w_u, so
    //   K_ij = A (a_i a_j S_u + b_i b_j S_v + k_sh s_i s_jᵀ)   (out.Su = A S_u, out.Sv = A S_v).
    const double tu = lu > 1.0 ? 1.0 - 1.0 / lu : 0.0;
    const double tv = lv > 1.0 ? 1.0 - 1.0 / lv : 0.0;
    out.Su = (A * kStretch * (1.0 - tu)) * hu * hu.transpose();
    out.Su.diagonal().array() += A * kStretch * tu;
    out.Sv = (A * kStretch * (1.0 - tv)) * hv * hv.transpose();
    out.Sv.diagonal().array() += A * kStretch * tv;
    out.shear = A * kShear;
    for (int i = 0; i < 3; ++i) {
        const double ai = g[2 * i], bi = g[2 * i + 1];
        out.a[i] = ai;
        out.b[i] = bi;
        out.f[i] = -A * (ai * gu + bi * gv);
        out.s[i] = ai * wv + bi * wu;
    }
    return true;
}

void membraneForces(const MembraneRest& rest, const Vec3 x[3], double kStretch, double kShear,
                    TriangleElastic& out) {
    MembraneFactors m;
    if (!membraneFactors(rest, x, kStretch, kShear, m)) {
        out.energy = 0.0;
        for (int i = 0; i < 3; ++i) {
            out.f[i].setZero();
            for (int j = 0; j < 3; ++j) out.K[i][j].setZero();
        }
        return;
    }
    out.energy = m.energy;
    for (int i = 0; i < 3; ++i) {
        out.f[i] = m.f[i];
        for (int j = 0; j < 3; ++j) out.K[i][j] = m.block(i, j);
    }
}

namespace {
// cot of the angle between a and b.
double cotangent(const Vec3& a, const Vec3& b) {
    const double s = a.cross(b).norm();
    return a.dot(b) / s;
}
} // namespace

bool makeHingeRest(const Vec3 x[4], HingeRest& out) {
    out = HingeRest{};
    const Vec3 e0 = x[1] - x[0];
    const double a0 = 0.5 * e0.cross(x[2] - x[0]).norm();
    const double a1 = 0.5 * e0.cross(x[3] - x[0]).norm();
    const double len2 = e0.squaredNorm();
    // Reject hinges with a sliver triangle: their cotangents are unbounded.
    if (!(a0 > 1e-8 * len2) || !(a1 > 1e-8 * len2)) return false;
    const double cotAlpha = cotangent(x[1] - x[0], x[2] - x[0]); // at x0 in triangle 0
    const double cotGamma = cotangent(x[1] - x[0], x[3] - x[0]); // at x0 in triangle 1
    const double cotBeta = cotangent(x[0] - x[1], x[2] - x[1]);  // at x1 in triangle 0
    const double cotDelta = cotangent(x[0] - x[1], x[3] - x[1]); // at x1 in triangle 1
    out.k = {cotBeta + cotDelta, cotAlpha + cotGamma, -(cotAlpha + cotBeta), -(cotGamma + cotDelta)};
    out.scale = 3.0 / (a0 + a1);
    for (double c : out.k)
        if (!std::isfinite(c)) {
            out = HingeRest{};
            return false;
        }
    return true;
}

void springForces(const Vec3& x0, const Vec3& x1, double restLength, double ea, SpringElastic& out) {
    out = SpringElastic{};
    if (!(restLength > 0.0)) return;
    const Vec3 e = x1 - x0;
    const double len = e.norm();
    const double k = ea / restLength; // N/m
    const double stretch = len - restLength;
    out.energy = 0.5 * k * stretch * stretch;
    if (!(len > 0.0)) return;
    const Vec3 u = e / len;
    out.f0 = k * stretch * u; // pulls x0 towards x1 when stretched
    const double t = len > restLength ? 1.0 - restLength / len : 0.0;
    out.K = k * (u * u.transpose() + t * (Mat3::Identity() - u * u.transpose()));
}

Mat3 hingeFrame(const Vec3 x[4]) {
    const Vec3 e = x[1] - x[0];
    const Vec3 n0 = e.cross(x[2] - x[0]), n1 = (x[3] - x[0]).cross(e); // same side when flat
    const double l0 = n0.norm(), l1 = n1.norm(), le = e.norm();
    Mat3 f = Mat3::Identity();
    if (!(le > 0.0) || !(l0 > 0.0) || !(l1 > 0.0)) return f;
    const Vec3 eh = e / le;
    Vec3 nb = n0 / l0 + n1 / l1;
    if (!(nb.norm() > 1e-6)) nb = n0 / l0;
    nb = (nb - eh * eh.dot(nb)).normalized(); // exactly ⟂ ê
    f.col(0) = eh;
    f.col(1) = nb;
    f.col(2) = eh.cross(nb);
    return f;
}

void setHingeRestShape(const Vec3 x[4], HingeRest& out) {
    out.bent.setZero();
    if (!(out.scale > 0.0)) return;
    Vec3 s = Vec3::Zero();
    for (int a = 0; a < 4; ++a) s += out.k[a] * x[a];
    out.bent = hingeFrame(x).transpose() * s;
    // |s̄| = 2|e| sin(θ/2) for a fold θ: below 1e-9 rad the hinge is flat (rounding of a plane).
    if (!out.bent.allFinite() || !(out.bent.norm() > 1e-9 * (x[1] - x[0]).norm())) out.bent.setZero();
}

Vec3 strandBendTarget(const Vec3& restD, const Vec3& restTangent, const Vec3& tangent) {
    const double n = tangent.norm();
    if (!(n > 0.0)) return restD;
    return Eigen::Quaterniond::FromTwoVectors(restTangent, tangent / n) * restD;
}

std::array<double, 3> strandBendWeights(double lPrev, double lNext) {
    const double a = 1.0 / lPrev, c = 1.0 / lNext;
    return {a, -(a + c), c};
}

} // namespace gale::solver
