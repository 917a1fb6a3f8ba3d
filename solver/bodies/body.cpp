// The linearised backward-Euler substep shared by cloth and hair.
//
// Baraff & Witkin, "Large Steps in Cloth Simulation", SIGGRAPH 1998, eq. (16)–(17):
//   (M + h D + h² K) Δv = h (f₀ − h K v₀),   v₁ = v₀ + Δv,   x₁ = x₀ + h v₁
// with K = −∂f/∂x and D = −∂f/∂v positive semi-definite, so the matrix is SPD. Pins and
// contacts enter through the constraint filter (linear.h). Optional extra Newton iterations
// solve the nonlinear backward-Euler residual r(v₁) = M(v₁ − v₀) − h f(x₀ + h v₁, v₁) with the
// same matrix re-evaluated at the iterate (body_newton.cpp). The wind is sampled once per
// substep, at x₀.
#include "solver/bodies/body.h"
#include "solver/bodies/rotation_projection.h"
#include "solver/collider/moving_collider.h"
#include "solver/mesh/mesh_sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gale::solver {

namespace {
// Flexible GMRES for the skew aerodynamic coupling (solveLinear): Krylov vectors per cycle and
// cycles at most (each vector costs one preconditioning solve).
constexpr int kGmresRestart = 20;
constexpr int kGmresRestarts = 4;
// Solves of a substep after the first for changes of the contact set (updateContacts).
constexpr int kContactRounds = 8;
// A cloth's rotation projection (without self-collision: Body::projectRotations) goes on past its
// first iterations while an edge is 0.5 % beyond its target (a strand's: the defaults, 2 %,
// rotation_projection.h). At 2 %, sheets dropped on capsules of 3–8 cm ended 1.015–1.019× rest
// where 16 substeps a frame give 1.002–1.003×, the outer edges of their flaps left long by the
// projection, and one landing on a 20° slab 1.044× (16: 1.006×); at 0.5 %, 1.005–1.008× and
// 1.005× (bench/README.md, "The rotation projection's late iterations on cloth").
constexpr LateIterations kClothLate{0.005, 18};
// The PCG residual's absolute floor, as a fraction of the CG tolerance of gravity's impulse over
// the step (substep(), FilteredSolver::setResidualFloor).
constexpr double kResidualFloor = 0.1;
} // namespace

bool PaintedParam::alwaysZero() const {
    if (!value.isKeyed()) return value.scalarAt(0.0) == 0.0;
    for (const auto& v : value.values())
        if (!v.empty() && v[0] != 0.0) return false;
    return true;
}

const char* rotationProjectionName(RotationProjection r) {
    return r == RotationProjection::Off       ? "off"
           : r == RotationProjection::Contact ? "contact"
                                              : "always";
}

const char* troubleName(Trouble t) {
    switch (t) {
    case Trouble::None:
        return "none";
    case Trouble::NonFinite:
        return "non-finite state";
    case Trouble::SolverNotConverged:
        return "linear solver did not converge";
    case Trouble::OverStretch:
        return "over-stretch";
    case Trouble::VelocityJump:
        return "velocity jump";
    }
    return "?";
}

Body::Body(std::string name, const VecX& restPositions)
    : mName(std::move(name)), mX(restPositions), mV(VecX::Zero(restPositions.size())),
      mMass(VecX::Zero(restPositions.size() / 3)), mRest(restPositions) {}

void Body::finishSetup(const std::vector<std::array<int, 2>>& edges) {
    const size_t n = vertexCount();
    mHeld.assign(n, 0);
    for (size_t i = 0; i < n; ++i)
        if (!(mMass[i] > 0.0) || !std::isfinite(mMass[i])) {
            mHeld[i] = 1; // in no element of positive size: nothing moves it, keep it in place
            mMass[i] = 1.0;
        }
    std::vector<std::pair<int, int>> pairs;
    couplings(pairs);
    mA.build(static_cast<int>(n), pairs);
    mEdges = edges;
    mEdgeRest.resize(edges.size());
    mLongestRest = 0.0;
    for (size_t e = 0; e < edges.size(); ++e) {
        mEdgeRest[e] =
            (vec3At(mRest.data(), edges[e][1]) - vec3At(mRest.data(), edges[e][0])).norm();
        mLongestRest = std::max(mLongestRest, mEdgeRest[e]);
    }
    mContactImpulse.assign(n, 0.0);
    mContactCollider.assign(n, -1);
    mContactSpeed.assign(n, 0.0);
}

void Body::addPins(const PinSet& pins) {
    const int set = static_cast<int>(mPinSets.size());
    mPinSets.push_back(pins);
    const bool soft = pins.attach && !pins.attach->triangles().empty() && pins.stiffness > 0.0;
    for (int v : pins.vertices) {
        if (v < 0 || static_cast<size_t>(v) >= vertexCount()) continue;
        if (std::find(mPinned.begin(), mPinned.end(), v) != mPinned.end()) continue;
        if (soft) {
            mSoft.push_back({v, set,
                             std::make_shared<const SurfaceBinding>(bindToSurface(
                                 *pins.attach, vec3At(mX.data(), v), pins.bindTime))});
            continue;
        }
        mPinned.push_back(v);
        mPinSet.push_back(set);
        mPinBinding.push_back(pins.attach && !pins.attach->triangles().empty()
                                  ? std::make_shared<const SurfaceBinding>(bindToSurface(
                                        *pins.attach, vec3At(mX.data(), v), pins.bindTime))
                                  : nullptr);
        const Vec3 p = vec3At(mX.data(), v);
        mAnchor.conservativeResize(mAnchor.size() + 3);
        mAnchor.tail<3>() = p;
    }
}

namespace {
Vec3 translationAt(const fields::Param& p, double t) {
    double d[3] = {0.0, 0.0, 0.0};
    if (p.width() >= 3) p.evaluate(t, d);
    return Vec3(d[0], d[1], d[2]);
}
// The rotation of a PinRotation at t (identity when inactive or about a zero axis).
Mat3 rotationAt(const PinRotation& r, double t) {
    if (!r.active || !(r.axis.norm() > 0.0)) return Mat3::Identity();
    const double rad = r.angle.scalarAt(t) * (M_PI / 180.0);
    return Eigen::AngleAxisd(rad, r.axis.normalized()).toRotationMatrix();
}
} // namespace

Vec3 Body::pinTarget(size_t k, double t) const {
    const PinSet& set = mPinSets[mPinSet[k]];
    if (mPinBinding[k]) return boundPosition(*set.attach, *mPinBinding[k], t);
    const Vec3 anchor = mAnchor.segment<3>(3 * k);
    const Vec3 rotated =
        set.rotate.active
            ? Vec3(set.rotate.pivot + rotationAt(set.rotate, t) * (anchor - set.rotate.pivot))
            : anchor;
    return rotated + translationAt(set.translate, t);
}

Vec3 Body::pinVelocity(size_t k, double t) const {
    const PinSet& set = mPinSets[mPinSet[k]];
    constexpr double d = 1e-6; // s: the right derivative (the motion ahead), exact on linear keys
    if (mPinBinding[k]) return (pinTarget(k, t + d) - pinTarget(k, t)) / d;
    Vec3 v = (translationAt(set.translate, t + d) - translationAt(set.translate, t)) / d;
    if (set.rotate.active && set.rotate.axis.norm() > 0.0) {
        const double omega = (set.rotate.angle.scalarAt(t + d) - set.rotate.angle.scalarAt(t)) / d *
                             (M_PI / 180.0); // rad/s
        const Vec3 r = rotationAt(set.rotate, t) * (mAnchor.segment<3>(3 * k) - set.rotate.pivot);
        v += (omega * set.rotate.axis.normalized()).cross(r);
    }
    return v;
}

void Body::restore(const Snapshot& s) {
    mX = s.x;
    mV = s.v;
    mDvGuess = s.dvGuess;
    mHGuess = s.hGuess;
    mSlidRate = s.slidRate;
    mSlipMass = s.slipMass;
    mSlidOn = s.slidOn;
}

double Body::kineticEnergy() const {
    double e = 0.0;
    for (size_t i = 0; i < vertexCount(); ++i)
        if (!mHeld[i]) e += 0.5 * mMass[i] * vec3At(mV.data(), i).squaredNorm();
    return e;
}

double Body::potentialEnergy(const Vec3& gravity) const {
    double e = 0.0;
    for (size_t i = 0; i < vertexCount(); ++i)
        if (!mHeld[i]) e -= mMass[i] * gravity.dot(vec3At(mX.data(), i));
    return e;
}

double Body::elasticEnergy(double t) {
    // The energy does not depend on the velocities (elasticAt evaluates the forces at rest).
    VecX f;
    return elasticAt(mX, t, f);
}

void Body::attachmentTargets(double t, std::vector<std::pair<int, Vec3>>& out) const {
    out.clear();
    for (size_t k = 0; k < mPinned.size(); ++k)
        if (mPinBinding[k]) out.emplace_back(mPinned[k], pinTarget(k, t));
    for (const SoftAttachment& s : mSoft)
        out.emplace_back(s.vertex, boundPosition(*mPinSets[s.set].attach, *s.binding, t));
}

void Body::attachmentGaps(std::vector<std::pair<int, double>>& out) const {
    out.clear();
    for (size_t k = 0; k < mPinned.size(); ++k)
        if (mPinBinding[k]) out.emplace_back(mPinned[k], mPinBinding[k]->distance);
    for (const SoftAttachment& s : mSoft) out.emplace_back(s.vertex, s.binding->distance);
}

void Body::addSoftAttachments(const ForceInput& in, ForceOutput& out, bool matrix) const {
    const double h = in.h, t = in.t + in.h;
    for (const SoftAttachment& s : mSoft) {
        const PinSet& set = mPinSets[s.set];
        const double k = set.stiffness;
        const Vec3 d = vec3At(in.x, s.vertex) - boundPosition(*set.attach, *s.binding, t);
        out.f->segment<3>(3 * s.vertex) -= k * d;
        out.elasticEnergy += 0.5 * k * d.squaredNorm();
        if (!matrix) continue;
        if (out.kv) out.kv->segment<3>(3 * s.vertex) += k * vec3At(in.v, s.vertex);
        if (out.A) out.A->addDiagonal(out.A->diagonalSlot(s.vertex), h * h * k);
    }
}

double Body::maxEdgeStretch() const {
    return maxEdgeStretchOf(mX);
}

double Body::minEdgeStretch() const {
    double m = mEdges.empty() ? 1.0 : INFINITY;
    for (size_t e = 0; e < mEdges.size(); ++e)
        if (mEdgeRest[e] > 0.0) m = std::min(m, edgeStretchOf(mX, e));
    return std::isfinite(m) ? m : 1.0;
}

double Body::edgeStretchOf(const VecX& x, size_t e) const {
    if (!(mEdgeRest[e] > 0.0)) return 0.0;
    return (vec3At(x.data(), mEdges[e][1]) - vec3At(x.data(), mEdges[e][0])).norm() / mEdgeRest[e];
}

double Body::maxEdgeStretchOf(const VecX& x) const {
    double m = 0.0;
    for (size_t e = 0; e < mEdges.size(); ++e) {
        const double r = edgeStretchOf(x, e);
        if (std::isnan(r)) return r; // a non-finite state is never "not stretched"
        m = std::max(m, r);
    }
    return m;
}

void Body::assemble(const ForceInput& in, ForceOutput& out, const Vec3& gravity, bool withMatrix) {
    const size_t n = vertexCount();
    const bool matrix =
        withMatrix && !mOptions.explicitEuler; // the explicit baseline needs forces only
    if (matrix) mA.setZero();
    mF.setZero(3 * n);
    mKv.setZero(3 * n);
    for (size_t i = 0; i < n; ++i) {
        if (matrix) mA.addDiagonal(mA.diagonalSlot(static_cast<int>(i)), mMass[i]);
        if (!mHeld[i]) mF.segment<3>(3 * i) += mMass[i] * gravity;
    }
    out.f = &mF;
    out.kv = matrix ? &mKv : nullptr;
    out.A = matrix ? &mA : nullptr;
    out.aero = matrix ? &mAero : nullptr;
    out.aeroOrientation = matrix && in.aeroPosition ? &mAeroOrientation : nullptr;
    out.skewed = false;
    if (matrix) mAero.clear();
    addForces(in, out);
    addSoftAttachments(in, out, matrix);
    if (matrix) {
        mAssembledH = in.h;
        mSkewed = out.skewed;
        mAeroPosition = in.aeroPosition && !mAero.empty();
    }
}

MovingMeshContact* Body::thinContact(size_t k, const Collider& c, double t, double h) {
    const bool sphere = c.shape == ColliderShape::Sphere;
    if ((!sphere && c.shape != ColliderShape::Capsule) || c.moving || !(h > 0.0)) return nullptr;
    // Thin: its diameter with the thickness on both sides shorter than the longest rest edge, so
    // that it fits between an edge's two vertices (a thicker one meets a vertex before a face
    // can pass over it; and a draped edge's chord over it dips within ξ/2 of its surface, which
    // the edge test would push out: a sheet dropped on a 3 cm capsule at 2.2 cm spacing ended
    // 1.06× against 1.007× at 16 substeps).
    if (!(2.0 * (c.radius + colliderThickness(c)) < mLongestRest)) return nullptr;
    if (mThinContacts.size() <= k) mThinContacts.resize(k + 1);
    std::shared_ptr<MovingMeshContact>& contact = mThinContacts[k];
    if (contact && contact->t0() == t && contact->t1() == t + h) return contact.get(); // prepared
    const std::vector<std::array<int, 3>> tri{sphere ? std::array<int, 3>{0, 0, 0}
                                                     : std::array<int, 3>{0, 1, 1}};
    // Its two poses, at t and t + h: frame 0 and 1 of a two-frame sequence (frame F at
    // t + F h).
    std::vector<std::vector<double>> frames;
    for (double at : {t, t + h}) {
        const ColliderPose p = colliderPose(c, at);
        frames.push_back({p.a[0], p.a[1], p.a[2]});
        if (!sphere) frames.back().insert(frames.back().end(), {p.b[0], p.b[1], p.b[2]});
    }
    auto seq = std::make_shared<const MeshSequence>(tri, std::move(frames), 0, 1.0 / h, -t / h);
    if (!contact) {
        contact = std::make_shared<MovingMeshContact>(std::move(seq));
        contact->setVertexPairs(false);
        contact->setRadius(c.radius);
    } else {
        contact->setMesh(std::move(seq));
    }
    contact->prepare(t, t + h);
    return contact.get();
}

void Body::evaluateKinematics(const Environment& env, double t, double h) {
    mKin.t0 = t;
    mKin.t1 = t + h;
    // Pins and attachments reach their targets at t + h (backward Euler).
    mKin.pinTargets.resize(mPinned.size());
    for (size_t k = 0; k < mPinned.size(); ++k) mKin.pinTargets[k] = pinTarget(k, mKin.t1);
    mKin.colliders.clear();
    if (!env.colliders) return;
    for (const Collider& c : *env.colliders) {
        ColliderMotion m;
        m.thickness = colliderThickness(c);
        // A moving mesh's tree for the step (moving_collider.h), searched far enough to find
        // the surface a vertex within the thickness of it is moving towards.
        if (c.moving) c.moving->prepare(mKin.t0, mKin.t1);
        m.start = colliderPose(c, mKin.t0);
        m.end = colliderPose(c, mKin.t1);
        if (c.moving) {
            const double search = 2.0 * m.thickness + 1e-3;
            m.start.searchRadius = std::max(m.start.searchRadius, search);
            m.end.searchRadius = std::max(m.end.searchRadius, search);
        }
        mKin.colliders.push_back(m);
    }
}

namespace {
// s = Σ of x over an element's corners (unused corners are −1).
Vec3 cornerSum(const AeroCoupling& c, const VecX& x) {
    Vec3 sum = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
        if (c.v[k] >= 0) sum += x.segment<3>(3 * c.v[k]);
    return sum;
}
} // namespace

void Body::skewProduct(const VecX& x, VecX& y) const {
    y.setZero(x.size());
    for (const AeroCoupling& c : mAero) {
        if (c.v[0] < 0) continue;
        if (mAeroPosition && c.v[2] >= 0) {
            // Newton's full Jacobian: all of ∂F/∂v beyond the damping in A, and the orientation
            // part less its PSD part (which is in A too).
            const AeroOrientation& o = mAeroOrientation[static_cast<size_t>(&c - mAero.data())];
            const Vec3 d0 = x.segment<3>(3 * c.v[0]);
            Vec3 w = o.velocityRest * cornerSum(c, x);
            w += o.position * ((x.segment<3>(3 * c.v[1]) - d0).cross(o.e2) +
                               o.e1.cross(x.segment<3>(3 * c.v[2]) - d0));
            Eigen::Matrix<double, 9, 1> xt;
            for (int k = 0; k < 3; ++k) xt.segment<3>(3 * k) = x.segment<3>(3 * c.v[k]);
            const Eigen::Matrix<double, 9, 1> px = o.psd * xt;
            for (int k = 0; k < 3; ++k) y.segment<3>(3 * c.v[k]) += w - px.segment<3>(3 * k);
            continue;
        }
        const Vec3 w = c.axis.cross(cornerSum(c, x));
        for (int k = 0; k < 3; ++k)
            if (c.v[k] >= 0) y.segment<3>(3 * c.v[k]) += w;
    }
}

double Body::aeroQuadratic(const VecX& x) const {
    double q = 0.0;
    for (const AeroCoupling& c : mAero) {
        if (c.v[0] < 0) continue;
        const Vec3 sum = cornerSum(c, x);
        q += sum.dot(c.damping * sum); // Σ_c x_cᵀ D s = sᵀ D s
    }
    return q;
}

// (H + B) Δv = b with H the assembled SPD matrix and B the skew part of the aerodynamic
// Jacobian (mAero), under the constraint filter: with Δv = y + z (z prescribed, S y = y),
//   S (H + B) S y = S (b − (H + B) z).
// H + B is positive real (its symmetric part H is SPD), so GMRES converges; it is right-
// preconditioned by the symmetric filtered solve itself (multigrid PCG or LDLᵀ on H, to a loose
// tolerance: flexible GMRES, Saad 1993, since a PCG solve is not a fixed linear operator).
// I + H⁻¹B has its eigenvalues on the line 1 + iμ, so few iterations suffice while ‖H⁻¹B‖ is
// moderate. Started from the symmetric solution; if it does not reach the tolerance the step
// keeps the symmetric solve (the skew part explicit, as it was before) and counts a fallback.
SolveStatus Body::solveLinear(const VecX& b, VecX& dv) {
    // A soft attachment stiff enough to own its row's diagonal (h²k ≫ the mass and the cloth's
    // own stiffness there) would own ‖rhs‖ too (its h k d grows with k): PCG is told to weigh
    // that row by its diagonal's share without the spring, w = d/(d + h²k) — the residual as the
    // velocity error it stands for, D⁻¹r, relative to the other rows' — so that it stops on the
    // whole cloth's residual (a 10⁷ N/m attachment otherwise left the cape at 3× rest). Rows
    // without a spring weigh 1: a body without soft attachments solves exactly as before.
    if (!mSoft.empty()) {
        std::vector<double> w(vertexCount(), 1.0);
        const double h2 = mAssembledH * mAssembledH;
        for (const SoftAttachment& s : mSoft) {
            const double spring = h2 * mPinSets[s.set].stiffness;
            const double total = mA.block(mA.diagonalSlot(s.vertex)).trace() / 3.0;
            const double own = std::max(total - spring, 1e-12 * total);
            if (total > 0.0 && std::isfinite(total)) w[s.vertex] = own / total;
        }
        mSolver.setResidualWeights(std::move(w));
    }
    SolveStatus ls = mSolver.solve(mA, mConstraints, b, dv, mOptions.linearSolver,
                                   mOptions.cgTolerance, mOptions.cgMaxIterations);
    if (!(mSkewed || mAeroPosition) || !ls.converged || ls.failed) return ls;
    const long n3 = b.size();
    const auto dot = [&](const VecX& u, const VecX& w) {
        return deterministicDot(u.data(), w.data(), static_cast<size_t>(n3));
    };
    VecX tmp(n3);
    const auto op = [&](const VecX& y, VecX& out) { // out = S (H + B) y
        out.resize(n3);
        mA.multiply(y.data(), out.data());
        skewProduct(y, tmp);
        out += tmp;
        mConstraints.apply(out.data());
    };
    mZeroZ = mConstraints;
    std::fill(mZeroZ.z.begin(), mZeroZ.z.end(), 0.0);
    const VecX z = Eigen::Map<const VecX>(mConstraints.z.data(), n3);
    VecX rhs;
    op(z, rhs);
    VecX sb = b;
    mConstraints.apply(sb.data());
    rhs = sb - rhs;
    const double target =
        std::max(mOptions.cgTolerance * std::sqrt(dot(rhs, rhs)), mResidualFloor);
    VecX y = dv - z;
    const double precTolerance = std::max(mOptions.cgTolerance, 1e-2);
    std::vector<VecX> V(kGmresRestart + 1), Z(kGmresRestart);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(kGmresRestart + 1, kGmresRestart);
    Eigen::VectorXd cs(kGmresRestart), sn(kGmresRestart), g(kGmresRestart + 1);
    VecX r, w;
    bool converged = false, failed = false;
    for (int restart = 0; restart < kGmresRestarts && !converged && !failed; ++restart) {
        op(y, r);
        r = rhs - r;
        const double beta = std::sqrt(dot(r, r));
        if (!std::isfinite(beta)) {
            failed = true;
            break;
        }
        if (beta <= target) {
            converged = true;
            break;
        }
        V[0] = r / beta;
        g.setZero();
        g[0] = beta;
        int k = 0;
        for (int j = 0; j < kGmresRestart; ++j) {
            Z[j].setZero(n3);
            mSolver.setKeepCoarse(true); // the same matrix as the solve above
            mSolver.setResidualFloor(0.0); // V[j] is a unit vector: relative only
            const SolveStatus ps = mSolver.solve(mA, mZeroZ, V[j], Z[j], mOptions.linearSolver,
                                                 precTolerance, mOptions.cgMaxIterations);
            mSolver.setResidualFloor(mResidualFloor);
            mSolver.setKeepCoarse(false);
            ls.iterations += ps.iterations;
            if (ps.failed || !Z[j].allFinite()) {
                failed = true;
                break;
            }
            op(Z[j], w);
            for (int i = 0; i <= j; ++i) { // modified Gram–Schmidt
                H(i, j) = dot(w, V[i]);
                w -= H(i, j) * V[i];
            }
            H(j + 1, j) = std::sqrt(dot(w, w));
            for (int i = 0; i < j; ++i) { // the earlier Givens rotations on column j
                const double t = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
                H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
                H(i, j) = t;
            }
            const double den = std::hypot(H(j, j), H(j + 1, j));
            cs[j] = den > 0.0 ? H(j, j) / den : 1.0;
            sn[j] = den > 0.0 ? H(j + 1, j) / den : 0.0;
            const double hNext = H(j + 1, j);
            H(j, j) = den;
            H(j + 1, j) = 0.0;
            g[j + 1] = -sn[j] * g[j];
            g[j] = cs[j] * g[j];
            k = j + 1;
            if (std::abs(g[j + 1]) <= target) {
                converged = true;
                break;
            }
            if (!(hNext > 0.0)) break; // the Krylov space is invariant: the solution is in it
            V[j + 1] = w / hNext;
        }
        if (failed || k == 0) break;
        // y += Z c with R c = g (R the leading k × k triangle).
        const Eigen::VectorXd c =
            H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
        for (int i = 0; i < k; ++i) y += c[i] * Z[i];
        if (!converged) { // recheck the true residual (an invariant space, or the next restart)
            op(y, r);
            converged = std::sqrt(dot(rhs - r, rhs - r)) <= target;
        }
    }
    // Newton's iterations (mAeroPosition) take GMRES's iterate whenever it beats the start: the
    // symmetric solve is no Newton direction there. The linearised step keeps the fallback.
    bool better = converged;
    if (!converged && mAeroPosition && !failed && y.allFinite()) {
        op(y, r);
        const double after = std::sqrt(dot(rhs - r, rhs - r));
        op(dv - z, r);
        better = after < 0.5 * std::sqrt(dot(rhs - r, rhs - r));
    }
    if (better && y.allFinite()) {
        dv = y + z;
    } else {
        ++ls.skewFallbacks; // dv keeps the symmetric solve
    }
    return ls;
}

SubstepStatus Body::substep(const Environment& env, double t, double h) {
    SubstepStatus st;
    const size_t n = vertexCount();
    const VecX x0 = mX, v0 = mV;
    const double stretchBefore = mEdges.empty() ? 0.0 : maxEdgeStretch();
    mStretchBefore = stretchBefore;
    evaluateKinematics(env, t, h);

    // 1. Wind at the vertices, once per substep, as one batch.
    const bool aero = feelsWind();
    double maxWind = 0.0;
    if (aero) {
        mWind.setZero(3 * n);
        if (env.wind) {
            fields::SampleTime when;
            when.time = t;
            when.fps = env.fps;
            when.frameZero = env.frameZero;
            when.substep = env.substepIndex;
            when.threads = env.threads;
            const fields::SampleStatus ss = env.wind->sample(mX.data(), n, when, mWind.data());
            size_t bad = 0;
            for (size_t i = 0; i < 3 * n; ++i)
                if (!std::isfinite(mWind[i])) {
                    mWind[i] = 0.0;
                    ++bad;
                }
            st.windNonFinite = std::max(ss.nonFinite, bad);
            if (!ss.ok || st.windNonFinite) {
                st.windMessage =
                    ss.message.empty()
                        ? std::to_string(st.windNonFinite) +
                              " wind sample(s) were not finite and were replaced by zero"
                        : ss.message;
                if (st.windNonFinite == 0 && !ss.ok) st.windNonFinite = 1;
            }
        }
        for (size_t i = 0; i < n; ++i) maxWind = std::max(maxWind, vec3At(mWind.data(), i).norm());
    }

    // 2. Forces, K v and the matrix M + hD + h²K at (x₀, v₀).
    ForceInput in;
    in.x = mX.data();
    in.v = mV.data();
    in.wind = aero ? mWind.data() : nullptr;
    in.t = t;
    in.h = h;
    in.airDensity = env.airDensity;
    in.aeroJacobian = mOptions.aeroJacobian;
    ForceOutput out;
    assemble(in, out, env.gravity);
    st.clampedJacobians = out.clamped;
    mB = h * (mF - h * mKv);

    // 3. Constraints: pins reach their target at t + h; held vertices stay; contacts.
    mConstraints.reset(n);
    mYPos.setZero(3 * n);
    double pinSpeed = 0.0;
    for (size_t k = 0; k < mPinned.size(); ++k) {
        const int i = mPinned[k];
        mConstraints.kind[i] = 1;
        const Vec3 vTarget = (mKin.pinTargets[k] - vec3At(x0.data(), i)) / h;
        vec3At(mConstraints.z.data(), i) = vTarget - vec3At(v0.data(), i);
        pinSpeed = std::max(pinSpeed, vTarget.norm());
    }
    for (size_t i = 0; i < n; ++i)
        if (mHeld[i]) {
            mConstraints.kind[i] = 1;
            vec3At(mConstraints.z.data(), i) = -vec3At(v0.data(), i);
        }
    contactConstraints(env, t, h);

    // 4. Solve, warm-started from the previous substep's Δv scaled to this step.
    SolveStatus ls;
    if (mOptions.explicitEuler) {
        // The explicit baseline: Δv = h M⁻¹ f, constrained vertices as prescribed.
        mDv.resize(3 * n);
        for (size_t i = 0; i < n; ++i) {
            Vec3 dv = (h / mMass[i]) * vec3At(mF.data(), i);
            if (mConstraints.kind[i] == 1) {
                dv = vec3At(mConstraints.z.data(), i);
            } else if (mConstraints.kind[i] == 2) {
                const Vec3 nn = vec3At(mConstraints.normal.data(), i);
                dv += nn * (vec3At(mConstraints.z.data(), i).dot(nn) - dv.dot(nn));
            }
            mDv.segment<3>(3 * i) = dv;
        }
        ls.converged = true;
    } else {
        if (mOptions.warmStart && mDvGuess.size() == static_cast<long>(3 * n) && mHGuess > 0.0 &&
            mDvGuess.allFinite())
            mDv = mDvGuess * (h / mHGuess);
        else
            mDv.setZero(3 * n);
        mSolver.setPreconditioner(mOptions.preconditioner);
        // The residual need not go below a tenth of the CG tolerance of gravity's impulse over
        // the step, ‖M g‖ h (N·s; a velocity error of ~tol g h / 10, 4e-5 m/s at 1/24 s): at
        // rest (a sheet lying on a collider: its filtered rhs is round-off) a relative
        // tolerance alone chased noise for ~400 CG iterations a step at 64², ~80 with the
        // floor (bench/README.md, "Collider contact in the solve").
        double m2 = 0.0;
        for (double m : mMass) m2 += m * m;
        mResidualFloor =
            kResidualFloor * mOptions.cgTolerance * std::sqrt(m2) * env.gravity.norm() * h;
        mSolver.setResidualFloor(mResidualFloor);
        mSolver.multigrid().setKind(mOptions.multigrid);
        // The multigrid's near-null space: rigid-body modes about the substep's start positions.
        mSolver.multigrid().setPositions(x0.data(), static_cast<int>(n));
        contactRhs(h);
        ls = solveLinear(mBc, mDv);
        // The contact active set: release what pulls, add what ends the step inside, solve
        // again from the last Δv (at most kContactRounds further solves).
        for (int round = 0; round < kContactRounds && ls.converged && !ls.failed; ++round) {
            if (updateContacts(env, t, h, x0, v0, st) == 0) break;
            contactRhs(h);
            const int before = ls.iterations;
            const double res = ls.residual;
            ls = solveLinear(mBc, mDv);
            ls.iterations += before;
            ls.residual = std::max(ls.residual, res);
            ++st.contactSolves;
        }
        rememberSliding(v0, h);  // for the next substep's start
        syncFriction(v0, false); // A as assembled again (Newton, the next rounds' callers)
    }
    const int clothIndex = static_cast<int>(mKin.colliders.size()); // applyClothPlanes
    for (size_t i = 0; i < n; ++i) {
        if (mContactCollider[i] >= 0) ++st.contactConstraints;
        if (mContactCollider[i] == clothIndex) ++st.clothConstraints;
    }
    st.iterations = ls.iterations;
    st.residual = ls.residual;
    st.converged = ls.converged && !ls.failed;

    if (!mOptions.explicitEuler) st.linearSolves = 1 + st.contactSolves;

    // 5. Newton on the backward-Euler residual, from the linearised solve as the first iterate.
    if (st.converged && !mOptions.explicitEuler && mOptions.newtonIterations > 0)
        newton(env, in, out, x0, v0, h, st);
    // ... or, when the linearised step alone is in trouble by the detector's rules (7.), the
    // retry: Newton from it on the same substep, its line search cutting what over-stretches
    // (Environment::retryNewtonIterations; the SPD iterates: the cut, not convergence, is its job).
    if (st.converged && !mOptions.explicitEuler && mOptions.newtonIterations == 0 &&
        env.retryNewtonIterations > 0) {
        std::string why;
        const Trouble tr = predictedTrouble(x0, v0, mDv, h,
                                            mLimits.velocityJump + 2.0 * (maxWind + pinSpeed), why);
        if (tr != Trouble::None) {
            st.retried = tr;
            st.retryReason = why;
            const bool full = mOptions.newtonFullJacobian;
            mOptions.newtonIterations = env.retryNewtonIterations;
            mOptions.newtonFullJacobian = false;
            mNewtonCgTolerance = env.retryCgTolerance;
            mNewtonKeepCoarse = env.retryKeepCoarse;
            newton(env, in, out, x0, v0, h, st);
            mOptions.newtonIterations = 0;
            mOptions.newtonFullJacobian = full;
            mNewtonCgTolerance = 0.0;
            mNewtonKeepCoarse = false;
        }
    }
    // 5b. The length the linearised step's rotations added, projected out
    // (rotation_projection.h): after the linearised step, or after the retry's few Newton
    // iterates (a cut, not a converged solve: at the wind onset the retry left 16.6 % where the
    // projection leaves 5.6 %), not after Newton the scene asked for.
    // ... and, whatever ran, the strain limit (StepOptions::stretchLimit).
    if (st.converged && !mOptions.explicitEuler) {
        const bool held = st.contactConstraints > st.clothConstraints; // a collider holds a vertex
        const bool rotations =
            (st.newtonIterations == 0 || st.retried != Trouble::None) &&
            (mOptions.rotationProjection == RotationProjection::Always ||
             (mOptions.rotationProjection == RotationProjection::Contact && held));
        if (rotations)
            projectRotations(x0, v0, h, st, true, 0.0,
                             held ? mOptions.rotationTolerance : mOptions.rotationFreeTolerance);
        // The limit apart, on what is left beyond it (the edges beyond the limit alone: the
        // rotation targets of every turned edge at once would keep its Gauss–Newton from
        // converging on a flapping sheet).
        if (mOptions.stretchLimit > 0.0 && !mEdges.empty() &&
            maxEdgeStretchOf(x0 + h * (v0 + mDv) + mYPos) > mOptions.stretchLimit)
            projectRotations(x0, v0, h, st, false, mOptions.stretchLimit,
                             mOptions.rotationTolerance);
    }
    mDvGuess = mDv;
    mHGuess = h;
    mV = v0 + mDv;
    mX = x0 + h * mV + mYPos;
    landed();

    // 6. Colliders: moving meshes first swept continuously over the step (no vertex or edge
    // crosses the surface, no body vertex crosses a cloth triangle: moving_collider.h), then
    // push out, approach speed, Coulomb friction. Hair has no triangles (its segments meet the
    // body's edges).
    if (env.colliders) {
        static const std::vector<std::array<int, 3>> noTriangles;
        const std::vector<std::array<int, 3>>* tris = collisionTriangles();
        // A strand's sweep is followed by relaxSwept (not a cloth's: see there).
        const bool relax = !tris && !mEdges.empty();
        std::vector<uint8_t> movable;
        const auto sweepAll = [&](std::vector<Vec3>* normals) {
            for (size_t k = 0; k < env.colliders->size(); ++k) {
                const Collider& c = (*env.colliders)[k];
                // A sphere or capsule thinner than the edges: its centre or axis, thickened by
                // its radius, against the edges and triangles (the vertices meet it below).
                MovingMeshContact* thin = c.moving ? nullptr : thinContact(k, c, mKin.t0, h);
                MovingMeshContact* mesh = c.moving ? c.moving.get() : thin;
                if (!mesh) continue;
                if (movable.empty()) { // the first sweep of the substep
                    movable.resize(n);
                    for (size_t i = 0; i < n; ++i)
                        movable[i] = mConstraints.kind[i] != 1 || mContactCollider[i] >= 0;
                    if (relax) {
                        mSweepX = mX;
                        mSweepNormals.assign(n, Vec3::Zero());
                    }
                }
                st.projected += mesh->sweep(x0, mX, mV, movable, mEdges, tris ? *tris : noTriangles,
                                            colliderThickness(c), c.friction, h, 4, normals);
            }
        };
        sweepAll(relax ? &mSweepNormals : nullptr);
        // What the sweep stretched, given back; the moves it made swept again (the sweep has
        // the last word: no path crosses a surface).
        if (relax && !movable.empty() && relaxSwept(x0, v0, mSweepX, h, st) > 0) sweepAll(nullptr);
    }
    st.contacts = resolveContacts(env, h, st);

    // 7. Trouble detection.
    double maxSpeed = 0.0, maxJump = 0.0, maxSpeed0 = 0.0;
    bool finite = mX.allFinite() && mV.allFinite();
    if (finite)
        for (size_t i = 0; i < n; ++i) {
            if (mHeld[i]) continue;
            maxSpeed = std::max(maxSpeed, vec3At(mV.data(), i).norm());
            maxSpeed0 = std::max(maxSpeed0, vec3At(v0.data(), i).norm());
            if (mConstraints.kind[i] != 1 || mContactCollider[i] >= 0)
                maxJump = std::max(maxJump, (vec3At(mV.data(), i) - vec3At(v0.data(), i)).norm());
        }
    st.maxSpeed = maxSpeed;
    st.maxStretch = finite && !mEdges.empty() ? maxEdgeStretch() : 0.0;
    mRecoverySpeed = mLimits.velocityJump + 2.0 * (maxWind + pinSpeed); // the world's speed scale
    mRecoveryStretch = std::max(1.1, std::min(stretchBefore, mLimits.overStretch));
    char buf[200];
    if (!finite || ls.failed) {
        st.trouble = Trouble::NonFinite;
        st.reason = !finite ? "positions or velocities became non-finite"
                            : "the linear solve produced non-finite values";
    } else if (!st.converged) {
        st.trouble = Trouble::SolverNotConverged;
        std::snprintf(buf, sizeof buf, "residual %.3g after %d iterations (tolerance %.3g)",
                      st.residual, st.iterations, mOptions.cgTolerance);
        st.reason = buf;
    } else if (st.maxStretch > mLimits.overStretch && st.maxStretch > 1.05 * stretchBefore) {
        st.trouble = Trouble::OverStretch;
        std::snprintf(buf, sizeof buf, "an edge reached %.3g× its rest length (limit %.3g×)",
                      st.maxStretch, mLimits.overStretch);
        st.reason = buf;
    } else {
        const double limit = mRecoverySpeed;
        if (maxJump > limit) {
            st.trouble = Trouble::VelocityJump;
            std::snprintf(buf, sizeof buf,
                          "a vertex changed speed by %.3g m/s in one substep "
                          "(limit %.3g m/s)",
                          maxJump, limit);
            st.reason = buf;
        }
    }
    return st;
}

// The rotation-length projection of the linearised step (rotation_projection.h). A free vertex
// that ends the step within a collider's thickness plus kHoldMargin of it moves only along that
// collider's surface (its tangent plane there), and afterwards back out to the distance it had
// where a curved surface came closer: the projection leaves the push-out after the solve
// nothing to do.
void Body::projectRotations(const VecX& x0, const VecX& v0, double h, SubstepStatus& st,
                            bool rotations, double stretchLimit, double tolerance,
                            const Constraints* constraints, const std::vector<double>* caps,
                            const std::vector<double>* floors) {
    constexpr double kHoldMargin = 0.01; // m
    // Vertex v's end position with velocity change dv.
    const auto endOf = [&](const VecX& dv, size_t v) {
        return Vec3(vec3At(x0.data(), v) + h * (vec3At(v0.data(), v) + vec3At(dv.data(), v)) +
                    vec3At(mYPos.data(), v));
    };
    const auto hold = [&](int i) {
        const size_t v = static_cast<size_t>(i);
        const Vec3 x1 = endOf(mDv, v);
        Vec3 normal = Vec3::Zero();
        double nearest = INFINITY;
        for (size_t k = 0; k < mKin.colliders.size(); ++k) {
            const double reach = mKin.colliders[k].thickness + kHoldMargin;
            ContactPoint cp;
            if (endPoseQuery(k, v, x1, reach, cp) && cp.distance < reach && cp.distance < nearest) {
                nearest = cp.distance;
                normal = cp.normal;
            }
        }
        return normal;
    };
    const VecX dvBefore = mDv;
    // A cloth without self-collision: its projection goes on to kClothLate's 0.5 %, and its
    // vertices held or released by a collider are backed out to the thickness (below). With
    // self-collision the pass after the solve meets what those moves do to the cloth's folds: the
    // storm cape of tests/cli/cape_storm_body.sh had a frame of 4.25× the median's substeps
    // (2.75× without), and with the portable kernels one of 47× (a pass accepted at 1.41× rest,
    // every substep after it halved to the smallest). A strand keeps the defaults.
    const bool lonelyCloth = collisionTriangles() != nullptr && !collision().self;
    const RotationProjectionStats ps =
        projectRotationLength(mEdges, mEdgeRest, mMass, constraints ? *constraints : mConstraints,
                              x0, v0, mYPos, h, mDv, tolerance, hold, rotations, stretchLimit, caps,
                              floors, lonelyCloth ? kClothLate : LateIterations{});
    // Every vertex it moved that a collider's surface came closer to (a curved one under a
    // contact sliding in its plane, or under a vertex moving in the tangent plane of its
    // nearest point): back out along the normal to the distance it had, or to the thickness. A
    // lonely cloth's vertex held by a collider in the solve, or released by the rounds, goes to the
    // thickness even where the step had left it nearer: sliding in the tangent plane of a curved
    // surface it ends inside its thickness by s²/2R, and a released one drifts back into it
    // (0.06–0.08 mm on a 15 cm ball), for the push-out after the solve otherwise. Not against a
    // moving mesh, whose sweep after the solve has the last word there. (Every cloth vertex the
    // projection moved, so backed out, took the storm cape of tests/cli/cape_storm_body.sh to a
    // frame of 8.75× the median's substeps; a strand's held vertex, hair swept by a ball at
    // 1 m/s, from 5 to 26 % stretch.)
    for (size_t v = 0; v < vertexCount() && !mKin.colliders.empty(); ++v) {
        if (vec3At(mDv.data(), v) == vec3At(dvBefore.data(), v)) continue;
        const Vec3 x1 = endOf(dvBefore, v);
        for (size_t k = 0; k < mKin.colliders.size(); ++k) {
            const double thick = mKin.colliders[k].thickness;
            const double reach = thick + kHoldMargin;
            ContactPoint before, after;
            const Vec3 x = endOf(mDv, v);
            if (!endPoseQuery(k, v, x, reach, after) || !(after.distance < thick)) continue;
            const double was = endPoseQuery(k, v, x1, reach, before) ? before.distance : reach;
            const bool toThickness = lonelyCloth && was >= 0.0 && !mKin.colliders[k].end.moving &&
                                     (mContactCollider[v] == static_cast<int>(k) ||
                                      (v < mReleased.size() && mReleased[v]));
            const double floor = toThickness ? thick : std::min(was, thick);
            if (after.distance < floor)
                vec3At(mDv.data(), v) += ((floor - after.distance) / h) * after.normal;
        }
    }
    if (rotations) {
        st.rotationProjected = true;
        st.rotationEdges = ps.activeEdges;
        st.rotationExcess = ps.excessBefore;
    }
    if (stretchLimit > 0.0) st.stretchLimited = true;
}

// A strand's vertex the sweep placed on a moving surface (at the point it met, carried to the
// step's end) can end far from its neighbours, which the solve left where it put them: a hair
// tip caught by a turning head at one substep a frame was left 10 % beyond its rest length, and
// a segment 10 % short. Every segment the sweep lengthened beyond both its length before the
// sweep and its rest length, or shortened below both (by more than the held tolerance), is
// brought back by the same projection (mass-weighted; a swept vertex moves only in the plane of
// its push, a free one near a collider only in its tangent plane, then put back at the
// thickness): the neighbours follow, as an inextensible strand would, and the swept vertex
// slides towards them without undoing its push. The moves become velocity, Δv = Δx/h; the
// caller sweeps them again. Hair on examples/10_hair_turn's head at one substep a frame:
// 10.3 % → 2.6 %. (Holding the swept vertices where the sweep put them left a segment both of
// whose ends were swept at 5.3 %.)
// Not for cloth: it took examples/09_walking_cape's largest stretch from 1.13 to 1.04, but the
// triangles of a sheet pushed ahead of a body vertex then slid off it (a 1 cm rod went through
// without the second sweep), and on randomised scenes with pins and colliders moving metres a
// frame it dragged the sheet after them (one went from 1.5 to 8.8–25× rest).
int Body::relaxSwept(const VecX& x0, const VecX& v0, const VecX& xBefore, double h,
                     SubstepStatus& st) {
    const size_t n = vertexCount();
    const double tol = mOptions.rotationTolerance;
    const auto lengthOf = [&](const VecX& x, size_t e) {
        return (vec3At(x.data(), mEdges[e][1]) - vec3At(x.data(), mEdges[e][0])).norm();
    };
    mSweepCaps.resize(mEdges.size());
    mSweepFloors.resize(mEdges.size());
    bool any = false;
    for (size_t e = 0; e < mEdges.size(); ++e) {
        const double rest = mEdgeRest[e], before = lengthOf(xBefore, e);
        mSweepCaps[e] = std::max(rest, before);
        mSweepFloors[e] = std::min(rest, before);
        if (!(rest > 0.0)) continue;
        const double after = lengthOf(mX, e);
        // A segment the sweep took beyond the over-stretch limit is trouble (the detector's
        // rules, step 7: the substep is done again at half the step), not a length to give
        // back: the neighbours of a vertex dragged a metre by a collider would follow it.
        if (after > mLimits.overStretch * rest) return 0;
        any = any || after > mSweepCaps[e] + tol * rest || after < mSweepFloors[e] - tol * rest;
    }
    if (!any) return 0;
    // A swept vertex moves only in the plane of its push (a contact plane with the push's
    // direction as its normal; held where it already had one): it may slide, not go back.
    mSweepConstraints = mConstraints;
    for (size_t i = 0; i < n; ++i) {
        const Vec3 nrm = mSweepNormals[i];
        if (nrm == Vec3::Zero() || mSweepConstraints.kind[i] == 1) continue;
        mSweepConstraints.kind[i] = mSweepConstraints.kind[i] == 2 ? 1 : 2;
        vec3At(mSweepConstraints.normal.data(), i) = nrm;
    }
    // Δv of the swept state (its velocities apart: the sweep's response stays).
    const VecX dvKeep = mDv;
    mDv = (mX - x0 - mYPos) / h - v0;
    const VecX dvSwept = mDv;
    // (With no rotation targets and no stretch limit it records nothing in st.)
    projectRotations(x0, v0, h, st, false, 0.0, tol, &mSweepConstraints, &mSweepCaps,
                     &mSweepFloors);
    int moved = 0;
    for (size_t i = 0; i < n; ++i) {
        const Vec3 d = vec3At(mDv.data(), i) - vec3At(dvSwept.data(), i);
        if (d == Vec3::Zero()) continue;
        vec3At(mX.data(), i) += h * d;
        vec3At(mV.data(), i) += d;
        ++moved;
    }
    st.sweepRelaxed += moved;
    mDv = dvKeep;
    return moved;
}

} // namespace gale::solver
