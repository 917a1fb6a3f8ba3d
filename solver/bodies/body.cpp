// The linearised backward-Euler substep shared by cloth and hair.
//
// Baraff & Witkin, "Large Steps in Cloth Simulation", SIGGRAPH 1998, eq. (16)–(17):
//   (M + h D + h² K) Δv = h (f₀ − h K v₀),   v₁ = v₀ + Δv,   x₁ = x₀ + h v₁
// with K = −∂f/∂x and D = −∂f/∂v positive semi-definite, so the matrix is SPD. Pins and
// contacts enter through the constraint filter (linear.h). Optional extra Newton iterations
// solve the nonlinear backward-Euler residual r(v₁) = M(v₁ − v₀) − h f(x₀ + h v₁, v₁) with the
// same matrix re-evaluated at the iterate. The wind is sampled once per substep, at x₀.
#include "solver/bodies/body.h"
#include "solver/collider/moving_collider.h"
#include "solver/mesh/mesh_sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace gale::solver {

namespace {
// Flexible GMRES for the skew aerodynamic coupling (solveLinear): Krylov vectors per cycle and
// cycles at most (each vector costs one preconditioning solve).
constexpr int kGmresRestart = 20;
constexpr int kGmresRestarts = 4;
// A vertex this close to a collider's offset surface (m) counts as touching it: rounding
// after a projection must not switch the contact off.
constexpr double kContactSlop = 1e-7;
// Solves of a substep after the first for changes of the contact set (updateContacts).
constexpr int kContactRounds = 8;
// A vertex touching a collider after a substep starts the next one in contact within this
// fraction of the thickness above it (it lands on the plane during the step).
constexpr double kContactBand = 0.5;
// A sliding contact's friction that changed by less than this fraction asks for no new solve.
constexpr double kFrictionChange = 0.01;
// m/s: the slip speed below which implicit friction holds a sliding contact like a viscous
// stick (IPC's ε_v, Li et al. 2020 §5: the friction force μ λ_n v_t / max(|v_t|, ε_v)); a
// contact sliding slower creeps at most this fast under Coulomb's full force.
constexpr double kSlipFloor = 1e-3;
// The PCG residual's absolute floor, as a fraction of the CG tolerance of gravity's impulse over
// the step (substep(), FilteredSolver::setResidualFloor).
constexpr double kResidualFloor = 0.1;
// A projection after the solve smaller than this (m, or m per substep of speed) is rounding.
constexpr double kProjectionSlop = 1e-6;
} // namespace

bool PaintedParam::alwaysZero() const {
    if (!value.isKeyed()) return value.scalarAt(0.0) == 0.0;
    for (const auto& v : value.values())
        if (!v.empty() && v[0] != 0.0) return false;
    return true;
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
    for (size_t e = 0; e < edges.size(); ++e)
        mEdgeRest[e] =
            (vec3At(mRest.data(), edges[e][1]) - vec3At(mRest.data(), edges[e][0])).norm();
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
    VecX f = VecX::Zero(mX.size());
    ForceInput in;
    in.x = mX.data();
    in.v = mV.data();
    in.t = t;
    ForceOutput out;
    out.f = &f;
    addForces(in, out);
    addSoftAttachments(in, out, false);
    return out.elasticEnergy;
}

void Body::attachmentTargets(double t, std::vector<std::pair<int, Vec3>>& out) const {
    out.clear();
    for (size_t k = 0; k < mPinned.size(); ++k)
        if (mPinBinding[k]) out.emplace_back(mPinned[k], pinTarget(k, t));
    for (const SoftAttachment& s : mSoft)
        out.emplace_back(s.vertex, boundPosition(*mPinSets[s.set].attach, *s.binding, t));
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
        mSkewed = out.skewed;
        mAeroPosition = in.aeroPosition && !mAero.empty();
    }
}

// The contact plane of vertex i, made from a query cp of collider `ci` at point p and time tq
// (t or t + h): the vertex must end the step on the offset surface n·x₁ = c, c = n·p − d + ξ
// moved with the surface to t + h. With the gap g = c − n·x₀ − h v_s·n (how far the plane is
// ahead of the vertex moving with the surface):
//   g ≥ 0 (behind the plane: inside, pushed out)  y = n g,  z·n = (v_s − v₀)·n
//   g < 0 (ahead of it, closing in)                y = 0,   z·n = (v_s − v₀)·n + g/h
// y is Baraff & Witkin's position alteration (1998 §5.2, §6: x₁ = x₀ + h v₁ + y; the forces
// see it, contactRhs): a push-out moves the vertex without giving it a speed. A closing vertex
// instead lands on the plane along its own motion during the step (the elastic solve sees that
// motion), and the impact is inelastic: its normal speed ends equal to the surface's
// (landed()). A y along the normal for a closing vertex would move it sideways in the sheet's
// plane on a curved collider, a strain its free neighbours do not share.
// A sticking contact (`stick`) is a full constraint, S = 0: the vertex follows its own motion
// relative to the surface, u = v − v_s (`path`: the vertex's velocity without the contact),
// until it meets the plane, at the fraction s = g/(h u·n) of the step, and then moves with the
// surface: v₁ = v_s + s u over the step (v_s when it is not closing in), and v_s at its end
// (landed()). A sliding one keeps S = I − nnᵀ and gets its friction in the right-hand side
// (updateContacts).
void Body::setContact(size_t i, int ci, const ContactPoint& cp, const Vec3& p, double tq,
                      double thick, double t1, double h, const VecX& xStart, const VecX& vStart,
                      const Vec3& path, bool stick) {
    const Vec3 nrm = cp.normal;
    const double vsn = cp.velocity.dot(nrm);
    const double c = nrm.dot(p) - cp.distance + thick + (t1 - tq) * vsn;
    const Vec3 x0 = vec3At(xStart.data(), i), v0 = vec3At(vStart.data(), i);
    const double gap = c - nrm.dot(x0) - h * vsn;
    const Vec3 u = path - cp.velocity;
    const double un = u.dot(nrm);
    Vec3 vStick = cp.velocity;
    if (gap < 0.0)
        vStick += un < 0.0 && gap > h * un ? Vec3((gap / (h * un)) * u) : Vec3(nrm * (gap / h));
    vec3At(mStickVelocity.data(), i) = vStick;
    const Vec3 z = vStick - v0;
    mConstraints.kind[i] = stick ? 1 : 2;
    vec3At(mConstraints.normal.data(), i) = nrm;
    vec3At(mConstraints.z.data(), i) = stick ? z : Vec3(nrm * z.dot(nrm));
    vec3At(mYPos.data(), i) = nrm * std::max(gap, 0.0);
    vec3At(mFriction.data(), i).setZero();
    mFrictionDamping[i] = 0.0;
    vec3At(mContactVelocity.data(), i) = cp.velocity;
    mContactSpeed[i] = vsn;
    mContactCollider[i] = ci;
    mContactMu[i] = 0.0;
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

void Body::contactConstraints(const Environment& env, double t, double h) {
    const size_t n = vertexCount();
    std::fill(mContactImpulse.begin(), mContactImpulse.end(), 0.0);
    std::fill(mContactCollider.begin(), mContactCollider.end(), -1);
    mReleased.assign(n, 0);
    mFriction.setZero(3 * n);
    mContactVelocity.setZero(3 * n);
    mStickVelocity.setZero(3 * n);
    mContactMu.assign(n, 0.0);
    mFoundInside.assign(n, 0);
    // The last substep's end-pose bounds hold at this one's start if it ended at t (the same
    // pose of every collider: the same time, the same collider list).
    const size_t slots = n * mKin.colliders.size();
    const bool carried = mBoundTime == t && mEndBound.size() == slots;
    mStartBound.swap(mEndBound);
    mStartAt.swap(mEndAt);
    if (!carried) mStartBound.assign(slots, -1.0);
    if (mNearTriangle.size() != slots) mNearTriangle.assign(slots, -1);
    mEndBound.assign(slots, -1.0);
    mEndAt.resize(3 * static_cast<Eigen::Index>(slots));
    mBoundTime = t + h; // the end pose's time, for the next substep
    // A is assembled anew for the substep: no friction in it.
    mFrictionDamping.assign(n, 0.0);
    mFrictionPrev.assign(2 * n, 0.0);
    mFrictionInA.assign(n, 0.0);
    mFrictionAxis.setZero(3 * n);
    if (!env.colliders || env.colliders->empty()) {
        applyClothPlanes(t, h);
        return;
    }
    bool warm = false; // a contact starts with the friction it slid with (syncFriction below)
    if (mSlipMass.size() != n) mSlipMass.assign(n, 0.0);
    for (size_t ci = 0; ci < mKin.colliders.size(); ++ci) {
        const Collider& c = (*env.colliders)[ci];
        const double thick = mKin.colliders[ci].thickness;
        const ColliderPose& pose = mKin.colliders[ci].start;
        // Vertices within 1.5 ξ of this collider's surface (its own contacts decide for them).
        std::vector<uint8_t> nearSurface(n, 0);
        // The band a vertex (and a body vertex near a triangle) is asked about below.
        const double reach = thick + kContactBand * thick + kContactSlop;
        for (size_t i = 0; i < n; ++i) {
            if (mConstraints.kind[i] != 0) continue; // pinned, held, or another collider's
            const Vec3 x = vec3At(mX.data(), i);
            const size_t slot = ci * n + i;
            if (mStartBound[slot] >= 0.0 &&
                (x - vec3At(mStartAt.data(), slot)).norm() < mStartBound[slot] - reach)
                continue; // farther than the band from the surface (1-Lipschitz distance)
            const ContactPoint cp = queryCollider(pose, x, mNearTriangle[slot]);
            mNearTriangle[slot] = cp.triangle;
            nearSurface[i] = cp.distance < reach;
            // Touching at the end of the last substep: within a band above the thickness (a
            // vertex that slid over a curved surface lifts off its tangent plane a little).
            const bool touched = i < mTouching.size() && mTouching[i];
            const double band = touched ? kContactBand * thick + kContactSlop : kContactSlop;
            if (!(cp.distance < thick + band)) continue;
            // Predicted normal speed relative to the surface without the constraint: keep
            // the vertex on the surface only if it would move in (no adhesion). The solve
            // corrects the guess: updateContacts() releases it if its force pulls.
            const Vec3 v0 = vec3At(mV.data(), i);
            const Vec3 pred = v0 + (h / mMass[i]) * vec3At(mF.data(), i) - cp.velocity;
            const double un = pred.dot(cp.normal);
            if (!(un < 0.0)) continue;
            setContact(i, static_cast<int>(ci), cp, x, t, thick, t + h, h, mX, mV, v0,
                       c.friction > 0.0);
            mContactMu[i] = c.friction;
            mContactImpulse[i] = -un;
            // Sliding on this collider at the last substep's end: it starts sliding, with the
            // friction it ended with (the secant rounds then start near their answer, not
            // from a stick and a frictionless slide).
            if (c.friction > 0.0 && i < mSlidOn.size() && mSlidOn[i] == static_cast<int>(ci)) {
                const Vec3 nrm = cp.normal;
                Eigen::Map<Vec3> z(mConstraints.z.data() + 3 * i);
                mConstraints.kind[i] = 2;
                z = nrm * z.dot(nrm);
                mFrictionDamping[i] = mSlidRate[i] * h;
                warm = true;
            } else {
                mSlipMass[i] = 0.0;
            }
        }
        // A moving mesh's vertices against this cloth's triangles: a body vertex within the
        // band of a triangle, its nearest point q = Σ w_k x_k moving in, gives each corner that
        // carries q (w_k > 0.05) and is not itself near the surface (a thin part between
        // vertices: where the corner touches the body, its own contact above holds it) a
        // sliding contact plane (S = I − nnᵀ, friction from the active set) through the body
        // vertex p, offset by the thickness, normal n = (q − p)/|q − p|: n·x_k ≥ n·p + ξ, moving
        // with the vertex. The solve then carries the face and pulls its
        // neighbours along, instead of flattening the tent the continuous pass made each substep
        // (moving_collider.h, the body vertex–cloth triangle pair; on a 1 cm rod held 5 cm into a
        // sheet the largest stretch fell from 2.4–3.1 to 1.14–1.25 at 2 substeps). Not sticking:
        // a hand riding over examples/09's cape would drag its hem (stretch 1.30 against 1.08).
        const std::vector<std::array<int, 3>>* tris = collisionTriangles();
        if (!c.moving || !tris) continue;
        for (const auto& tri : *tris) {
            // No corner could take a contact (each constrained already, or near the surface
            // itself): no query.
            bool open = false;
            for (int k = 0; k < 3; ++k)
                open = open || (mConstraints.kind[tri[k]] == 0 && !nearSurface[tri[k]]);
            if (!open) continue;
            Vec3 corners[3];
            for (int k = 0; k < 3; ++k) corners[k] = vec3At(mX.data(), tri[k]);
            Vec3 p, vel;
            double w[3], dist;
            if (!c.moving->nearestVertex(corners[0], corners[1], corners[2], reach, p, w, dist,
                                         vel) ||
                !(dist > 1e-12))
                continue;
            const Vec3 q = w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2];
            const Vec3 nrm = (q - p) / dist;
            for (int k = 0; k < 3; ++k) {
                const int i = tri[k];
                if (!(w[k] > 0.05) || mConstraints.kind[i] != 0 || nearSurface[i]) continue;
                const Vec3 x = corners[k];
                const Vec3 v0 = vec3At(mV.data(), i);
                const Vec3 pred = v0 + (h / mMass[i]) * vec3At(mF.data(), i) - vel;
                const double un = pred.dot(nrm);
                if (!(un < 0.0)) continue;
                ContactPoint cp;
                cp.normal = nrm;
                cp.distance = nrm.dot(x - p);
                cp.velocity = vel;
                setContact(i, static_cast<int>(ci), cp, x, t, thick, t + h, h, mX, mV, v0,
                           false);
                mContactMu[i] = c.friction;
                mContactImpulse[i] = -un;
            }
        }
    }
    applyClothPlanes(t, h);
    if (warm) syncFriction(mV, true);
}

// Cloth against cloth in the solve (World, WorldSettings::clothContactInSolve): a free vertex
// resting on other cloth at the step's start (ClothContactPlane), predicted to move towards it,
// gets the sliding contact a collider gives (setContact: S = I − nnᵀ, no friction), against the
// plane n·x = n·p + g through the other cloth's point p moving at the pair's centre-of-mass
// velocity u, g its gap there clamped to [0, ξ]: it may slide and leave, not close in. Not pushed
// out to ξ (the pass after the solve eases a resting pair back a quarter of the way a substep):
// pushed here, a pile gained energy each substep. The constraint is released as any contact's
// when its force would pull (updateContacts); its index is one past the colliders (no query).
void Body::applyClothPlanes(double t, double h) {
    const double xi = mCollision.thickness;
    const int index = static_cast<int>(mKin.colliders.size());
    for (const ClothContactPlane& plane : mClothPlanes) {
        const size_t i = static_cast<size_t>(plane.vertex);
        if (i >= vertexCount() || mConstraints.kind[i] != 0) continue;
        const Vec3 x = vec3At(mX.data(), i);
        const Vec3 v0 = vec3At(mV.data(), i);
        const Vec3 pred = v0 + (h / mMass[i]) * vec3At(mF.data(), i) - plane.velocity;
        const double un = pred.dot(plane.normal);
        if (!(un < 0.0) && !plane.closing) continue;
        ContactPoint cp;
        cp.normal = plane.normal;
        cp.distance = plane.normal.dot(x - plane.point);
        if (!(cp.distance >= 0.0)) continue; // beyond it already: the pass's, not pushed here
        cp.velocity = plane.velocity;
        setContact(i, index, cp, x, t, std::min(cp.distance, xi), t + h, h, mX, mV, v0, false);
        mContactMu[i] = 0.0;
        mContactImpulse[i] = std::max(0.0, -un);
    }
    mClothPlanes.clear();
}

bool Body::endPoseQuery(size_t k, size_t i, const Vec3& x, double beyond, ContactPoint& cp) {
    const size_t slot = k * vertexCount() + i;
    const bool known = slot < mEndBound.size() && mEndBound[slot] >= 0.0;
    if (known && (x - vec3At(mEndAt.data(), slot)).norm() < mEndBound[slot] - beyond) return false;
    const ColliderPose& pose = mKin.colliders[k].end;
    const bool hinted = slot < mNearTriangle.size();
    cp = queryCollider(pose, x, hinted ? mNearTriangle[slot] : -1);
    if (hinted) mNearTriangle[slot] = cp.triangle;
    if (slot < mEndBound.size()) {
        // A moving mesh reports nothing (∞) beyond its search radius: that radius is the bound.
        mEndBound[slot] = std::isfinite(cp.distance) ? std::max(cp.distance, 0.0)
                                                     : (pose.moving ? pose.searchRadius : -1.0);
        vec3At(mEndAt.data(), slot) = x;
    }
    return true;
}

// The inelastic impact of the contacts that closed in during the step (setContact): the normal
// speed relative to the surface, which carried the vertex onto the plane, ends at zero.
void Body::landed() {
    for (size_t i = 0; i < vertexCount(); ++i) {
        if (mContactCollider[i] < 0) continue;
        const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
        Eigen::Map<Vec3> v(mV.data() + 3 * i);
        const double removed = v.dot(nrm) - mContactSpeed[i];
        if (mConstraints.kind[i] == 1)
            v = vec3At(mContactVelocity.data(), i); // stuck
        else
            v -= nrm * removed;
        mContactImpulse[i] += std::max(0.0, -removed);
    }
}

// The right-hand side with the contacts: their friction impulses, and the position alteration
// seen by the forces at the end of the step, x₀ + h v₁ + y, so b = h (f₀ − h K v₀) − (hD + h²K)
// y / h (Baraff & Witkin 1998, eq. 18; the damping sees y as the velocity y/h it moves with
// during the step). (A − M) y = (hD + h²K) y.
void Body::contactRhs(double h) {
    mBc = mB;
    bool any = false, anyY = false;
    for (size_t i = 0; i < vertexCount(); ++i)
        if (mContactCollider[i] >= 0) {
            any = true;
            anyY = anyY || vec3At(mYPos.data(), i).squaredNorm() > 0.0;
        }
    if (!any) return;
    mBc += mFriction;
    if (!anyY) return;
    mTmp.resize(mB.size());
    mA.multiply(mYPos.data(), mTmp.data());
    for (size_t i = 0; i < vertexCount(); ++i)
        mTmp.segment<3>(3 * i) -= mMass[i] * mYPos.segment<3>(3 * i);
    mBc -= mTmp / h;
}

// The active set after a solve (Baraff & Witkin 1998 §5.3), from each contact's constraint
// impulse λ = A Δv − b (N·s), normal part λ_n = λ·n:
// - λ_n < 0 (the contact pulls): released, for the rest of the substep (not a contact made
//   because the vertex ended a solve inside);
// - sticking and |λ_t| > μ λ_n (more friction than Coulomb allows): sliding, S = I − nnᵀ, with
//   Coulomb friction implicit in the solve (syncFriction): the friction impulse on the relative
//   tangential velocity at the step's end, −c P (v₁ − v_s), P = I − nnᵀ, with
//   c = μ λ_n / max(|v_t|, ε_v) (kg) lagged from the latest solve (λ_n and the slip |v_t|), so
//   its magnitude is μ λ_n when the slip settles (the lagged friction of Li et al. 2020, §5).
//   c P is a positive semi-definite damping added to A: whatever λ_n is, the friction can slow
//   the slip to zero but never reverse it or add energy (an impulse lagged in b instead can
//   exceed what stops a light vertex by orders of magnitude: hair, 1e-7 kg a vertex, behind
//   a stiff spring's normal impulse);
// - a free vertex that ends the step within a collider's thickness moving in (relative to the
//   surface) gets a contact plane from the query at its end position, at t + h (sticking when
//   the collider has friction).
// Returns the number of changes (each asks for another solve).
int Body::updateContacts(const Environment& env, double t, double h, const VecX& x0, const VecX& v0,
                         SubstepStatus& st) {
    const size_t n = vertexCount();
    // Without colliders, cloth held against cloth (applyClothPlanes) is still released here.
    if ((!env.colliders || env.colliders->empty()) &&
        std::none_of(mContactCollider.begin(), mContactCollider.begin() + n,
                     [](int c) { return c >= 0; }))
        return 0;
    int changes = 0;
    mTmp.resize(3 * n);
    mA.multiply(mDv.data(), mTmp.data());
    mTmp -= mBc;
    for (size_t i = 0; i < n; ++i) {
        if (mContactCollider[i] < 0) continue;
        const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
        const Vec3 lambda = vec3At(mTmp.data(), i);
        const double ln = lambda.dot(nrm); // N·s
        Eigen::Map<Vec3> z(mConstraints.z.data() + 3 * i);
        if (ln < 0.0 && !mFoundInside[i]) {
            mConstraints.kind[i] = 0;
            z.setZero();
            mFrictionDamping[i] = 0.0;
            vec3At(mYPos.data(), i).setZero();
            mContactCollider[i] = -1;
            mContactImpulse[i] = 0.0;
            mReleased[i] = 1;
            ++st.contactReleases;
            ++changes;
            continue;
        }
        const double mu = mContactMu[i];
        if (mConstraints.kind[i] == 1) { // sticking
            const Vec3 lt = lambda - nrm * ln;
            const double ltn = lt.norm();
            if (ltn > mu * ln * (1.0 + 1e-9) && ltn > 0.0) {
                // The first slide is frictionless: its slip bounds the true one from above,
                // and the lagged c = μ λ_n / |v_t| then converges from above (each further
                // solve slows the slip towards Coulomb's; from below, from a resting slip of
                // ε_v, the slip would grow only by tan θ / μ a solve).
                mConstraints.kind[i] = 2;
                z = nrm * z.dot(nrm);
                mFrictionDamping[i] = 0.0;
                mFrictionPrev[2 * i] = mFrictionPrev[2 * i + 1] = 0.0;
                ++st.contactSlides;
                ++changes;
            }
        } else if (mu > 0.0) { // sliding: c from this solve's normal impulse and slip
            const Vec3 rel =
                vec3At(v0.data(), i) + vec3At(mDv.data(), i) - vec3At(mContactVelocity.data(), i);
            const double slipN = std::max((rel - nrm * rel.dot(nrm)).norm(), kSlipFloor);
            const double bound = std::max(mu * ln, 0.0); // Coulomb's impulse (N·s)
            const double now = mFrictionDamping[i];
            double next = bound / slipN; // Picard: the lagged c
            // Secant on the vertex's own response, slip = p / (m + c) through this solve's
            // (c, slip) and the previous one's: c with c·slip(c) = μ λ_n (Aitken's step; the
            // plain lag converges only by the factor μ λ_n / p a solve).
            const double cPrev = mFrictionPrev[2 * i], sPrev = mFrictionPrev[2 * i + 1];
            double m = 0.0;
            if (sPrev > slipN * (1.0 + 1e-6) && now > cPrev) {
                m = (now * slipN - cPrev * sPrev) / (sPrev - slipN);
                if (m > 0.0) mSlipMass[i] = m;
            } else if (sPrev == 0.0 && now > 0.0) {
                // The first solve of a contact that started sliding with the friction it slid
                // with (contactConstraints): one point, the response's mass carried with it.
                m = mSlipMass[i];
            }
            if (m > 0.0) {
                const double p = slipN * (m + now);
                next = p > bound ? bound * m / (p - bound) : bound / kSlipFloor;
            }
            mFrictionPrev[2 * i] = now;
            mFrictionPrev[2 * i + 1] = slipN;
            if (std::abs(next - now) > kFrictionChange * std::max(now, next)) ++changes;
            mFrictionDamping[i] = next;
        }
    }
    const double t1 = t + h;
    for (size_t k = 0; k < mKin.colliders.size(); ++k) {
        const Collider& c = (*env.colliders)[k];
        const double thick = mKin.colliders[k].thickness;
        const int ci = static_cast<int>(k);
        for (size_t i = 0; i < n; ++i) {
            if (mConstraints.kind[i] != 0 || mReleased[i]) continue;
            const Vec3 v1 = vec3At(v0.data(), i) + vec3At(mDv.data(), i);
            const Vec3 x1 = vec3At(x0.data(), i) + h * v1;
            ContactPoint cp;
            bool found = endPoseQuery(k, i, x1, thick - kContactSlop, cp) &&
                         cp.distance < thick - kContactSlop;
            // An open surface (MovingMeshContact::openSurface: a cloth the hair meets) the step's
            // path went through, ending beyond it (its unsigned distance there can exceed ξ: the
            // query above misses it): the continuous pass's vertex test, the face it met as a plane
            // at the step's end (moving_collider.h, sweptContact), is the contact, so that the
            // solve, not the pass after it, stops the vertex on its side.
            if (!found && c.moving && c.moving->openSurface())
                found = c.moving->sweptContact(vec3At(x0.data(), i), x1, thick, cp) &&
                        cp.distance < 0.0;
            if (!found) continue;
            if (!((v1 - cp.velocity).dot(cp.normal) < 0.0)) continue;
            setContact(i, ci, cp, x1, t1, thick, t1, h, x0, v0, v1, c.friction > 0.0);
            mContactMu[i] = c.friction;
            mContactImpulse[i] = -(v1 - cp.velocity).dot(cp.normal); // the approach it had
            mFoundInside[i] = 1;
            ++st.contactAdded;
            ++changes;
        }
    }
    syncFriction(v0, true);
    return changes;
}

// Sliding friction in the implicit system: A_ii += c P and b_i −= c P (v₀ − v_s), P = I − nnᵀ,
// so that (A + cP) Δv = b − c P (v₀ − v_s) puts the friction impulse −c P (v₁ − v_s) on the
// vertex (updateContacts). What an earlier call added is taken out first.
void Body::syncFriction(const VecX& v0, bool keep) {
    for (size_t i = 0; i < vertexCount(); ++i) {
        const double was = mFrictionInA[i];
        const double c = keep && mContactCollider[i] >= 0 && mConstraints.kind[i] == 2
                             ? mFrictionDamping[i]
                             : 0.0;
        if (was == 0.0 && c == 0.0) continue;
        const int slot = mA.diagonalSlot(static_cast<int>(i));
        if (was != 0.0) {
            const Vec3 a = vec3At(mFrictionAxis.data(), i);
            mA.addBlock(slot, Mat3(Mat3::Identity() - a * a.transpose()), -was);
        }
        mFrictionInA[i] = c;
        Eigen::Map<Vec3> rhs(mFriction.data() + 3 * i);
        rhs.setZero();
        if (c == 0.0) continue;
        const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
        const Mat3 tangential = Mat3::Identity() - nrm * nrm.transpose();
        vec3At(mFrictionAxis.data(), i) = nrm;
        mA.addBlock(slot, tangential, c);
        rhs = -c * (tangential * (vec3At(v0.data(), i) - vec3At(mContactVelocity.data(), i)));
    }
}

int Body::resolveContacts(const Environment& env, double h, SubstepStatus& st) {
    if (!env.colliders || env.colliders->empty()) {
        mTouching.clear();
        return 0;
    }
    const size_t n = vertexCount();
    std::vector<uint8_t> touched(n, 0);
    for (size_t ci = 0; ci < mKin.colliders.size(); ++ci) {
        const Collider& c = (*env.colliders)[ci];
        const double thick = mKin.colliders[ci].thickness;
        for (size_t i = 0; i < n; ++i) {
            if (mConstraints.kind[i] == 1 && mContactCollider[i] < 0) continue; // pin or held
            Eigen::Map<Vec3> x(mX.data() + 3 * i);
            const bool held = mContactCollider[i] == static_cast<int>(ci);
            ContactPoint cp;
            if (!endPoseQuery(ci, i, x, held ? INFINITY : thick, cp)) continue;
            if (!std::isfinite(cp.distance)) continue; // a moving mesh found nothing near
            if (!(cp.distance < thick) && !held) continue;
            touched[i] = 1;
            const double push = cp.distance < thick ? thick - cp.distance : 0.0;
            if (push > 0.0) x += push * cp.normal;
            Eigen::Map<Vec3> v(mV.data() + 3 * i);
            Vec3 rel = v - cp.velocity;
            double impulse = mContactImpulse[i]; // m/s removed by the constraint in the solve
            const double vn = rel.dot(cp.normal);
            if (vn < 0.0) {
                rel -= vn * cp.normal;
                impulse += -vn;
            }
            // What the solve left for this projection (reported; none where the solve's
            // contact planes held): a push-out beyond rounding, or an approach speed removed.
            if (push > kProjectionSlop || -vn > kProjectionSlop / h) {
                ++st.projected;
                st.projectedDistance = std::max(st.projectedDistance, push);
                st.projectedSpeed = std::max(st.projectedSpeed, std::max(0.0, -vn));
            }
            // Coulomb friction: the tangential speed drops by at most μ × the normal impulse
            // (a contact of the solve had its friction there).
            const Vec3 vt = rel - rel.dot(cp.normal) * cp.normal;
            const double vtn = vt.norm();
            Vec3 slip = Vec3::Zero();
            if (vtn > 0.0 && !held) {
                const double keep = std::max(0.0, 1.0 - c.friction * impulse / vtn);
                slip = (1.0 - keep) * vt;
                rel -= slip;
            }
            // The position moved with the velocity before friction: take that part back too,
            // so that x₁ = x₀ + h v₁ holds for the tangential motion.
            x -= h * slip;
            v = cp.velocity + rel;
            mContactImpulse[i] = 0.0;
            mContactCollider[i] = -1;
        }
    }
    int count = 0;
    for (uint8_t u : touched) count += u;
    mTouching = std::move(touched);
    return count;
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
        // What slid, and with what friction, for the next substep's start.
        mSlidOn.assign(n, -1);
        mSlidRate.assign(n, 0.0);
        for (size_t i = 0; i < n; ++i) {
            if (mContactCollider[i] < 0 || mConstraints.kind[i] != 2 || !(mContactMu[i] > 0.0) ||
                !(mFrictionDamping[i] > 0.0))
                continue;
            const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
            const Vec3 rel =
                vec3At(v0.data(), i) + vec3At(mDv.data(), i) - vec3At(mContactVelocity.data(), i);
            if (!((rel - nrm * rel.dot(nrm)).norm() > 2.0 * kSlipFloor)) continue;
            mSlidOn[i] = mContactCollider[i];
            mSlidRate[i] = mFrictionDamping[i] / h;
        }
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
        for (const Collider& c : *env.colliders)
            if (c.moving) {
                std::vector<uint8_t> movable(n);
                for (size_t i = 0; i < n; ++i)
                    movable[i] = mConstraints.kind[i] != 1 || mContactCollider[i] >= 0;
                st.projected += c.moving->sweep(x0, mX, mV, movable, mEdges,
                                                tris ? *tris : noTriangles, colliderThickness(c),
                                                c.friction, h);
            }
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

} // namespace gale::solver
