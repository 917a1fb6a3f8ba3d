// Frame-end trouble (frame_trouble.h): the most stretched edge past over_stretch and the deepest
// vertex inside each collider, with what held or pushed them there.
#include "solver/world/frame_trouble.h"

#include <cmath>
#include <cstdio>

namespace gale::solver {

namespace {

std::string point(const Vec3& p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.4g, %.4g, %.4g)", p.x(), p.y(), p.z());
    return buf;
}

// What holds vertex i: 0 free, 1 a pin, 2 an attachment.
std::vector<uint8_t> heldBy(const Body& body) {
    std::vector<uint8_t> held(body.vertexCount(), 0);
    const std::vector<int>& pinned = body.pinnedVertices();
    for (size_t k = 0; k < pinned.size(); ++k)
        held[static_cast<size_t>(pinned[k])] = body.pinIsAttachment(k) ? 2 : 1;
    return held;
}

const char* holder(uint8_t h) {
    return h == 2 ? "attachment" : "pin";
}

} // namespace

const char* FrameTrouble::kindName() const {
    return kind == Kind::OverStretch ? "over_stretch" : "inside_collider";
}

std::string FrameTrouble::text() const {
    char buf[256];
    if (kind == Kind::OverStretch)
        std::snprintf(buf, sizeof buf,
                      "over-stretched: edge %d-%d at %.3g× its rest length (limit %g×)", vertex,
                      other, amount, limit);
    else
        std::snprintf(buf, sizeof buf, "inside a collider: vertex %d %.3g mm below its surface",
                      vertex, 1e3 * amount);
    std::string s = buf;
    s += " at " + point(position);
    if (count > 1)
        s += " (" + std::to_string(count) +
             (kind == Kind::OverStretch ? " edges past the limit)" : " vertices inside)");
    s += ", forced by " + forcedBy +
         (!scene      ? ""
          : !teleport ? " (the scene's: held vertices cannot follow)"
                      : " (the scene's: no cloth follows a teleport)");
    return s;
}

void findFrameTrouble(const Body& body, const std::vector<Collider>& colliders, double t,
                      double overStretch, std::vector<FrameTrouble>& out, double frameStart) {
    const VecX& x = body.positions();
    const std::vector<uint8_t> held = heldBy(body);
    std::vector<ColliderPose> poses;
    for (const Collider& c : colliders) poses.push_back(colliderPose(c, t));
    auto pos = [&](int i) { return vec3At(x.data(), static_cast<size_t>(i)); };
    // The collider vertex i is in contact with (within twice its thickness), or −1.
    auto near = [&](int i) {
        int best = -1;
        double bestD = 0.0;
        for (size_t c = 0; c < colliders.size(); ++c) {
            const double d = queryCollider(poses[c], pos(i)).distance;
            if (d < 2.0 * colliders[c].thickness + 1e-3 && (best < 0 || d < bestD)) {
                best = static_cast<int>(c);
                bestD = d;
            }
        }
        return best;
    };
    auto colliderName = [&](int c) {
        return "collider '" + (colliders[c].name.empty() ? std::to_string(c) : colliders[c].name) +
               "'";
    };
    // A collider that jumped in this frame (step keys): what it forces is the scene's, said so.
    auto jumped = [&](int c, std::string& forcedBy) {
        double at = 0.0;
        bool ofB = false;
        const double jump =
            colliderStepJump(colliders[static_cast<size_t>(c)], frameStart, t, at, ofB);
        if (!(jump > kTeleportTolerance)) return false;
        char buf[96];
        std::snprintf(buf, sizeof buf, " (it jumped %.3g m at t = %.4g s: step keys)", jump, at);
        forcedBy += buf;
        return true;
    };

    // ---- over-stretch: r_e = |x_j − x_i| / L_e > over_stretch ----
    const auto& edges = body.edges();
    FrameTrouble s;
    s.kind = FrameTrouble::Kind::OverStretch;
    s.limit = overStretch;
    for (size_t e = 0; e < edges.size(); ++e) {
        const double r = body.edgeStretchOf(x, e);
        if (!(r > overStretch)) continue;
        ++s.count;
        if (r > s.amount) {
            s.amount = r;
            s.vertex = edges[e][0];
            s.other = edges[e][1];
        }
    }
    if (s.count > 0) {
        s.position = 0.5 * (pos(s.vertex) + pos(s.other));
        const uint8_t a = held[s.vertex], b = held[s.other];
        if (a && b) {
            s.forcedBy = a == b ? std::string(holder(a)) + "s" : "a pin and an attachment";
            s.scene = true;
        } else if (a || b) {
            s.forcedBy = std::string("the ") + holder(a ? a : b) + " at vertex " +
                         std::to_string(a ? s.vertex : s.other);
        } else {
            int c = -1;
            for (int v : {s.vertex, s.other})
                if (c < 0) c = near(v);
            s.forcedBy = c >= 0 ? colliderName(c) : "the solver";
            if (c >= 0 && jumped(c, s.forcedBy)) s.scene = s.teleport = true;
        }
        out.push_back(s);
    }

    // ---- inside: signed distance below −kInsideTolerance ----
    for (size_t c = 0; c < colliders.size(); ++c) {
        if (colliders[c].moving) continue;
        FrameTrouble in;
        in.kind = FrameTrouble::Kind::InsideCollider;
        in.limit = kInsideTolerance;
        bool heldInside = false;
        for (size_t i = 0; i < body.vertexCount(); ++i) {
            const double depth = -queryCollider(poses[c], pos(static_cast<int>(i))).distance;
            if (!(depth > kInsideTolerance)) continue;
            ++in.count;
            if (depth > in.amount) {
                in.amount = depth;
                in.vertex = static_cast<int>(i);
                heldInside = held[i] != 0;
            }
        }
        if (in.count == 0) continue;
        in.position = pos(in.vertex);
        in.forcedBy = colliderName(static_cast<int>(c));
        if (jumped(static_cast<int>(c), in.forcedBy)) in.scene = in.teleport = true;
        if (heldInside) {
            in.teleport = false; // held there: the held vertices' reason
            in.forcedBy += std::string(" and the ") + holder(held[in.vertex]) + " holding vertex " +
                           std::to_string(in.vertex) + " inside it";
            in.scene = true;
        }
        out.push_back(in);
    }
}

} // namespace gale::solver
