// Aerodynamic lift and drag on one cloth triangle or one hair segment, with the damping matrix
// the implicit solve needs. Wilson, McAdams, Leo, Simmons, "Simulating Wind Effects on Cloth
// and Hair in Disney's Frozen", SIGGRAPH 2014 Talks; spec/aero.md has the derivations.
#pragma once

#include "solver/linalg/types.h"

namespace gale::solver {

// Which force formula a triangle uses.
enum class AeroModel {
    Frozen,     // the paper exactly: F = ½ρA((C_D − C_L)(v·n)v + C_L|v|²n)
    SmoothLift, // lift multiplied by cosθ = (v·n)/|v|: lift ∝ sinθcosθ, zero edge-on (NvCloth)
};

// How the velocity Jacobian is linearised for the implicit solve.
enum class AeroJacobian {
    Bounded, // symmetrised exact ∂F/∂v, its normal–in-plane coupling moved onto the diagonal
             // (an upper bound), negative parts clamped (default: stable, no coupling mode)
    Projected, // symmetrised exact ∂F/∂v with negative eigenvalues clamped (stable)
    Paper,     // the paper's substitution v ≈ (v·n)n after differentiation
    None,      // aerodynamics applied explicitly (for comparisons only: unstable in strong wind)
};

// The scene's name of each (`aero_jacobian`): "bounded", "projected", "paper", "none".
const char* aeroJacobianName(AeroJacobian j);

// Force on an element from the air and its damping matrix D (symmetric positive
// semi-definite, N·s/m): with v = v_wind − v_element, ∂F/∂v_element ≈ −D.
struct AeroResult {
    Vec3 force = Vec3::Zero();
    Mat3 damping = Mat3::Zero();
    // Axial vector ω of the skew part of ∂F/∂v (N·s/m): ½(J − Jᵀ) x = ω × x. A symmetric solve
    // cannot hold it; left explicit it makes the linearised step amplify flutter (docs/solver.md).
    Vec3 skewAxis = Vec3::Zero();
    bool clamped = false; // Paper Jacobian with C_D < C_L: (C_D − C_L) clamped to 0
};

// One triangle. `vRel` = wind − cloth velocity (m/s); `areaNormal` = ½(x1 − x0)×(x2 − x0), of
// either winding (the normal is made two-sided: v·n ≥ 0); `rho` air density (kg/m³); `cl`,
// `cd` lift and drag coefficients (dimensionless, ≥ 0). Zero area or zero relative velocity
// gives exactly zero force and damping.
AeroResult aeroTriangle(const Vec3& vRel, const Vec3& areaNormal, double rho, double cl,
                        double cd, AeroModel model, AeroJacobian jacobian);

// The exact (unsymmetrised) ∂F/∂v of `aeroTriangle`'s force at fixed geometry (for tests and
// the projected treatment).
Mat3 aeroTriangleExactJacobian(const Vec3& vRel, const Vec3& areaNormal, double rho, double cl,
                               double cd, AeroModel model);

// ∂F/∂a of `aeroTriangle`'s force with respect to the area-weighted normal a = `areaNormal` at
// fixed relative velocity: how the force turns and grows with the triangle's orientation, the
// part of ∂F/∂x that the velocity damping lacks (Newton's full Jacobian, body.cpp). With
// p = v·a, σ = sgn p, A = |a|, â = a/A, s = |p|/A, r = |v|:
//   frozen:      ∂F/∂a = ½ρσ[(C_D − C_L) v vᵀ + C_L r² I]
//   smooth-lift: ∂F/∂a = ½ρ[C_D σ v vᵀ + C_L(r â vᵀ + σ s r(I − â âᵀ) − 2σ(s/r) v vᵀ + (s²/r) v
//   âᵀ)]
// Zero at p = 0: there the frozen lift C_L r² n flips sides (F jumps by ρ C_L r² a), so the
// backward-Euler equations of a triangle crossing edge-on have no solution (docs/solver.md).
Mat3 aeroTriangleAreaJacobian(const Vec3& vRel, const Vec3& areaNormal, double rho, double cl,
                              double cd, AeroModel model);

// The nearest (Frobenius) positive semi-definite matrix to the symmetric part of `j`, given
// that j = c·I + (terms in span{n, v}); `n` unit, `v` any. Exact, closed form (2×2 eigen).
Mat3 projectPsdInPlane(const Mat3& j, const Vec3& n, const Vec3& v);

// One hair segment of length `length` (m) and diameter `diameter` (m) along unit tangent `t`:
// cross-flow drag ½ρ C_n d L |v_n| v_n plus tangential skin drag ½ρ C_t (π d L) |v_t| v_t.
// Its exact Jacobian is symmetric positive semi-definite, returned as `damping`.
AeroResult aeroSegment(const Vec3& vRel, const Vec3& t, double length, double diameter,
                       double rho, double cn, double ct);

} // namespace gale::solver
