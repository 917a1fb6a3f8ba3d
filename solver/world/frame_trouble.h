// Trouble a frame ends with (../shared/spec/cli.md, "Shots"): an edge stretched beyond
// [solver] over_stretch, or a vertex inside a collider; where it is, how much, and what forced it
// (a pin or attachment, a collider, or the solver), so that a run can warn and --strict refuse.
#pragma once

#include "solver/bodies/body.h"
#include "solver/collider/collider.h"

#include <cmath>
#include <string>
#include <vector>

namespace gale::solver {

struct FrameTrouble {
    enum class Kind { OverStretch, InsideCollider };
    Kind kind = Kind::OverStretch;
    // Over-stretch: the most stretched edge, vertices `vertex`–`other`; inside: the deepest
    // vertex (`other` −1).
    int vertex = -1, other = -1;
    Vec3 position = Vec3::Zero(); // m: the vertex, or the edge's midpoint
    double amount = 0.0;          // the edge's length / rest length, or the depth inside (m)
    double limit = 0.0;           // over_stretch, or the depth tolerated (m)
    int count = 0;                // edges (vertices) of the body in this trouble at the frame
    // "pins" / "attachments" / "a pin and an attachment" (both ends held), "the pin at vertex 7",
    // "collider 'ball'" (and, inside, " and the pin holding vertex 7 inside it"), "the solver".
    std::string forcedBy;
    bool scene = false; // forced by the scene (held vertices pulled apart, or held inside)
    bool teleport = false; // ... by a collider's step keys alone (it jumped in this frame)
    // One line for stderr and run.json's events, e.g. "over-stretched: edge 12-13 at 4.1× its
    // rest length (limit 3×) at (0.1, 0.9, 0), forced by collider 'ball'".
    std::string text() const;
    const char* kindName() const;
};

// A vertex counts as inside a collider when it is deeper than this below its surface (m): the
// solve keeps it `thickness` outside, so this is a miss by thickness + 1 mm.
constexpr double kInsideTolerance = 1e-3;

// A step-keyed jump of a collider's position larger than this (m, about a cloth's thickness) is
// a teleport: trouble it forces in that frame is the scene's (and scene checks warn of it).
constexpr double kTeleportTolerance = 0.01;

// The trouble `body` ends its frame with at time t, appended to `out` (at most one entry per kind
// and collider). Moving mesh colliders are surfaces without an inside (CCD keeps cloth from
// crossing them) and are not searched for inside vertices.
// frameStart: the frame's start time; a collider whose step keys jump more than
// kTeleportTolerance within (frameStart, t] forces its trouble as the scene's ("jumped ...").
void findFrameTrouble(const Body& body, const std::vector<Collider>& colliders, double t,
                      double overStretch, std::vector<FrameTrouble>& out,
                      double frameStart = INFINITY);

} // namespace gale::solver
