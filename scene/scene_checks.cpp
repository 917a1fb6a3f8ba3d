// Run warnings of a scene (scene_checks.h): sequence coverage, units and reach of colliders.
#include "scene/scene_checks.h"

#include "io/frame_pattern.h"

#include "solver/collider/mesh_collider.h"
#include "solver/collider/moving_collider.h"
#include "solver/world/frame_trouble.h"
#include "solver/world/self_collision.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

namespace gale::scene {

using solver::Vec3;

namespace {

// How far the body may stretch or compress an attached edge before runWarnings says so.
constexpr double kBindingLimit = 0.10;
// How far from the body's surface an attached vertex may be bound before runWarnings says so:
// the larger of kBindGapFloor (m) and kBindGapShare of the cloth's (or hair's) extent.
constexpr double kBindGapFloor = 0.05;
constexpr double kBindGapShare = 0.25;
// How deep inside a collider a pin may hold a vertex before runWarnings says so (m).
constexpr double kPinDepth = 0.01;

struct Box {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
    void add(const Vec3& p) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    void add(const Box& b) {
        lo = lo.cwiseMin(b.lo);
        hi = hi.cwiseMax(b.hi);
    }
    bool empty() const { return !(lo.x() <= hi.x()); }
    double extent() const { return empty() ? 0.0 : (hi - lo).norm(); }
    // The gap between two boxes (0 when they overlap).
    double gap(const Box& b) const { return (lo - b.hi).cwiseMax(b.lo - hi).cwiseMax(0.0).norm(); }
};

Box boxOf(const std::vector<double>& xyz) {
    Box b;
    for (size_t i = 0; i + 2 < xyz.size(); i += 3) b.add(Vec3(xyz[i], xyz[i + 1], xyz[i + 2]));
    return b;
}

std::string metres(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

// Where a collider's surface can be over the run: every frame of a sequence, or an analytic
// shape at the run's start (an empty box for planes and static meshes: not looked at).
// The box a collider covers: a sequence's over all its frames (where it goes), a static mesh's
// bounds, an analytic shape's at t0. `size`, when given: how large the body itself is (a
// sequence's largest box of one frame, not the ground it covers walking).
Box colliderBox(const solver::Collider& c, double t0, double* size = nullptr) {
    Box b;
    if (size) *size = 0.0;
    if (c.moving) {
        const solver::MeshSequence& seq = c.moving->mesh();
        std::vector<double> x;
        for (long f = seq.firstFrame(); f <= seq.lastFrame(); ++f) {
            seq.positionsAt(seq.frameTime(static_cast<double>(f)), x);
            const Box frame = boxOf(x);
            if (size) *size = std::max(*size, frame.extent());
            b.add(frame);
        }
        return b;
    }
    if (c.mesh) {
        const std::array<double, 6>& m = c.mesh->sdf().meshBounds();
        b.add(Vec3(m[0], m[1], m[2]));
        b.add(Vec3(m[3], m[4], m[5]));
        if (size) *size = b.extent();
        return b;
    }
    if (c.shape == solver::ColliderShape::Sphere || c.shape == solver::ColliderShape::Capsule) {
        const solver::ColliderPose p = solver::colliderPose(c, t0);
        const Vec3 r = Vec3::Constant(c.radius);
        b.add(p.a - r);
        b.add(p.a + r);
        if (c.shape == solver::ColliderShape::Capsule) {
            b.add(p.b - r);
            b.add(p.b + r);
        }
        if (size) *size = b.extent();
    }
    return b;
}

} // namespace

std::vector<SceneError> runWarnings(const SimScene& scene,
                                    const std::vector<std::unique_ptr<solver::Body>>& bodies,
                                    int first, int last) {
    std::vector<SceneError> out;
    const fields::SceneSettings& s = scene.wind.settings;
    // A warning at a key's line and column; warn(c, ...) at a collider's.
    const auto warnAt = [&](int line, int col, std::string message) {
        SceneError e = sceneErrorAt(scene.wind.path, line, col, std::move(message));
        e.warning = true;
        out.push_back(std::move(e));
    };
    const auto warn = [&](const solver::Collider& c, std::string message) {
        warnAt(c.line, c.col, std::move(message));
    };
    Box cloth;
    double clothExtent = 0.0;
    std::vector<Box> bodyBoxes;
    std::vector<std::pair<int, solver::Vec3>> bound;
    for (const auto& b : bodies) {
        std::vector<double> x(b->positions().data(), b->positions().data() + b->positions().size());
        bodyBoxes.push_back(boxOf(x));
        clothExtent = std::max(clothExtent, bodyBoxes.back().extent());
        // Attached cloth is where its body is at the first frame (a cape modelled on the rest
        // pose, carried there by the pre-roll): a body it is attached to is near it.
        b->attachmentTargets(s.frameTime(first), bound);
        for (const auto& [v, p] : bound) bodyBoxes.back().add(p);
        cloth.add(bodyBoxes.back());
    }
    // The longest edge at rest of any cloth (m): what a thin static mesh is measured against.
    double longestClothEdge = 0.0;
    for (size_t i = 0; i < scene.cloths.size() && i < bodies.size(); ++i) {
        const solver::VecX& rest = bodies[i]->restPositions();
        for (const auto& [a, b] : bodies[i]->edges())
            longestClothEdge = std::max(longestClothEdge,
                                        (rest.segment<3>(3 * a) - rest.segment<3>(3 * b)).norm());
    }
    // A selection that holds nothing (a box beside the cloth, a map that is zero everywhere).
    const auto heldBy = [](const solver::Body& body, bool attachments) {
        size_t n = 0;
        for (const solver::PinSet& set : body.pinSets())
            if ((set.attach != nullptr) == attachments) n += set.vertices.size();
        return n;
    };
    for (size_t i = 0; i < scene.cloths.size() && i < bodies.size(); ++i) {
        const ClothSpec& spec = scene.cloths[i];
        const std::string what = "[[cloth]] '" + spec.name + "'";
        if (spec.hasPins && heldBy(*bodies[i], false) == 0)
            out.push_back(specError(
                scene.wind.path, spec.pins,
                what + " pins: they select no vertex: check the box, vertices or map", true));
        if (spec.hasAttach && heldBy(*bodies[i], true) == 0)
            out.push_back(specError(
                scene.wind.path, spec.attach,
                what + " attach: it selects no vertex: check the box, vertices or map", true));
    }
    for (size_t j = 0; j < scene.hairs.size() && scene.cloths.size() + j < bodies.size(); ++j) {
        const HairSpec& spec = scene.hairs[j];
        if (spec.hasAttach && heldBy(*bodies[scene.cloths.size() + j], true) == 0)
            out.push_back(specError(
                scene.wind.path, spec.attach,
                "[[hair]] '" + spec.name + "' attach: it selects no root: check the box", true));
    }
    // Attachments bound far from the body: the cloth is not where the body is at the frame the
    // binding is made (a cape exported in centimetres onto a body in metres: bound 148 m off;
    // a body whose first frame stands far from its rest pose, without a pre-roll: 1.8 m off).
    // The binding holds that offset for the whole run, so the cloth rides beside the body.
    const auto boundFar = [&](const solver::Body& body, const std::string& what,
                              const PinSpec& key) {
        std::vector<std::pair<int, double>> gaps;
        body.attachmentGaps(gaps);
        if (gaps.empty()) return;
        const auto worst =
            std::max_element(gaps.begin(), gaps.end(),
                             [](const auto& a, const auto& b) { return a.second < b.second; });
        std::vector<double> x(body.positions().data(),
                              body.positions().data() + body.positions().size());
        const double extent = boxOf(x).extent();
        if (!(worst->second > std::max(kBindGapFloor, kBindGapShare * extent))) return;
        size_t far = 0;
        for (const auto& g : gaps)
            far += g.second > std::max(kBindGapFloor, kBindGapShare * extent);
        const char* kind = what.rfind("[[hair]]", 0) == 0 ? "hair" : "cloth";
        // Bound at the first simulated frame (the shot's start, or an earlier --frames start,
        // SimRun): the pre-roll's first under a pre-roll, where the body stands in its rest
        // pose (the collider's rest_mesh, else the sequence's first file).
        const bool preroll = s.preroll > 0;
        const int bindFrame = std::min(first, s.frameStart) - s.preroll;
        const std::string where =
            "at frame " + std::to_string(bindFrame) +
            (preroll ? " (the pre-roll's first, the body in its rest pose)" : "");
        const std::string hint =
            preroll
                ? std::string(" was modelled on the body's rest pose (the collider's rest_mesh, "
                              "else the sequence's first file)?")
                : std::string(" was modelled at that frame (scene.preroll eases it there "
                              "from its rest pose)?");
        out.push_back(specError(scene.wind.path, key,
                                what + " attach: vertex " + std::to_string(worst->first) +
                                    " is bound " + metres(worst->second) +
                                    " m from the body's surface " + where + " (" +
                                    std::to_string(far) + " of " + std::to_string(gaps.size()) +
                                    " bound vertices farther than " +
                                    metres(std::max(kBindGapFloor, kBindGapShare * extent)) +
                                    " m; the " + kind + " spans " + metres(extent) +
                                    " m): it rides that far beside the body all run; are the two "
                                    "in the same units, and does the body stand where the " +
                                    kind + hint,
                                true));
    };
    for (size_t i = 0; i < scene.cloths.size() && i < bodies.size(); ++i)
        if (scene.cloths[i].hasAttach)
            boundFar(*bodies[i], "[[cloth]] '" + scene.cloths[i].name + "'",
                     scene.cloths[i].attach);
    for (size_t j = 0; j < scene.hairs.size() && scene.cloths.size() + j < bodies.size(); ++j)
        if (scene.hairs[j].hasAttach)
            boundFar(*bodies[scene.cloths.size() + j], "[[hair]] '" + scene.hairs[j].name + "'",
                     scene.hairs[j].attach);
    // Attached edges (both ends bound to a body's surface) that the body's motion stretches or
    // compresses past kBindingLimit over the run's frames: the cloth there cannot do better than
    // the skin (hard) or fights it (soft).
    for (size_t i = 0; i < scene.cloths.size() && i < bodies.size(); ++i) {
        const ClothSpec& spec = scene.cloths[i];
        const solver::Body& body = *bodies[i];
        if (!spec.hasAttach) continue;
        body.attachmentTargets(s.frameTime(first), bound);
        if (bound.empty()) continue;
        std::vector<int> slot(body.vertexCount(), -1);
        for (size_t k = 0; k < bound.size(); ++k) slot[bound[k].first] = static_cast<int>(k);
        std::vector<std::array<int, 3>> attached; // edge's two slots and its index
        for (size_t e = 0; e < body.edges().size(); ++e) {
            const auto& ed = body.edges()[e];
            if (slot[ed[0]] >= 0 && slot[ed[1]] >= 0)
                attached.push_back({slot[ed[0]], slot[ed[1]], static_cast<int>(e)});
        }
        if (attached.empty()) continue;
        const auto& x0 = body.positions();
        double worst = 1.0;
        int worstFrame = first, worstEdge = -1;
        size_t past = 0;
        for (int f = first; f <= last; ++f) {
            body.attachmentTargets(s.frameTime(f), bound);
            for (const auto& a : attached) {
                const auto& ed = body.edges()[a[2]];
                const double len0 = (x0.segment<3>(3 * ed[0]) - x0.segment<3>(3 * ed[1])).norm();
                if (!(len0 > 0.0)) continue;
                const double r = (bound[a[0]].second - bound[a[1]].second).norm() / len0;
                const bool out = r > 1.0 + kBindingLimit || r < 1.0 - kBindingLimit;
                if (out) ++past;
                if (std::fabs(std::log(r)) > std::fabs(std::log(worst))) {
                    worst = r;
                    worstFrame = f;
                    worstEdge = a[2];
                }
            }
        }
        if (!past) continue;
        const auto& ed = body.edges()[worstEdge];
        warnAt(
            spec.attach.line, spec.attach.col,
            "[[cloth]] '" + spec.name + "' attach: the body's motion " +
                (worst > 1.0 ? "stretches" : "compresses") + " the attached edges to " +
                metres(worst) + "x their length (edge " + std::to_string(ed[0]) + "-" +
                std::to_string(ed[1]) + " at frame " + std::to_string(worstFrame) + "; " +
                std::to_string(past) + " edge-frames past +/-" + metres(100.0 * kBindingLimit) +
                " %): the cloth there follows the skin (hard) or fights it (stiffness); bind "
                "closer to the surface, where the body deforms less, or soften it with stiffness");
    }
    // Step keys on motion: pins' translation and a sphere's or capsule's position jump within
    // one substep, at a speed no cloth can follow (it stretches, then snaps back; the hard
    // scenes' worst energies, bench/README.md).
    const double t0 = s.frameTime(first), t1 = s.frameTime(last);
    const double h = 1.0 / (s.fps * std::max(1, s.substeps));
    const auto teleport = [&](const std::string& what, const char* key, double jump, double at) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      "%s is keyed with interp = \"step\": at t = %.4g s it "
                      "jumps %s m in one substep (%s m/s)",
                      key, at, metres(jump).c_str(), metres(jump / h).c_str());
        return what + ": " + buf +
               ", a teleport no cloth or hair follows (it stretches, or is pushed through, "
               "then snaps back); use interp = \"linear\" or \"smooth\", or key the move over "
               "several frames";
    };
    const auto pinsTeleport = [&](const std::string& what, const PinSpec& pins) {
        double at = 0.0;
        const double jump = pins.translate.stepJump(t0, t1, &at);
        if (!(jump > solver::kTeleportTolerance)) return;
        warnAt(pins.line, pins.col, teleport(what, "translate", jump, at));
    };
    for (const ClothSpec& spec : scene.cloths)
        if (spec.hasPins) pinsTeleport("[[cloth]] '" + spec.name + "' pins", spec.pins);
    // Pins that carry vertices inside a collider (a plane, sphere, capsule or static mesh: the
    // shapes with an inside) at some frame of the run: the cloth there can neither leave the
    // collider nor stay on the pins, and stretches between them (frame trouble "inside a
    // collider ... and the pin holding vertex N inside it", found here before the run).
    for (size_t i = 0; i < scene.cloths.size() && i < bodies.size(); ++i) {
        const ClothSpec& spec = scene.cloths[i];
        const solver::Body& body = *bodies[i];
        if (!spec.hasPins) continue;
        for (const solver::Collider& c : scene.colliders) {
            if (c.moving) continue;
            int worstFrame = first, worstVertex = -1, frames = 0;
            double worst = 0.0;
            for (int f = first; f <= last; ++f) {
                const double t = s.frameTime(f);
                const solver::ColliderPose pose = solver::colliderPose(c, t);
                bool inside = false;
                for (size_t k = 0; k < body.pinnedVertices().size(); ++k) {
                    if (body.pinIsAttachment(k)) continue;
                    const double depth =
                        -solver::queryCollider(pose, body.pinTarget(k, t)).distance;
                    if (!(depth > kPinDepth)) continue;
                    inside = true;
                    if (depth > worst) {
                        worst = depth;
                        worstFrame = f;
                        worstVertex = body.pinnedVertices()[k];
                    }
                }
                frames += inside;
            }
            if (worstVertex < 0) continue;
            warnAt(
                spec.pins.line, spec.pins.col,
                "[[cloth]] '" + spec.name + "' pins: they hold vertices inside [[collider]] '" +
                    c.name + "' in " + std::to_string(frames) + " frame(s) of the run (vertex " +
                    std::to_string(worstVertex) + " " + metres(worst) +
                    " m below its surface at frame " + std::to_string(worstFrame) +
                    "): the cloth there can neither leave the collider nor stay on the pins, and "
                    "stretches between them; move the pins (or their translate keys) or the "
                    "collider");
        }
    }
    // Hair that starts through a colliding cloth (its segments crossing the cloth's triangles):
    // the run lets such strands through the cloth until they are clear (World), but they start
    // on both sides of it.
    for (size_t j = 0; j < scene.hairs.size() && scene.cloths.size() + j < bodies.size(); ++j) {
        const solver::Body& hair = *bodies[scene.cloths.size() + j];
        if (!hair.collision().self) continue;
        for (size_t i = 0; i < scene.cloths.size() && i < bodies.size(); ++i) {
            const solver::Body& cloth = *bodies[i];
            if (!cloth.collision().self) continue;
            const solver::HairThroughCloth through = solver::hairThroughCloth(hair, cloth);
            if (through.segments == 0) continue;
            char where[96];
            std::snprintf(where, sizeof where, "(%.4g, %.4g, %.4g)", through.at.x(), through.at.y(),
                          through.at.z());
            warnAt(scene.hairs[j].line, scene.hairs[j].col,
                   "[[hair]] '" + scene.hairs[j].name + "' starts through [[cloth]] '" +
                       scene.cloths[i].name + "': " + std::to_string(through.segments) +
                       " segment(s) cross it (the first at " + where +
                       "); the run lets them through the cloth until they are clear of it, so the "
                       "strands end up on either side: start the hair clear of the cloth");
        }
    }
    for (const solver::Collider& c : scene.colliders) {
        if (c.shape != solver::ColliderShape::Sphere && c.shape != solver::ColliderShape::Capsule)
            continue;
        double at = 0.0;
        bool ofB = false;
        const double jump = solver::colliderStepJump(c, t0, t1, at, ofB);
        if (jump > solver::kTeleportTolerance)
            warn(c, teleport("[[collider]] '" + c.name + "'",
                             c.shape == solver::ColliderShape::Sphere ? "center"
                             : ofB                                    ? "b"
                                                                      : "a",
                             jump, at));
    }
    // A sequence that ends before the run (or starts after it), or whose frame pattern matched
    // one file: the body stands still there. (Loaded with the scene's fps and time_zero: its
    // frame numbers are the run's.)
    const auto checkSequence = [&](const solver::MeshSequence& seq, int line, int col,
                                   const std::string& what) {
        io::FramePattern fp;
        if (!io::parseFramePattern(std::filesystem::path(seq.path()).filename().string(), fp))
            return;
        if (seq.lastFrame() == seq.firstFrame() && last > first)
            warnAt(line, col,
                   what + ": its mesh sequence '" + seq.path() + "' matches one file (frame " +
                       std::to_string(seq.firstFrame()) +
                       "), so the body stands still over the run (frames " + std::to_string(first) +
                       " to " + std::to_string(last) +
                       "): write the other frames, or name the file without a frame token");
        else if (last > seq.lastFrame() || first < seq.firstFrame())
            warnAt(line, col,
                   what + ": its mesh sequence '" + seq.path() + "' has frames " +
                       std::to_string(seq.firstFrame()) + "-" + std::to_string(seq.lastFrame()) +
                       " but the run goes from frame " + std::to_string(first) + " to " +
                       std::to_string(last) +
                       ": outside its frames the body holds its first or last pose (write the "
                       "frames, or shorten the run)");
    };
    // A body in centimetres (or cloth in them): extents 25× apart.
    const auto checkScale = [&](double extent, int line, int col, const std::string& what) {
        if (cloth.empty() || !(clothExtent > 0.0) || !(extent > 0.0)) return;
        if (extent > 25.0 * clothExtent)
            warnAt(line, col,
                   what + " is " + metres(extent) + " m across, " + metres(extent / clothExtent) +
                       "x the largest cloth or hair (" + metres(clothExtent) +
                       " m): modelled in centimetres? gale's units are metres (export at a scale "
                       "of 0.01)");
        else if (25.0 * extent < clothExtent)
            warnAt(line, col,
                   what + " is " + metres(extent) + " m across, 1/" + metres(clothExtent / extent) +
                       " of the largest cloth or hair (" + metres(clothExtent) +
                       " m): is the cloth in centimetres? gale's units are metres");
    };
    // Bodies named only by attachments get the same checks (a collider's are below).
    std::vector<const solver::MeshSequence*> checked;
    for (const solver::Collider& c : scene.colliders)
        if (c.moving) checked.push_back(&c.moving->mesh());
    for (size_t i = 0; i < bodies.size(); ++i) {
        const bool isCloth = i < scene.cloths.size();
        if (!isCloth && i - scene.cloths.size() >= scene.hairs.size()) break;
        const PinSpec& spec =
            isCloth ? scene.cloths[i].attach : scene.hairs[i - scene.cloths.size()].attach;
        const std::string what =
            (isCloth ? "[[cloth]] '" + scene.cloths[i].name
                     : "[[hair]] '" + scene.hairs[i - scene.cloths.size()].name) +
            "' attach";
        for (const solver::PinSet& set : bodies[i]->pinSets()) {
            const solver::MeshSequence* seq = set.attach.get();
            if (!seq || std::find(checked.begin(), checked.end(), seq) != checked.end()) continue;
            checked.push_back(seq);
            checkSequence(*seq, spec.line, spec.col, what);
            checkScale(boxOf(seq->firstPositions()).extent(), spec.line, spec.col,
                       what + ": its body");
        }
    }
    for (const solver::Collider& c : scene.colliders) {
        const std::string what = "[[collider]] '" + c.name + "'";
        if (c.moving) checkSequence(c.moving->mesh(), c.line, c.col, what);
        double size = 0.0;
        const Box box = colliderBox(c, s.frameTime(first), &size);
        if (box.empty() || cloth.empty() || !(clothExtent > 0.0)) continue;
        checkScale(size, c.line, c.col, what);
        // A static mesh thinner than the cloth's edges (or than two of its SDF's voxels): its
        // contact is per cloth vertex, so a plate or rod standing between two rows of vertices
        // goes through the cloth's faces (a 1 cm plate on edge under a sheet of 2.2 cm spacing:
        // the sheet fell through it untouched).
        if (c.mesh && longestClothEdge > 0.0) {
            const Vec3 span = box.hi - box.lo;
            int axis = 0;
            span.minCoeff(&axis);
            const double voxel = c.mesh->sdf().voxel();
            const std::string thin = what + " is a static mesh " + metres(span[axis]) +
                                     " m thin along " + "xyz"[axis] + ", less than ";
            if (span[axis] < longestClothEdge)
                warn(c, thin + "the longest cloth edge (" + metres(longestClothEdge) +
                            " m): its contact is per cloth vertex (its SDF), so cloth can pass "
                            "through it between vertices; give it as a one-frame sequence (name "
                            "the file with a frame token, body.#.obj: continuous contact against "
                            "its triangles and edges), or as a capsule where it is a rod");
            else if (span[axis] < 2.0 * voxel)
                warn(c, thin + "two of its SDF's voxels (" + metres(voxel) +
                            " m), which cannot hold its shape: set voxel to at most " +
                            metres(span[axis] / 4.0) + " m");
        }
        double nearest = std::numeric_limits<double>::infinity();
        for (const Box& b : bodyBoxes) nearest = std::min(nearest, box.gap(b));
        // Reach: twice the cloth's size, and as far as a body falls over the run (½ g T²: a
        // sheet dropped from 2 m onto a ball lands on it).
        const double run = s.frameTime(last) - s.frameTime(first);
        const double fall = 0.5 * Vec3(s.gravity[0], s.gravity[1], s.gravity[2]).norm() * run * run;
        const double reach = std::max(1.0, 2.0 * clothExtent) + fall;
        if (nearest > reach)
            warn(c, what + " never comes within " + metres(nearest) +
                        " m of any cloth or hair over the run (farther than they fall in it, " +
                        metres(fall) + " m): check its position (or remove it)");
    }
    return out;
}

} // namespace gale::scene
