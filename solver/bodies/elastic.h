// Elastic elements with positive semi-definite stiffness matrices: Baraff–Witkin stretch and
// shear on triangles, the quadratic (isometric) bending of Bergou et al. on hinges, and the
// stretch springs and bending stencils of hair strands.
#pragma once

#include "solver/linalg/types.h"

#include <array>

namespace gale::solver {

// ---- Cloth membrane: Baraff & Witkin, "Large Steps in Cloth Simulation", SIGGRAPH 1998 ----
// The deformation of a triangle, F = [w_u w_v] = Σ_i x_i g_iᵀ (3×2), maps rest material space
// (warp u, weft v, metres) to world space. Energy per triangle, rest area A (m²):
//   E = A [ ½k_s((|w_u| − 1)² + (|w_v| − 1)²) + ½k_sh (w_u·w_v)² ]
// k_s stretch and k_sh shear stiffness in N/m (membrane stiffness: modulus × thickness).
struct MembraneRest {
    double area = 0.0;           // rest area (m²); 0 for a degenerate rest triangle
    std::array<double, 6> g{};   // g_i = (g[2i], g[2i+1]): ∂w_u/∂x_i, ∂w_v/∂x_i (1/m)
};

// Rest data from the rest corners and their 2D material coordinates (m). False (and area 0)
// for a degenerate triangle: it then takes no membrane force.
bool makeMembraneRest(const Vec3 uv[3], MembraneRest& out);
// Material coordinates of a rest triangle lying anywhere in 3D: u along `warp` projected onto
// the triangle's plane (or along world Y if that is nearly normal), v perpendicular in-plane.
void materialCoordinates(const Vec3 x[3], const Vec3& warp, Vec3 uv[3]);

// Energy, forces f_i = −∂E/∂x_i and the Gauss–Newton stiffness K_ij ≈ ∂²E/∂x_i∂x_j (PSD):
// the stretch Hessian keeps its geometric term only in tension, (1 − 1/|w|)(I − ŵŵᵀ) ≥ 0;
// the indefinite part of the shear Hessian is dropped.
struct TriangleElastic {
    double energy = 0.0;
    Vec3 f[3];
    Mat3 K[3][3];
};
void membraneForces(const MembraneRest& rest, const Vec3 x[3], double kStretch, double kShear,
                    TriangleElastic& out);

// The same in the factored form assembly uses (cheaper than the nine blocks): with
// a_i = ∂w_u/∂x_i, b_i = ∂w_v/∂x_i (rest.g) and s_i = ∂(w_u·w_v)/∂x_i = a_i w_v + b_i w_u,
//   K_ij = a_i a_j S_u + b_i b_j S_v + c s_i s_jᵀ,   S_u, S_v symmetric PSD, c = A k_sh,
// so K_ji = K_ijᵀ and K v needs only ẇ_u = Σ a_j v_j, ẇ_v = Σ b_j v_j and Σ s_j·v_j:
//   (K v)_i = a_i S_u ẇ_u + b_i S_v ẇ_v + c (Σ_j s_j·v_j) s_i.
struct MembraneFactors {
    double energy = 0.0;
    Vec3 f[3];
    double a[3], b[3];
    Mat3 Su, Sv; // A k_s ((1 − t) ŵ ŵᵀ + t I) of w_u and w_v, t = max(0, 1 − 1/|w|)
    double shear = 0.0; // c = A k_sh
    Vec3 s[3];
    Mat3 block(int i, int j) const {
        return (a[i] * a[j]) * Su + (b[i] * b[j]) * Sv + (shear * s[i]) * s[j].transpose();
    }
};
// False (and `out` untouched) for a degenerate rest triangle.
bool membraneFactors(const MembraneRest& rest, const Vec3 x[3], double kStretch, double kShear,
                     MembraneFactors& out);

// ---- Cloth bending: Bergou, Wardetzky, Harmon, Zorin, Grinspun, "A Quadratic Bending Model for
// Inextensible Surfaces", SGP 2006. For the hinge over edge (x0, x1) with opposite corners x2,
// x3 and the angles α, γ at x0 and β, δ at x1 in the two triangles:
//   k = (cot β + cot δ, cot α + cot γ, −(cot α + cot β), −(cot γ + cot δ))
//   E = ½ (3 k_b / (A0 + A1)) |Σ k_i x_i|²   (flat rest shape; k_b in N·m)
// A constant, PSD Hessian Q = (3 k_b / (A0 + A1)) k kᵀ ⊗ I₃. For a hinge folded by θ,
// E = 6 k_b |e|² sin²(θ/2) / (A0 + A1).
struct HingeRest {
    std::array<double, 4> k{}; // cotangent weights (dimensionless)
    double scale = 0.0;        // 3 / (A0 + A1) (1/m²); 0 for a degenerate hinge
    // A curved rest shape: the rest value of s̄ = Σ k_i X_i in the hinge's frame (edge ê,
    // bisector normal n̂_b = (n̂0 + n̂1)/|n̂0 + n̂1|, b̂ = ê × n̂_b), metres; all zero when flat.
    Vec3 bent = Vec3::Zero();
};
bool makeHingeRest(const Vec3 x[4], HingeRest& out);

// Non-flat rest shapes (rest_shape = "mesh"): the energy becomes E = ½ c |s − r(x)|² with
// r(x) = the rest s̄ carried into the current hinge frame (frameOf below), a rotation of the rest
// vector with the hinge as in projective dynamics' bending (Bouaziz, Martin, Liu, Kavan, Pauly,
// "Projective Dynamics", SIGGRAPH 2014). r is zero for a flat rest hinge (the flat model
// above), E = 0 at the rest shape, and r is frozen in the Jacobian, which stays the constant
// PSD c k kᵀ ⊗ I₃ (its rotation is explicit; it is small per substep for bends near the rest).
// Stores the rest s̄ of x (the rest corners) in out.bent; out.k must be set (makeHingeRest).
void setHingeRestShape(const Vec3 x[4], HingeRest& out);
// The hinge frame (ê, n̂_b, b̂) at corners x, as columns; n̂_b falls back to n̂0 when the two
// normals nearly cancel (a hinge folded flat onto itself).
Mat3 hingeFrame(const Vec3 x[4]);

// ---- Hair: a chain of segments ----
// Stretch: E = ½ (EA / L)(|e| − L)² per segment (EA in N). Gradient along ê; stiffness
//   K = (EA/L)[ê êᵀ + max(0, 1 − L/|e|)(I − ê êᵀ)]  (PSD), K_00 = K_11 = K, K_01 = −K.
struct SpringElastic {
    double energy = 0.0;
    Vec3 f0 = Vec3::Zero(); // force on the first end (the second gets −f0)
    Mat3 K = Mat3::Zero();
};
void springForces(const Vec3& x0, const Vec3& x1, double restLength, double ea, SpringElastic& out);

// Bending at interior vertex i: d = (x_{i+1} − x_i)/L_i − (x_i − x_{i−1})/L_{i−1} (the change of
// the unit rest tangent), E = ½ (EI / L̄) |d|², L̄ = (L_{i−1} + L_i)/2, EI in N·m² (straight rest
// shape). d = Σ c_j x_j with constant weights c, so Q = (EI/L̄) c cᵀ ⊗ I₃ is constant and PSD.
std::array<double, 3> strandBendWeights(double lPrev, double lNext);
// A curled rest strand: E = ½ (EI/L̄) |d − R d̄|², d̄ the rest d and R the smallest rotation
// taking the rest direction of segment i−1 to its current one (R frozen in the Jacobian, as for
// cloth hinges above). The strand carries no material frame (no twist), so a curl keeps its
// curvature but may roll about the incoming segment.
Vec3 strandBendTarget(const Vec3& restD, const Vec3& restTangent, const Vec3& tangent);

} // namespace gale::solver
