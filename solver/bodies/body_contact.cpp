// A body's collider contact inside its substep: the contact planes made at the step's start and
// by the active set after each solve, Coulomb friction implicit in the solve, cloth held against
// cloth, and the push-out after the solve (Baraff & Witkin 1998 §5; docs/solver.md, "Contact").
#include "solver/bodies/body.h"
#include "solver/collider/moving_collider.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

namespace {
// A vertex this close to a collider's offset surface (m) counts as touching it: rounding
// after a projection must not switch the contact off.
constexpr double kContactSlop = 1e-7;
// A vertex touching a collider after a substep starts the next one in contact within this
// fraction of the thickness above it (it lands on the plane during the step).
constexpr double kContactBand = 0.5;
// A sliding contact's friction that changed by less than this fraction asks for no new solve.
constexpr double kFrictionChange = 0.01;
// m/s: the slip speed below which implicit friction holds a sliding contact like a viscous
// stick (IPC's ε_v, Li et al. 2020 §5: the friction force μ λ_n v_t / max(|v_t|, ε_v)); a
// contact sliding slower creeps at most this fast under Coulomb's full force.
constexpr double kSlipFloor = 1e-3;
// passedThrough: a path counts as having gone through a collider once it came within this
// fraction of the thickness of it.
constexpr double kThroughDepth = 0.25;
// A sliding contact on a moving mesh whose vertex ends this fraction of the thickness behind the
// face its path met takes that face's plane (updateContacts).
constexpr double kReplaneDepth = 0.25;
// A projection after the solve smaller than this (m, or m per substep of speed) is rounding.
constexpr double kProjectionSlop = 1e-6;

// Where the path a → b of a vertex first comes within `reach` of a collider that is not a moving
// mesh (an analytic shape, or a static mesh's SDF; all 1-Lipschitz distances: conservative
// advancement, each step the distance still to go, a tenth short of it for the trilinear
// interpolation's slack), in `at`, with the query there in `cp`. False when a is within reach
// already (a vertex that starts inside has only its closest point) or the path never comes that
// close. The closest point to the end of a step can lie on another face than the one the vertex
// came through: a sheet landing flat on a 24 cm box, its vertices 4 cm into the top and 3.7 cm
// from a side, was pushed out of the side and up (the top's edges 1.5–1.8× rest at one substep
// a frame); on a sphere of 10 cm, a vertex 8 cm in was pushed out at its side.
bool pathEntry(const ColliderPose& pose, const Vec3& a, const Vec3& b, double reach, Vec3& at,
               ContactPoint& cp) {
    const double len = (b - a).norm();
    if (!(len > 0.0)) return false;
    double s = 0.0; // m along the path
    for (int it = 0; it < 64; ++it) {
        at = a + (s / len) * (b - a);
        cp = queryCollider(pose, at);
        const double gap = cp.distance - reach;
        if (!(gap > 0.0)) return it > 0;
        if (gap < 0.02 * reach) return true; // on the surface, to 2 % of the thickness
        s += 0.9 * gap;
        if (s >= len) return false;
    }
    return true; // (grazing: close enough, outside)
}

} // namespace

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
    mSweptClear.assign(slots, 0);
    mSweptAt.resize(3 * static_cast<Eigen::Index>(slots));
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
            if (c.friction > 0.0 && i < mSlidOn.size() && i < mSlidRate.size() &&
                mSlidRate[i] > 0.0 && std::isfinite(mSlidRate[i]) &&
                mSlidOn[i] == static_cast<int>(ci)) {
                slide(i, mSlidRate[i] * h);
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
        // (A sphere or capsule thinner than the edges, thinContact: its centre or axis ends are
        // the body vertices, r + ξ the offset; its axis against the edges below.)
        MovingMeshContact* thin = c.moving ? nullptr : thinContact(ci, c, t, h);
        if (thin) thinEdgePlanes(ci, c, pose, thick, nearSurface, t, h);
        MovingMeshContact* mesh = c.moving ? c.moving.get() : thin;
        const std::vector<std::array<int, 3>>* tris = collisionTriangles();
        if (!mesh || !tris) continue;
        const double offset = thin ? thick + c.radius : thick;
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
            if (!mesh->nearestVertex(corners[0], corners[1], corners[2],
                                     reach + (thin ? c.radius : 0.0), p, w, dist, vel) ||
                !(dist > 1e-12))
                continue;
            const Vec3 q = w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2];
            const Vec3 nrm = (q - p) / dist;
            for (int k = 0; k < 3; ++k) {
                const int i = tri[k];
                if (!(w[k] > 0.05) || mConstraints.kind[i] != 0 || nearSurface[i]) continue;
                planeContact(static_cast<size_t>(i), static_cast<int>(ci), nrm,
                             nrm.dot(corners[k] - p), vel, offset, c.friction, t, h);
            }
        }
    }
    applyClothPlanes(t, h);
    if (warm) syncFriction(mV, true);
}

// A sphere's centre or a capsule's axis (collider k, thinner than the edges: thinContact) within
// r + ξ and the contact band of an edge at the substep's start, the edge's end predicted to
// move in: each free end not near the surface itself (its own contact holds it) gets a sliding
// contact on the plane n·x ≥ n·x₀ − (d − r − ξ), d the distance from the axis point p closest to
// the edge to the edge's closest point, n from p towards it, moving with p: the edge's point is
// held r + ξ out, each end no further in than that asks — the resting side of the edge contacts
// that updateContacts makes when a solve's edge reaches the axis (a sheet draped over a rod, held
// from the first solve instead of after it).
void Body::thinEdgePlanes(size_t k, const Collider& c, const ColliderPose& pose, double thick,
                          const std::vector<uint8_t>& nearSurface, double t, double h) {
    const Vec3 a = pose.a, b = c.shape == ColliderShape::Capsule ? pose.b : pose.a;
    const Vec3 va = pose.velA, vb = c.shape == ColliderShape::Capsule ? pose.velB : pose.velA;
    const double reach = c.radius + thick + kContactBand * thick + kContactSlop;
    for (const auto& [i0, i1] : mEdges) {
        const size_t e0 = static_cast<size_t>(i0), e1 = static_cast<size_t>(i1);
        const bool open0 = mConstraints.kind[e0] == 0 && !nearSurface[e0],
                   open1 = mConstraints.kind[e1] == 0 && !nearSurface[e1];
        if (!open0 && !open1) continue;
        const Vec3 x0 = vec3At(mX.data(), e0), x1 = vec3At(mX.data(), e1);
        double s, u;
        const double d2 = contact::segmentSegmentDistance2(x0, x1, a, b, s, u);
        if (!(d2 < reach * reach) || !(d2 > 1e-24)) continue;
        const Vec3 p = a + u * (b - a);
        const Vec3 nrm = (x0 + s * (x1 - x0) - p) / std::sqrt(d2);
        const Vec3 vel = va + u * (vb - va);
        // The edge point's plane (as in updateContacts): its gap, not the end's own.
        for (const size_t i : {e0, e1})
            if ((i == e0 ? open0 : open1) && mConstraints.kind[i] == 0)
                planeContact(i, static_cast<int>(k), nrm, std::sqrt(d2), vel, thick + c.radius,
                             c.friction, t, h);
    }
}

// A sliding contact for free vertex i at the substep's start on the plane `distance` below it
// along `normal`, offset out by `offset` (n·x₁ ≥ n·x − distance + offset), moving at `velocity`,
// when its predicted motion (no constraint) moves it in relative to the plane.
void Body::planeContact(size_t i, int ci, const Vec3& normal, double distance,
                        const Vec3& velocity, double offset, double mu, double t, double h) {
    const Vec3 x = vec3At(mX.data(), i);
    const Vec3 v0 = vec3At(mV.data(), i);
    const double un = (v0 + (h / mMass[i]) * vec3At(mF.data(), i) - velocity).dot(normal);
    if (!(un < 0.0)) return;
    ContactPoint cp;
    cp.normal = normal;
    cp.distance = distance;
    cp.velocity = velocity;
    setContact(i, ci, cp, x, t, offset, t + h, h, mX, mV, v0, false);
    mContactMu[i] = mu;
    mContactImpulse[i] = -un;
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

// Whether vertex i's step x₀ → x₁, relative to collider k (not a moving mesh: its sweep is
// continuous already), came within the thickness on the way although it ends outside: through
// a small collider and out of its far side. At one substep a frame a sheet falling from 1 m
// moves 18 cm a step, more than a 5 cm sphere's diameter, a 3 cm capsule's or a 4 cm plate's
// thickness: it fell through them untouched. The distance is 1-Lipschitz, so a path of length
// L (the vertex's move plus the surface's, at most h × its fastest point) that ends d₁ from
// the collider stays beyond d₁ − L: only paths longer than d₁ − ξ are walked (pathEntry), and
// d₁ comes from the end-pose bound when that proves it (no query). `at` and `cp`: the entry.
bool Body::passedThrough(size_t k, size_t i, const Vec3& xStart, const Vec3& x1, double h,
                         double thick, Vec3& at, ContactPoint& cp) {
    const ColliderPose& pose = mKin.colliders[k].end;
    if (pose.moving) return false;
    const double surface = pose.shape == ColliderShape::Mesh
                               ? 0.0 // a static mesh does not move
                               : h * std::max(pose.velA.norm(), pose.velB.norm());
    const double length = (x1 - xStart).norm() + surface;
    ContactPoint end;
    if (!endPoseQuery(k, i, x1, thick + length, end) || !(end.distance - thick <= length))
        return false;
    // Through means into the collider's skin past a quarter of the thickness: a vertex resting
    // at the thickness whose path grazes it (a static mesh's interpolated distance is not
    // exactly 1-Lipschitz) is the end-pose test's, not this one's. The contact is then made
    // where the path first came within the thickness (or at that depth, when it started within).
    const Vec3 a = xStart + h * end.velocity;
    if (!pathEntry(pose, a, x1, kThroughDepth * thick, at, cp)) return false;
    Vec3 entry;
    ContactPoint entryCp;
    if (pathEntry(pose, a, x1, thick, entry, entryCp)) {
        at = entry;
        cp = entryCp;
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
                slide(i, 0.0);
                ++st.contactSlides;
                ++changes;
            }
        } else if (mu > 0.0) { // sliding: c from this solve's normal impulse and slip
            const double slipN = std::max(slipOf(i, v0), kSlipFloor);
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
    // A contact sliding on a moving mesh holds its vertex on the plane it was made with, which
    // moves with the surface point but does not turn or bend with it: on a head turning fast
    // under hair (8 mm a substep at the scalp) the vertex slid along the plane and ended behind
    // the face its path met, 8.6 mm deep, and the continuous pass after the solve put it back at
    // that point, squashing its segments to 0.81×. Such a contact takes that face's plane
    // instead (a new linearisation of the surface where the vertex went), keeping its friction,
    // and the rounds solve again.
    for (size_t i = 0; i < n; ++i) {
        const int ci = mContactCollider[i];
        if (ci < 0 || static_cast<size_t>(ci) >= mKin.colliders.size() || mConstraints.kind[i] != 2)
            continue;
        const Collider& c = (*env.colliders)[static_cast<size_t>(ci)];
        if (!c.moving) continue;
        const double thick = mKin.colliders[static_cast<size_t>(ci)].thickness;
        const Vec3 v1 = vec3At(v0.data(), i) + vec3At(mDv.data(), i);
        const Vec3 x1 = vec3At(x0.data(), i) + h * v1;
        ContactPoint cp;
        if (!sweptBehind(*c.moving, static_cast<size_t>(ci) * n + i, vec3At(x0.data(), i), x1,
                         thick, true, cp))
            continue;
        const double friction = mFrictionDamping[i];
        const bool inside = mFoundInside[i];
        setContact(i, ci, cp, x1, t1, thick, t1, h, x0, v0, v1, false);
        mContactMu[i] = c.friction;
        if (friction > 0.0) slide(i, friction);
        mFoundInside[i] = inside;
        ++changes;
    }
    for (size_t k = 0; k < mKin.colliders.size(); ++k) {
        const Collider& c = (*env.colliders)[k];
        const double thick = mKin.colliders[k].thickness;
        const int ci = static_cast<int>(k);
        // The contacts this round makes with collider k: every free vertex that ends the solve
        // within its reach, moving in relative to it.
        struct NewContact {
            size_t i;
            ContactPoint cp;
            Vec3 at, v1;  // where cp was queried, the velocity the solve gave
            double depth; // m past the contact plane along its normal at the step's end
        };
        std::vector<NewContact> made;
        for (size_t i = 0; i < n; ++i) {
            if (mConstraints.kind[i] != 0) continue;
            // A contact released in this substep is not made again from its end query (its
            // force pulled: it leaves), only from the moving mesh's continuous test below.
            const bool released = mReleased[i];
            if (released && !c.moving) continue;
            const Vec3 v1 = vec3At(v0.data(), i) + vec3At(mDv.data(), i);
            const Vec3 x1 = vec3At(x0.data(), i) + h * v1;
            ContactPoint cp;
            bool found = !released && endPoseQuery(k, i, x1, thick - kContactSlop, cp) &&
                         cp.distance < thick - kContactSlop;
            // A moving mesh the step's path went through, ending beyond the face it met: the
            // continuous pass's vertex test, the face it met as a plane at the step's end
            // (moving_collider.h, sweptContact), is the contact, so that the solve, not the pass
            // after it, stops the vertex on its side. Asked of
            // - an open surface (MovingMeshContact::openSurface: a cloth the hair meets), whose
            //   unsigned distance there can exceed ξ (the query above misses it);
            // - a vertex released in an earlier round that a later solve carried more than ξ/4
            //   behind the face it met (a head turning into hair whose contact pulled at first):
            //   the pass put it back at the point it met, its slide over the step lost, a segment
            //   squashed to 0.93×. Made again as found inside, it is not released again.
            // A path found clear is not swept again while the rounds leave its end where it was.
            if (!found && c.moving && (released || c.moving->openSurface()))
                found = sweptBehind(*c.moving, k * n + i, vec3At(x0.data(), i), x1, thick, released,
                                    cp);
            Vec3 at = x1;
            const ColliderPose& pose = mKin.colliders[k].end;
            if (!found) {
                // Ending outside, but through the collider on the way (passedThrough).
                ContactPoint entry;
                Vec3 p;
                if (!passedThrough(k, i, vec3At(x0.data(), i), x1, h, thick, p, entry)) continue;
                cp = entry;
                at = p;
                ++st.contactsThrough;
            } else if (!pose.moving) {
                // The plane of the face the step's path came in through, the path relative to
                // the collider (its start moved with the surface there to t + h).
                ContactPoint entry;
                Vec3 p;
                const Vec3 a = vec3At(x0.data(), i) + h * cp.velocity;
                if (pathEntry(pose, a, x1, thick, p, entry)) {
                    cp = entry;
                    at = p;
                }
            }
            if (!((v1 - cp.velocity).dot(cp.normal) < 0.0)) continue;
            made.push_back({i, cp, at, v1, cp.normal.dot(at - x1) - cp.distance + thick});
        }
        // A vertex that ends inside only because an edge neighbour in front of it along the
        // normal (deeper by more than half their rest length: a column of the cloth landing
        // end-on) ends inside too waits a round: held, the neighbour stops it through their edge,
        // and the vertex behind it is then where the solve puts it, not pressed onto the surface
        // beside the first (which folds a sheet landing edge-first flat on the ground, its
        // diagonals stretched to 1.14×; bench/README.md). It is added in a later round if it
        // still ends inside. Only behind a neighbour that gets its contact this round, so that no
        // round is spent on a wait that ends in nothing.
        std::vector<uint8_t> deferred;
        if (mOptions.deferStackedContacts && !c.moving && made.size() > 1) {
            mDeferDepth.assign(n, -INFINITY); // per vertex, its depth past the contact surface
            for (const NewContact& m : made)
                mDeferDepth[m.i] = m.depth;
            for (size_t e = 0; e < mEdges.size(); ++e) {
                const auto [a, b] = mEdges[e];
                const double da = mDeferDepth[static_cast<size_t>(a)],
                             db = mDeferDepth[static_cast<size_t>(b)];
                if (!(da > -INFINITY) || !(db > -INFINITY)) continue;
                const double half = 0.5 * mEdgeRest[e];
                if (deferred.empty()) deferred.assign(n, 0);
                if (da - db > half) deferred[static_cast<size_t>(b)] = 1;
                if (db - da > half) deferred[static_cast<size_t>(a)] = 1;
            }
        }
        for (const NewContact& m : made) {
            ++changes; // a contact made, or one that waits for another round
            if (!deferred.empty() && deferred[m.i]) continue;
            const size_t i = m.i;
            setContact(i, ci, m.cp, m.at, t1, thick, t1, h, x0, v0, m.v1, c.friction > 0.0);
            mContactMu[i] = c.friction;
            mContactImpulse[i] = -(m.v1 - m.cp.velocity).dot(m.cp.normal); // the approach it had
            mFoundInside[i] = 1;
            ++st.contactAdded;
        }
    }
    // Edges against a sphere's centre or a capsule's axis thinner than them (thinContact): a
    // rod between two rows of cloth vertices, which no vertex reaches. An edge whose path in the
    // solve comes within the collider's radius + ξ/2 of the axis (the continuous pass's edge test)
    // gives each of its free ends a sliding contact that keeps the edge's point r + ξ out from the
    // axis point it met, along the normal from the axis to the edge there, moving with it: the
    // solve then holds the edge off the rod (a sheet draped over a 1 cm rod, held only by the pass
    // after the solve, hung at 1.5× rest, its energy pumped in every step).
    for (size_t k = 0; k < mKin.colliders.size() && !mEdges.empty(); ++k) {
        const Collider& c = (*env.colliders)[k];
        MovingMeshContact* thin = c.moving ? nullptr : thinContact(k, c, t, h);
        if (!thin) continue;
        const double thick = mKin.colliders[k].thickness;
        const auto free = [&](int v) {
            return mConstraints.kind[static_cast<size_t>(v)] == 0 &&
                   !mReleased[static_cast<size_t>(v)];
        };
        // Free vertex v, ending the solve at x1 with v1, held on the plane of cp (the edge's or
        // face's point's gap, r + ξ out) if it moves in relative to it: found inside, so that the
        // rounds end.
        const auto hold = [&](int v, const ContactPoint& cp, const Vec3& x1, const Vec3& v1) {
            if (!free(v) || !((v1 - cp.velocity).dot(cp.normal) < 0.0)) return;
            const size_t i = static_cast<size_t>(v);
            setContact(i, static_cast<int>(k), cp, x1, t1, thick + c.radius, t1, h, x0, v0, v1,
                       false);
            mContactMu[i] = c.friction;
            mContactImpulse[i] = -(v1 - cp.velocity).dot(cp.normal);
            mFoundInside[i] = 1;
            ++st.contactAdded;
            ++changes;
        };
        for (const auto& [a, b] : mEdges) {
            if (!free(a) && !free(b)) continue;
            const Vec3 va = vec3At(v0.data(), a) + vec3At(mDv.data(), a),
                       vb = vec3At(v0.data(), b) + vec3At(mDv.data(), b);
            const Vec3 a0 = vec3At(x0.data(), a), b0 = vec3At(x0.data(), b);
            EdgeHit hit;
            if (!thin->edgeContact(a0, a0 + h * va, b0, b0 + h * vb, thick, mThinCandidates, hit))
                continue;
            // Each end's plane is the edge point's: n·x ≥ n·x₁ − g, g = n·(q₁ − p₁) − r − ξ
            // the gap of the edge's point q₁ at the step's end (negative: short of r + ξ), so
            // that neither end moves the point in (not n·x ≥ n·p₁ + r + ξ for each: an end on
            // the rod's flank would be lifted level with its top).
            ContactPoint cp;
            cp.normal = hit.normal;
            cp.velocity = hit.displacement / h;
            const Vec3 q1 = a0 + h * va + hit.sa * (b0 + h * vb - a0 - h * va);
            cp.distance = hit.normal.dot(q1 - hit.body1);
            hold(a, cp, a0 + h * va, va);
            hold(b, cp, b0 + h * vb, vb);
        }
        // Its centre or tips against the triangles the same way (a 1 cm ball shot at a face's
        // centre, where it enters no edge's reach: 1.21× at the impact when the pass after the
        // solve alone pushed the face's corners): the corners that carry the point met (w > 0.05)
        // held so that the point keeps r + ξ from it along the normal from it to the face.
        const std::vector<std::array<int, 3>>* tris = collisionTriangles();
        for (size_t f = 0; tris && f < tris->size(); ++f) {
            const auto& tri = (*tris)[f];
            if (!free(tri[0]) && !free(tri[1]) && !free(tri[2])) continue;
            Vec3 c0[3], c1[3], v1[3];
            for (int j = 0; j < 3; ++j) {
                v1[j] = vec3At(v0.data(), tri[j]) + vec3At(mDv.data(), tri[j]);
                c0[j] = vec3At(x0.data(), tri[j]);
                c1[j] = c0[j] + h * v1[j];
            }
            FaceHit hit;
            if (!thin->faceContact(c0, c1, thick, mThinCandidates, hit)) continue;
            ContactPoint cp;
            cp.normal = -hit.normal; // from the body vertex towards the face
            cp.velocity = (hit.p1 - hit.p0) / h;
            const Vec3 q1 = hit.w[0] * c1[0] + hit.w[1] * c1[1] + hit.w[2] * c1[2];
            cp.distance = cp.normal.dot(q1 - hit.p1);
            for (int j = 0; j < 3; ++j)
                if (hit.w[j] > 0.05) hold(tri[j], cp, c1[j], v1[j]);
        }
    }
    syncFriction(v0, true);
    return changes;
}

// The moving mesh's continuous vertex test (MovingMeshContact::sweptContact) for the path x0 → x1
// of slot (collider, vertex): true when it ends behind the face it met — by more than
// kReplaneDepth ξ when `deep`, at all otherwise — with cp that face's plane at the step's end. An
// end an earlier round of this substep found clear of the same depth, or of any depth for a deep
// ask, is not tested again (mSweptClear: 1 clear of any, 2 of the deep one).
bool Body::sweptBehind(const MovingMeshContact& mesh, size_t slot, const Vec3& x0, const Vec3& x1,
                       double thick, bool deep, ContactPoint& cp) {
    const uint8_t level = deep ? 2 : 1;
    const uint8_t clear = mSweptClear[slot];
    if (clear != 0 && clear <= level && vec3At(mSweptAt.data(), slot) == x1) return false;
    const double depth = deep ? kReplaneDepth * thick : 0.0;
    const bool behind = mesh.sweptContact(x0, x1, thick, cp) && cp.distance < -depth;
    mSweptClear[slot] = behind ? 0 : level;
    vec3At(mSweptAt.data(), slot) = x1;
    return behind;
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

// What slid at the end of the substep's solves (slip above 2 ε_v relative to the surface), on
// which collider and with what friction c/h: the next substep starts it sliding with it
// (contactConstraints). Empty when nothing slid (nothing to copy into snapshots).
void Body::rememberSliding(const VecX& v0, double h) {
    const size_t n = vertexCount();
    mSlidOn.clear();
    mSlidRate.clear();
    for (size_t i = 0; i < n; ++i) {
        if (mContactCollider[i] < 0 || mConstraints.kind[i] != 2 || !(mContactMu[i] > 0.0) ||
            !(mFrictionDamping[i] > 0.0) || !(slipOf(i, v0) > 2.0 * kSlipFloor))
            continue;
        if (mSlidOn.empty()) {
            mSlidOn.assign(n, -1);
            mSlidRate.assign(n, 0.0);
        }
        mSlidOn[i] = mContactCollider[i];
        // The next substep's slip, extrapolated from this one's change (an accelerating slide:
        // c = μ λ_n / slip from this substep's end slip would hold it back in the next, whose
        // rounds then spend themselves catching up — near the stick threshold a slide took 30
        // frames to reach its acceleration): c for the same impulse at the predicted slip.
        const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
        const Vec3 rel0 = vec3At(v0.data(), i) - vec3At(mContactVelocity.data(), i);
        const double slip0 = (rel0 - nrm * rel0.dot(nrm)).norm(), slip1 = slipOf(i, v0);
        const double predicted = slip1 + (slip1 - slip0);
        const double ratio = std::clamp(slip1 / std::max(predicted, kSlipFloor), 0.5, 2.0);
        mSlidRate[i] = mFrictionDamping[i] * ratio / h;
    }
}

// A contact turns to sliding (S = I − nnᵀ, the prescribed change kept along the normal only)
// with friction c (kg; the secant starts afresh).
void Body::slide(size_t i, double c) {
    const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
    Eigen::Map<Vec3> z(mConstraints.z.data() + 3 * i);
    mConstraints.kind[i] = 2;
    z = nrm * z.dot(nrm);
    mFrictionDamping[i] = c;
    mFrictionPrev[2 * i] = mFrictionPrev[2 * i + 1] = 0.0;
}

// m/s: vertex i's slip at the end of the last solve, its velocity relative to its contact's
// surface in the contact plane.
double Body::slipOf(size_t i, const VecX& v0) const {
    const Vec3 nrm = vec3At(mConstraints.normal.data(), i);
    const Vec3 rel =
        vec3At(v0.data(), i) + vec3At(mDv.data(), i) - vec3At(mContactVelocity.data(), i);
    return (rel - nrm * rel.dot(nrm)).norm();
}

} // namespace gale::solver
