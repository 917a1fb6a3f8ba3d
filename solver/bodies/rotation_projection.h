// Projects out the length a linearised step's rotations add (StepOptions::rotationProjection): the
// linearised step sees an edge's length change only along its start direction, so an edge
// turned by θ within the step ends L(√(1 + θ²) − 1) longer than any force resisted. Each edge
// longer than both its rest length and the length the linearisation saw is brought back to the
// longer of the two by a mass-weighted, constraint-filtered projection solved on the active
// edges only (Gauss–Newton on the compliance-regularised system, Goldenthal et al. 2007, §4,
// with XPBD's regularisation α, Macklin et al. 2016).
#pragma once

#include "solver/linalg/linear.h"
#include "solver/linalg/types.h"

#include <array>
#include <functional>
#include <vector>

namespace gale::solver {

struct RotationProjectionStats {
    int activeEdges = 0;  // edges beyond their target at the first iteration
    int iterations = 0;   // Gauss–Newton iterations
    int cgIterations = 0; // summed over them
    double excessBefore = 0.0, excessAfter = 0.0; // largest (length − target) / rest
};

// x₁ = x₀ + h (v₀ + Δv) + y; Δv is changed in place. rotations: targets max(L, d̂₀·d₁) (else
// none); stretchLimit > 0 caps every target at stretchLimit × L (strain limiting: with
// rotations off, only the edges beyond the cap are projected). mass: per vertex (kg); the
// constraint constraint filter S limits a vertex's motion (a pin or attachment moves not at all, a
// contact only in its plane); a free one near a collider (hold(i), asked only for the vertices of
// active edges: the collider's normal there, zero when none) only in the plane of that normal.
// tolerance: relative excess (× rest) below which an edge is left alone. caps (m, per edge; may
// be null): every target capped at caps[e] as well (the lengths an edge had before a move that
// stretched it: Body's projection after the continuous sweep); floors (m, per edge; may be null):
// an edge shorter than floors[e] by more than the tolerance is lengthened to it as well.
// late: after the first Gauss–Newton iterations, up to `iterations` more are made while an edge
// is still beyond its target by `excess` × rest (or by 5× the tolerance where that is more).
struct LateIterations {
    double excess = 0.02;
    int iterations = 18;
};
RotationProjectionStats
projectRotationLength(const std::vector<std::array<int, 2>>& edges, const std::vector<double>& rest,
                      const VecX& mass, const Constraints& constraints, const VecX& x0,
                      const VecX& v0, const VecX& y, double h, VecX& dv, double tolerance,
                      const std::function<Vec3(int)>& hold = {}, bool rotations = true,
                      double stretchLimit = 0.0, const std::vector<double>* caps = nullptr,
                      const std::vector<double>* floors = nullptr, const LateIterations& late = {});

} // namespace gale::solver
