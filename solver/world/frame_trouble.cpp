// Frame-end trouble (frame_trouble.h): the most stretched edge past over_stretch and the deepest
// vertex inside each collider, with what held or pushed them there.
#include "solver/world/frame_trouble.h"
#include "solver/collider/moving_collider.h"

#include <cmath>
#include <cstdio>
#include <queue>

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
    return h == 2 ? "attachment" : h == 3 ? "moving collider touching it" : "pin";
}

// How far the scene pulls its held vertices apart: the largest |x_a − x_b| / d_ab over pairs of
// held vertices (pins, attachments), d_ab their distance along the cloth at rest — the shortest
// path over edges, at least the rest geodesic, so the ratio is a lower bound of the stretch the
// cloth between them must take, whatever the solver does. Dijkstra from up to kSources held
// vertices, spread through them (a trouble frame's diagnosis, not every frame's).
double pullApart(const Body& body, const std::vector<uint8_t>& held, int& va, int& vb) {
    constexpr size_t kSources = 32;
    std::vector<int> H;
    for (size_t i = 0; i < held.size(); ++i)
        if (held[i]) H.push_back(static_cast<int>(i));
    if (H.size() < 2) return 0.0;
    const size_t n = body.vertexCount();
    const VecX& r = body.restPositions();
    const VecX& x = body.positions();
    std::vector<int> start(n + 1, 0), to(2 * body.edges().size());
    std::vector<double> len(to.size());
    for (const auto& e : body.edges()) ++start[e[0] + 1], ++start[e[1] + 1];
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (const auto& e : body.edges()) {
        const double l = (vec3At(r.data(), e[0]) - vec3At(r.data(), e[1])).norm();
        to[fill[e[0]]] = e[1], len[fill[e[0]]++] = l;
        to[fill[e[1]]] = e[0], len[fill[e[1]]++] = l;
    }
    double best = 0.0;
    std::vector<double> d(n);
    using Item = std::pair<double, int>;
    const size_t step = std::max<size_t>(1, H.size() / kSources);
    for (size_t k = 0; k < H.size(); k += step) {
        const int s = H[k];
        std::fill(d.begin(), d.end(), INFINITY);
        std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
        d[s] = 0.0;
        q.push({0.0, s});
        while (!q.empty()) {
            const auto [dist, u] = q.top();
            q.pop();
            if (dist > d[u]) continue;
            if (held[u] && u != s && dist > 0.0) {
                const double ratio = (vec3At(x.data(), u) - vec3At(x.data(), s)).norm() / dist;
                if (ratio > best) best = ratio, va = s, vb = u;
            }
            for (int j = start[u]; j < start[u + 1]; ++j)
                if (dist + len[j] < d[to[j]]) {
                    d[to[j]] = dist + len[j];
                    q.push({d[to[j]], to[j]});
                }
        }
    }
    return best;
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
        int pa = -1, pb = -1;
        // Held for this: pins, attachments, and vertices a moving collider touches (pushed
        // where the collider goes: a ball driven through a sheet pinned at its corners).
        std::vector<uint8_t> pushed = held;
        for (size_t i = 0; i < pushed.size() && !(a && b); ++i) {
            if (pushed[i]) continue;
            const int c = near(static_cast<int>(i));
            if (c < 0) continue;
            const ColliderPose& p = poses[static_cast<size_t>(c)];
            if (p.moving || p.velA.squaredNorm() > 0.0 || p.velB.squaredNorm() > 0.0) pushed[i] = 3;
        }
        const double pulled = a && b ? 0.0 : pullApart(body, pushed, pa, pb);
        if (pulled > overStretch) {
            // Held vertices farther apart than the cloth between them can reach within the limit.
            char buf[224];
            std::snprintf(buf, sizeof buf,
                          "the %s at vertex %d and the %s at vertex %d, %.3g m apart: %.3g× "
                          "their distance along the cloth at rest",
                          holder(pushed[pa]), pa, holder(pushed[pb]), pb,
                          (pos(pa) - pos(pb)).norm(), pulled);
            s.forcedBy = buf;
            s.scene = true;
        } else if (a && b) {
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
    // A moving mesh: when it is closed and prepared for the step ending now, by a ray's parity
    // (MovingMeshContact::insideDepth; its continuous passes keep cloth out, but what moves cloth
    // after them could leave it inside, unseen).
    for (size_t c = 0; c < colliders.size(); ++c) {
        const MovingMeshContact* moving = colliders[c].moving.get();
        if (moving && !(moving->closed() && std::abs(moving->t1() - t) <= 1e-9 * std::max(1.0, t)))
            continue;
        FrameTrouble in;
        in.kind = FrameTrouble::Kind::InsideCollider;
        in.limit = kInsideTolerance;
        bool heldInside = false;
        for (size_t i = 0; i < body.vertexCount(); ++i) {
            const double depth = moving
                                     ? moving->insideDepth(pos(static_cast<int>(i)))
                                     : -queryCollider(poses[c], pos(static_cast<int>(i))).distance;
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
