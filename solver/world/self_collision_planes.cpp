// The self-collision pass's contact planes (self_collision.h): the planes that hold cloth
// against the cloth it rests on in the next step's solve (contactPlanes), and those of an
// interval solved again with every pair the pass found (retryPlanes).
#include "solver/world/self_collision.h"

#include "solver/world/self_collision_detail.h"

#include <algorithm>
#include <cmath>

namespace gale::solver {

using namespace self_collision_detail;

namespace {
// Of the planes offered for each vertex, the one it is nearest along its normal (ties: the
// first); none for held vertices nor for a vertex beyond the plane.
class NearestPlanes {
public:
    NearestPlanes(const std::vector<double>& x, const std::vector<double>& invMass)
        : mX(x), mInvMass(invMass), mNearest(invMass.size(), INFINITY), mPlane(invMass.size()) {}
    void offer(int i, const Vec3& nrm, const Vec3& point, const Vec3& velocity,
               bool closing = false) {
        if (mInvMass[i] == 0.0) return;
        const double gap = nrm.dot(Vec3(vec3At(mX.data(), i)) - point);
        // A corner beyond the vertex along n (a tilted face under a vertex near its edge) is not
        // held: its plane would push it back by as much.
        if (!(gap >= 0.0) || !(gap < mNearest[i])) return;
        mNearest[i] = gap;
        mPlane[i] = {i, nrm, point, velocity, closing};
    }
    // Per body (vertex offsets `offset`, body of each vertex `body`), in vertex order.
    std::vector<std::vector<ClothContactPlane>> perBody(const std::vector<int>& body,
                                                        const std::vector<int>& offset) const {
        std::vector<std::vector<ClothContactPlane>> out(offset.size());
        for (size_t i = 0; i < mNearest.size(); ++i) {
            if (!std::isfinite(mNearest[i])) continue;
            ClothContactPlane p = mPlane[i];
            p.vertex = static_cast<int>(i) - offset[body[i]];
            out[body[i]].push_back(p);
        }
        return out;
    }

private:
    const std::vector<double>& mX;
    const std::vector<double>& mInvMass;
    std::vector<double> mNearest;
    std::vector<ClothContactPlane> mPlane;
};
} // namespace

std::vector<int> SelfCollision::bodyOffsets() const {
    std::vector<int> offset;
    for (const Member& m : mBodies) offset.push_back(m.offset);
    return offset;
}

std::vector<std::vector<ClothContactPlane>> SelfCollision::contactPlanes() const {
    // For a pair of vertex v (mass m_v, velocity v_v) and triangle point q = Σ w_k x_k (mass
    // m_t = Σ w_k m_k, velocity v_t = Σ w_k v_k), both sides meet at the centre-of-mass velocity
    // u = (m_v v_v + m_t v_t) / (m_v + m_t), as in an inelastic collision: v gets the plane
    // through q with the pair's normal n, the corners the plane through x_v with −n, both moving
    // at u.
    if (mResting == 0 && mNearVt.empty())
        return std::vector<std::vector<ClothContactPlane>>(mBodies.size());
    NearestPlanes planes(mX1, mInvMass);
    const auto at = [](const std::vector<double>& v, int i) { return Vec3(vec3At(v.data(), i)); };
    for (size_t r = 0; r < mResting + mNearVt.size(); ++r) {
        const Contact& c = r < mResting ? mPassVt[r] : mNearVt[r - mResting];
        const int v = c.pair.v[0];
        // Hair on cloth: the hair meets the cloth in its own solve (World::clothAsColliders),
        // and the cloth is not held against a strand.
        if (!mBodyHasTriangles[mVertexBody[v]]) continue;
        Vec3 q = Vec3::Zero(), vt = Vec3::Zero();
        double mt = 0.0;
        for (int k = 1; k < 4; ++k) {
            const double w = -c.pair.a[k];
            q += w * at(mX1, c.pair.v[k]);
            vt += w * at(mV, c.pair.v[k]);
            mt += w * mMass[c.pair.v[k]];
        }
        const double mv = mMass[v];
        if (!(mv + mt > 0.0)) continue;
        const Vec3 u = (mv * at(mV, v) + mt * vt) / (mv + mt);
        planes.offer(v, c.n, q, u);
        for (int k = 1; k < 4; ++k)
            if (-c.pair.a[k] > 0.3) planes.offer(c.pair.v[k], -c.n, at(mX1, v), u);
    }
    return planes.perBody(mVertexBody, bodyOffsets());
}

std::vector<std::vector<ClothContactPlane>>
SelfCollision::retryPlanes(const std::vector<VecX>& startVelocities) const {
    // The pairs may start far apart (up to a step's approach), so each gets one plane between
    // its sides, not the other side's point (both sides could then travel into the gap and pass
    // each other), with the face's normal n (the pair's own may lean, from an edge):
    // - The plane moves at the velocity u of the contact's cluster (the pairs joined by shared
    //   vertices): its centre-of-mass velocity at the step's start, or a held vertex's. A
    //   pair's own centre of mass would have a light corner of one sheet carry the whole
    //   momentum of the other's face, and the planes of one cluster disagree.
    // - It starts where the sides, closing on it at their speeds relative to u, reach it
    //   together: c = x_v + s (q − x_v), s = (v_v − u)·(−n) / ((v_v − v_t)·(−n)) clamped to
    //   [0, 1] (the mass share m_t / (m_v + m_t) for a pair not closing; 0 or 1 with a held
    //   side).
    // - Each side is held ξ/2 off it (ξ when the other side is held): the pair ends ξ apart.
    std::vector<Contact> pairs = mPassVt;
    const size_t vtCount = pairs.size();
    pairs.insert(pairs.end(), mPassEe.begin(), mPassEe.end());
    if (pairs.empty()) return std::vector<std::vector<ClothContactPlane>>(mBodies.size());
    const size_t n = mVertexBody.size();
    std::vector<double> vel(3 * n);
    for (size_t b = 0; b < mBodies.size(); ++b)
        std::copy(startVelocities[b].data(), startVelocities[b].data() + startVelocities[b].size(),
                  vel.begin() + 3 * mBodies[b].offset);
    const auto at = [](const std::vector<double>& v, int i) { return Vec3(vec3At(v.data(), i)); };
    // The clusters, and each one's velocity.
    DisjointSets sets(n);
    std::vector<uint8_t> in(n, 0);
    for (const Contact& c : pairs)
        for (int k = 0; k < 4; ++k) {
            if (c.pair.a[k] == 0.0) continue;
            in[c.pair.v[k]] = 1;
            sets.join(c.pair.v[0], c.pair.v[k]);
        }
    std::vector<double> mass(n, 0.0), heldCount(n, 0.0);
    std::vector<Vec3> momentum(n, Vec3::Zero()), heldVelocity(n, Vec3::Zero());
    for (size_t i = 0; i < n; ++i) {
        if (!in[i]) continue;
        const int r = sets.find(static_cast<int>(i));
        if (mInvMass[i] == 0.0) {
            heldCount[r] += 1.0;
            heldVelocity[r] += at(vel, static_cast<int>(i));
        } else {
            mass[r] += mMass[i];
            momentum[r] += mMass[i] * at(vel, static_cast<int>(i));
        }
    }
    const auto clusterVelocity = [&](int i) -> Vec3 {
        const int r = sets.find(i);
        if (heldCount[r] > 0.0) return heldVelocity[r] / heldCount[r];
        return mass[r] > 0.0 ? Vec3(momentum[r] / mass[r]) : Vec3(Vec3::Zero());
    };
    NearestPlanes planes(mX0, mInvMass);
    for (size_t ci = 0; ci < pairs.size(); ++ci) {
        const Contact& c = pairs[ci];
        // Hair on cloth: the hair meets the cloth in its own solve (contactPlanes).
        if (!mBodyHasTriangles[mVertexBody[c.pair.v[0]]] ||
            !mBodyHasTriangles[mVertexBody[c.pair.v[3]]])
            continue;
        // The two sides: weights α_k > 0 (the vertex, or the first edge's point) and α_k < 0
        // (the face's point, or the second edge's); their points, velocities and masses.
        Vec3 p[2] = {Vec3::Zero(), Vec3::Zero()}, v[2] = {Vec3::Zero(), Vec3::Zero()};
        double m[2] = {0.0, 0.0}, w[2] = {0.0, 0.0};
        bool held[2] = {false, false};
        for (int k = 0; k < 4; ++k) {
            const int side = c.pair.a[k] > 0.0 ? 0 : 1;
            const double wk = std::abs(c.pair.a[k]);
            const int i = c.pair.v[k];
            p[side] += wk * at(mX0, i);
            v[side] += wk * at(vel, i);
            m[side] += wk * mMass[i];
            w[side] += wk;
            held[side] = held[side] || (wk > 0.0 && mInvMass[i] == 0.0);
        }
        if ((held[0] && held[1]) || !(w[0] > 0.0 && w[1] > 0.0) || !(m[0] + m[1] > 0.0)) continue;
        // The normal: a vertex–triangle pair's face's (on the vertex's side), an edge pair's own.
        Vec3 nrm = c.n;
        if (ci < vtCount) {
            const Vec3 face = (at(mX0, c.pair.v[2]) - at(mX0, c.pair.v[1]))
                                  .cross(at(mX0, c.pair.v[3]) - at(mX0, c.pair.v[1]));
            if (face.norm() > 0.0) nrm = face.normalized() * (face.dot(c.n) < 0.0 ? -1.0 : 1.0);
        }
        const Vec3 u = clusterVelocity(c.pair.v[0]);
        const Vec3 va = v[0] / w[0], vb = v[1] / w[1];
        const double closing = -(va - vb).dot(nrm);
        double s = m[1] / (m[0] + m[1]); // the first side's share of the gap
        if (held[0])
            s = 0.0;
        else if (held[1])
            s = 1.0;
        else if (closing > 0.0)
            s = std::clamp(-(va - u).dot(nrm) / closing, 0.0, 1.0);
        const Vec3 centre = p[0] + s * (p[1] - p[0]);
        const double xi = pairThickness(c.pair);
        for (int k = 0; k < 4; ++k) {
            const int side = c.pair.a[k] > 0.0 ? 0 : 1;
            if (!(std::abs(c.pair.a[k]) > 0.3)) continue;
            const double sign = side == 0 ? 1.0 : -1.0;
            const double off = held[1 - side] ? xi : 0.5 * xi;
            planes.offer(c.pair.v[k], sign * nrm, centre - sign * off * nrm, u, true);
        }
    }
    return planes.perBody(mVertexBody, bodyOffsets());
}

} // namespace gale::solver
