// The scene's wind rigs as expressions see them: the windicator ($windDir, $windSpeed) and the
// gust rig behind the `gust(P)` built-in, whose data rides on a per-scene function table.
#pragma once

#include "fields/field.h"
#include "fields/scene.h"
#include "runtime/builtins.h"

#include <memory>

namespace gale::fields {

// What gust(P) reads (immutable once built; shared by every thread evaluating the scene).
struct GustRig {
    Windicator windicator;
    std::vector<Gust> gusts;
};

// The windicator's direction at time t as a unit vector (a zero vector stays zero).
Vec3 windDirectionAt(const Windicator& w, double t);

// A gust's envelope (0..1) at its local time: 0 before 0; rises smoothly (3s^2 - 2s^3) over
// `attack`, holds 1 for `hold`, falls smoothly to 0 over `decay`.
double gustEnvelope(const Gust& g, double localTime);

// m/s of every gust of the rig at position p and time t, given the unit wind direction at t.
// A gust's local time there is t - start - (p . dir) / travelSpeed; its (keyframed) strength
// is read at the time its front left the plane through the origin, t - (p . dir) / travelSpeed.
double gustSpeedAt(const GustRig& rig, const Vec3& dir, const Vec3& p, double t);

// The gust(P) built-in reading `rig` (null: gust(P) is 0 everywhere).
runtime::Builtin gustBuiltin(std::shared_ptr<const GustRig> rig);

// fieldFunctions() with gust(P) bound to this scene's windicator and gusts.
std::shared_ptr<const runtime::FunctionTable> sceneFunctions(const Scene& scene);

} // namespace gale::fields
