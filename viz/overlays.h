// What a viz picture shows besides the wind, as data (picture.h): a scene's rigs at a time and
// the simulated objects of one frame.
#pragma once

#include "fields/scene.h"
#include "viz/picture.h"

#include <istream>
#include <string>

namespace gale::viz {

// The windicator, gust bands and gust timeline of a scene at time t.
SliceOverlays sceneOverlays(const fields::Scene& scene, double t);

// OBJ text (v, f and l lines; other lines ignored) appended to `out`.
void parseObjGeometry(std::istream& in, GeometryOverlay& out);

// One object's frame as written by gale sim (OBJ with f / l lines, or PLY with faces or a
// `strand` column) as geometry to draw. False with `error` set when it cannot be read.
bool loadFrameGeometry(const std::string& path, GeometryOverlay& out, std::string& error);

} // namespace gale::viz
