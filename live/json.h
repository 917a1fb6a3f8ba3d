// The live page's data as JSON (nlohmann::json): the state of /api/state (files, diagnostics,
// parameters, ramps, time), the scene's static geometry, one field view and simulated frames.
#pragma once

#include "live/field_frame.h"
#include "live/project.h"

#include <nlohmann/json.hpp>

namespace gale::live {

// {"files", "diagnostics": [{file, line, col, severity, message, text}], "params": [{name,
// value, min, max, file, line, ...}], "ramps": [...], "time", "ok", "fps", "frames"}. Paths
// are given as the project names them.
nlohmann::json stateJson(const Project& project, double time);

// {"box": {lo, hi}, "rest": [geometry], "colliders": [...]}.
nlohmann::json sceneJson(const Project& project);

// {"t", "colliders": [{name, shape, a, b, normal, radius, moving, points?}]}: every collider
// placed at time t as the solver places it; `points` (x,y,z,...) for mesh sequences, whose
// triangles /api/scene gives.
nlohmann::json collidersJson(const Project& project, double t);

// {"slice": {nu, nv, bounds, axes, plane, speed: [...], max, top}, "arrows": {n, positions,
// velocities, max}, "streamlines": [{points: [x,y,z,...], speed: [...]}], "overlays": {...},
// "times": {...}}. Numbers are rounded to 1e-4 (m, m/s), which the page cannot tell apart.
nlohmann::json fieldJson(const FieldFrame& frame, const viz::SliceOverlays& overlays);

// {"label", "points": [x,y,z,...], "triangles": [i,j,k,...], "polylines": [[i,...],...]}.
nlohmann::json geometryJson(const viz::GeometryOverlay& g);

// Compact JSON text; bytes that are not UTF-8 (a Latin-1 comment in a source line) become
// U+FFFD rather than an exception.
std::string jsonText(const nlohmann::json& j);

// {"error": message}.
std::string errorJson(const std::string& message);

} // namespace gale::live
