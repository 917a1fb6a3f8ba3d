// Newton on a body's backward-Euler step and the recovery of a step in trouble (body.h): the
// residual and the incremental potential its line search decreases, the trouble a linearised
// step predicts, and the strain-limited fallback (Body::recover).
#include "solver/bodies/body.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gale::solver {

double Body::residualAt(const VecX& dv, const VecX& x0, const VecX& v0, double h, ForceInput& in,
                        ForceOutput& out, const Vec3& gravity, bool withMatrix) {
    const size_t n = vertexCount();
    mV = v0 + dv;
    mX = x0 + h * mV + mYPos;
    in.x = mX.data();
    in.v = mV.data();
    assemble(in, out, gravity, withMatrix);
    mG.resize(3 * n);
    double rInf = 0.0, r2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
        Vec3 g = mMass[i] * dv.segment<3>(3 * i) - h * mF.segment<3>(3 * i);
        const uint8_t kind = mConstraints.kind[i];
        if (kind == 1) {
            g.setZero();
        } else if (kind == 2) {
            const Vec3 nn = vec3At(mConstraints.normal.data(), i);
            g -= g.dot(nn) * nn;
        }
        mG.segment<3>(3 * i) = g;
        const double e = (mDiagInv[i] * g).norm(); // m/s
        if (!std::isfinite(e)) return std::numeric_limits<double>::infinity();
        rInf = std::max(rInf, e);
        r2 += e * e;
    }
    mResidual2 = std::sqrt(r2);
    return rInf;
}

Trouble Body::predictedTrouble(const VecX& x0, const VecX& v0, const VecX& dv, double h,
                               double jumpLimit, std::string& reason) const {
    const size_t n = vertexCount();
    const VecX x = x0 + h * (v0 + dv) + mYPos;
    char buf[200];
    const double stretch = mEdges.empty() ? 0.0 : maxEdgeStretchOf(x);
    if (stretch > mLimits.overStretch && stretch > 1.05 * mStretchBefore) {
        std::snprintf(buf, sizeof buf, "an edge would reach %.3g× its rest length (limit %.3g×)",
                      stretch, mLimits.overStretch);
        reason = buf;
        return Trouble::OverStretch;
    }
    double maxJump = 0.0;
    for (size_t i = 0; i < n; ++i)
        if (!mHeld[i] && (mConstraints.kind[i] != 1 || mContactCollider[i] >= 0))
            maxJump = std::max(maxJump, vec3At(dv.data(), i).norm());
    if (maxJump > jumpLimit) {
        std::snprintf(buf, sizeof buf,
                      "a vertex would change speed by %.3g m/s in one substep (limit %.3g m/s)",
                      maxJump, jumpLimit);
        reason = buf;
        return Trouble::VelocityJump;
    }
    return Trouble::None;
}

bool Body::stretchFeasible(const VecX& x) const {
    // The over-stretch detector's rule (substep()): trouble when an edge exceeds the limit and
    // the largest stretch grew by more than 5 %. The line search takes no step into it.
    return maxEdgeStretchOf(x) <= std::max(mLimits.overStretch, 1.05 * mStretchBefore);
}

double Body::elasticAt(const VecX& x, double t, VecX& fEl) {
    fEl.setZero(x.size());
    mZero.setZero(x.size());
    ForceInput in;
    in.x = x.data();
    in.v = mZero.data(); // no velocity: no damping; no wind: no aerodynamics
    in.t = t;
    ForceOutput out;
    out.f = &fEl;
    addForces(in, out);
    addSoftAttachments(in, out, false);
    return out.elasticEnergy;
}

// Newton on the backward-Euler equations in the velocity change Δv = v₁ − v₀ (x₁ = x₀ + h v₁):
//   g(Δv) = M Δv − h f(x₀ + h v₁, v₁) = 0,   filtered by the constraints (S g = 0).
// The first iterate is the linearised solve already in mDv (Baraff & Witkin 1998). Converged when
// every free vertex's velocity error eᵢ = Aᵢᵢ⁻¹ S gᵢ (block-Jacobi estimate, Aᵢᵢ the diagonal
// blocks of A at the substep's start; m/s) is below `newtonTolerance`.
// Otherwise each iteration k solves A_k δ = −g_k, A_k = M + hD + h²K at the iterate (SPD: the
// projected aerodynamic damping, the Gauss–Newton membrane), and takes the longest step
// α ∈ {1, ½, ¼, …} with Armijo's decrease of the incremental potential (Gast et al. 2015) in
// which the non-conservative forces (aerodynamics, Rayleigh damping) are frozen at the iterate:
//   Φ_k(Δv) = ½ Δvᵀ M Δv + E(x₀ + h(v₀ + Δv)) − h G_kᵀ Δv,   G_k = f_k − f_E(x_k)
// (E the elastic energy, f_E = −∇E; gravity is in G_k). ∇Φ_k(Δv_k) = g_k, so δ is a descent
// direction of Φ_k for any SPD A_k, and a step that would over-stretch an edge raises E and is
// cut. A fixed point of the iteration solves the nonlinear equations exactly, aerodynamics
// included. The linearised iterate is checked against Δv = 0 with Φ₀ (forces frozen at x₀, v₀).
void Body::newton(const Environment& env, ForceInput& in, ForceOutput& out, const VecX& x0,
                  const VecX& v0, double h, SubstepStatus& st) {
    constexpr double kArmijo = 1e-4;
    constexpr int kMaxCuts = 10;
    const size_t n = vertexCount();
    const double t1 = in.t;
    mDiagInv.resize(n);
    for (size_t i = 0; i < n; ++i)
        mDiagInv[i] = invertBlockOrScale(mA.block(mA.diagonalSlot(static_cast<int>(i))));
    mF0 = mF; // f(x₀, v₀)
    double rInf = residualAt(mDv, x0, v0, h, in, out, env.gravity, false);
    st.newtonResidual = rInf;
    if (rInf <= mOptions.newtonTolerance) return;

    // Φ along Δv = α d from base Δv_b: inertia exact, E exact, frozen forces G linear.
    auto inertia = [&](const VecX& dv) {
        double e = 0.0;
        for (size_t i = 0; i < n; ++i) e += 0.5 * mMass[i] * dv.segment<3>(3 * i).squaredNorm();
        return e;
    };
    // The aerodynamic force frozen at the base Δv_b decreases as the cloth follows the air: its
    // symmetric damping enters Φ as ½ (Δv − Δv_b)ᵀ hD (Δv − Δv_b) (PSD), so that the line search
    // does not take the frozen force for a constant one.
    auto phi = [&](const VecX& dv, double energy, const VecX& base) {
        return inertia(dv) + energy - h * mGk.dot(dv) + 0.5 * aeroQuadratic(dv - base);
    };

    // The linearised step against Δv = 0, with G₀ = f(x₀, v₀) − f_E(x₀).
    const VecX dvLin = mDv;
    elasticAt(x0, t1, mFel);
    mGk = mF0 - mFel;
    VecX trialX = x0 + h * v0 + mYPos;
    double energy = elasticAt(trialX, t1, mFel);
    VecX dvBase = VecX::Zero(3 * n);
    const double phi0 = phi(dvBase, energy, dvBase);
    double slope = -h * (mFel + mGk).dot(dvLin); // ∇Φ₀(0)·d
    double alpha = 1.0, phiTrial = 0.0;
    VecX fElTrial;
    int cuts = 0;
    for (;; ++cuts) {
        mDv = alpha * dvLin;
        trialX = x0 + h * (v0 + mDv) + mYPos;
        // Feasibility first: a trial the over-stretch rule refuses is cut without its energy
        // (a pass over the edges instead of a force evaluation; the accepted step is the same).
        if (stretchFeasible(trialX)) {
            const double eTrial = elasticAt(trialX, t1, fElTrial);
            phiTrial = phi(mDv, eTrial, dvBase);
            const bool ok =
                slope < 0.0 ? phiTrial <= phi0 + kArmijo * alpha * slope : phiTrial < phi0;
            if (ok && std::isfinite(phiTrial)) {
                energy = eTrial;
                mFel = fElTrial;
                break;
            }
        }
        if (cuts == kMaxCuts) { // no part of the linearised step helps: Newton from Δv = 0
            mDv = dvBase;
            // ... or, when x₀ + h v₀ itself over-stretches (a fast incoming velocity), from
            // the free directions at rest (x₁ = x₀, feasible by the detector's rule) and the
            // constrained ones as prescribed: every later iterate must stay feasible too.
            if (!stretchFeasible(x0 + h * v0 + mYPos)) {
                VecX d = -v0 - dvLin;
                mConstraints.apply(d.data());
                mDv = dvLin + d;
            }
            energy = elasticAt(x0 + h * (v0 + mDv) + mYPos, t1, mFel);
            break;
        }
        alpha *= 0.5;
    }
    st.lineSearchCuts += cuts;

    VecX rhs(3 * n), delta(3 * n);
    std::fill(mConstraints.z.begin(), mConstraints.z.end(), 0.0);
    for (int k = 0;; ++k) {
        // f_k and A_k at the iterate; g_k; G_k = f_k − f_E(x_k) (f_E from the accepted trial).
        in.aeroPosition = mOptions.newtonFullJacobian && k < mOptions.newtonIterations;
        rInf = residualAt(mDv, x0, v0, h, in, out, env.gravity, k < mOptions.newtonIterations);
        in.aeroPosition = false;
        if (rInf <= mOptions.newtonTolerance || k == mOptions.newtonIterations ||
            !std::isfinite(rInf))
            break;
        mGk = mF - mFel;
        rhs = -mG;
        delta.setZero();
        // (Options::newtonKeepCoarse: the linearised step's coarse levels, level 0 refreshed;
        // a retry's keepCoarse: its first solve's.)
        mSolver.setKeepCoarse(mOptions.newtonKeepCoarse || (mNewtonKeepCoarse && k > 0));
        const double tolerance = mOptions.cgTolerance;
        if (mNewtonCgTolerance > 0.0) mOptions.cgTolerance = mNewtonCgTolerance;
        const SolveStatus ns = solveLinear(rhs, delta);
        mOptions.cgTolerance = tolerance;
        mSolver.setKeepCoarse(false);
        ++st.linearSolves;
        st.iterations += ns.iterations;
        st.residual = std::max(st.residual, ns.residual);
        ++st.newtonIterations;
        if (ns.failed || !delta.allFinite()) break;
        dvBase = mDv;
        const double phiBase = phi(dvBase, energy, dvBase);
        const double base2 = mResidual2;
        slope = mG.dot(delta);
        alpha = 1.0;
        bool accepted = false;
        for (cuts = 0; cuts <= kMaxCuts; ++cuts, alpha *= 0.5) {
            mDv = dvBase + alpha * delta;
            trialX = x0 + h * (v0 + mDv) + mYPos;
            if (!stretchFeasible(trialX)) continue; // cut before its energy, as above
            const double eTrial = elasticAt(trialX, t1, fElTrial);
            phiTrial = phi(mDv, eTrial, dvBase);
            bool ok = std::isfinite(phiTrial) &&
                      phiTrial <= phiBase + kArmijo * alpha * std::min(slope, 0.0);
            // With the full Jacobian δ is Newton's direction for the residual itself, which Φ_k
            // (forces frozen) need not see decrease: a step that lowers the residual is progress.
            if (mAeroPosition && std::isfinite(phiTrial) && !ok) {
                residualAt(mDv, x0, v0, h, in, out, env.gravity, false);
                ok = mResidual2 <= (1.0 - kArmijo * alpha) * base2;
            }
            if (ok) {
                energy = eTrial;
                mFel = fElTrial;
                accepted = true;
                break;
            }
        }
        st.lineSearchCuts += std::min(cuts, kMaxCuts);
        if (!accepted) { // no decrease along δ (rounding at convergence): stay
            mDv = dvBase;
            rInf = residualAt(mDv, x0, v0, h, in, out, env.gravity, false);
            break;
        }
    }
    st.newtonResidual = rInf;
    st.newtonStalled = !(rInf <= mOptions.newtonTolerance);
}

int Body::recover(const Snapshot& start, double h) {
    const size_t n = vertexCount();
    const VecX& x0 = start.x;
    const VecX& v0 = start.v;
    if (!mV.allFinite() || !mX.allFinite()) {
        mV = v0;
        mX = x0 + h * v0;
    }
    if (!std::isfinite(mRecoverySpeed)) mRecoverySpeed = mLimits.velocityJump;
    // 1. Speeds capped at the world's speed scale, velocity_jump + 2 (wind + pins) (never the
    // cloth's own, which may be what ran away); pins keep their motion.
    std::vector<uint8_t> fixed(n, 0);
    for (int i : mPinned) fixed[i] = 1;
    for (size_t i = 0; i < n; ++i) {
        if (mHeld[i]) fixed[i] = 1;
        if (fixed[i]) continue;
        Eigen::Map<Vec3> v(mV.data() + 3 * i);
        const double speed = v.norm();
        if (!(speed <= mRecoverySpeed))
            v = std::isfinite(speed) ? Vec3((mRecoverySpeed / speed) * v) : Vec3::Zero();
    }
    for (size_t i = 0; i < n; ++i)
        if (!fixed[i]) mX.segment<3>(3 * i) = x0.segment<3>(3 * i) + h * mV.segment<3>(3 * i);
    // 2. Strain limiting (Provot 1995): each edge longer than s·L₀ shortened to it, the change
    // shared by inverse mass (fixed vertices do not move), Gauss–Seidel over the edges in order.
    int shortened = 0;
    for (int sweep = 0; sweep < 100; ++sweep) {
        int changed = 0;
        for (size_t e = 0; e < mEdges.size(); ++e) {
            const int a = mEdges[e][0], b = mEdges[e][1];
            const double wa = fixed[a] ? 0.0 : 1.0 / mMass[a], wb = fixed[b] ? 0.0 : 1.0 / mMass[b];
            if (wa + wb == 0.0) continue;
            Eigen::Map<Vec3> xa(mX.data() + 3 * a), xb(mX.data() + 3 * b);
            const Vec3 d = xb - xa;
            const double len = d.norm(), cap = mRecoveryStretch * mEdgeRest[e];
            if (!(len > cap * (1.0 + 1e-9)) || !(len > 0.0)) continue;
            const Vec3 corr = ((len - cap) / len) * d;
            xa += (wa / (wa + wb)) * corr;
            xb -= (wb / (wa + wb)) * corr;
            ++changed;
        }
        shortened += changed;
        if (changed == 0) break;
    }
    // 3. Velocities from the corrected positions, x₁ = x₀ + h v₁.
    for (size_t i = 0; i < n; ++i)
        if (!fixed[i]) mV.segment<3>(3 * i) = (mX.segment<3>(3 * i) - x0.segment<3>(3 * i)) / h;
    mDvGuess = mV - v0;
    return shortened;
}

} // namespace gale::solver
