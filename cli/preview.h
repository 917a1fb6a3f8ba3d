// Preview renders of simulations: `gale viz SCENE.toml --frames A:B` (one picture per frame with the
// simulated cloth and hair over the slice, the windicator and the gust timeline) and
// `gale viz --contact-sheet WEDGEDIR` (a grid of thumbnails of a wedge's variants), plus the
// `gale viz` helpers both share with the plain slice pictures (defined in cli/viz_command.cpp).
#pragma once

#include "cli/commands.h"
#include "cli/field_input.h"
#include "viz/render.h"
#include "fields/scene.h"

#include <string>
#include <vector>

namespace gale::cli {

// ---- shared with cli/viz_command.cpp ----
// "z=0" -> axis 2, value 0.
bool parsePlane(const std::string& text, int& axis, double& value, std::string& error);
// "1024x768" (or one number for a square), 200x150 to 16384x16384.
bool parseSize(const std::string& text, int& w, int& h, std::string& error);
// Up to 3 decimals without trailing zeros: 28.8, 24, 0.125.
std::string shortNumber(double v);
std::string axisName(int a);
// The windicator, gust bands and gust timeline of a scene at time t.
SliceOverlays sceneOverlays(const fields::Scene& scene, double t);
// Samples the wind at every pixel of `slice` (nu, nv, bounds, axes and plane set) at time t.
// Prints the problem and returns an exit code (0 on success; 4 for non-finite velocities).
int sampleSlice(const FieldInput& input, double t, int threads, Slice& slice);

// ---- preview renders ----
// Frames named by --frames: "A:B", "A:B:STEP" or a list "12,24,48" (ascending, no repeats
// needed). False with `error` set otherwise.
bool parseFrameList(const std::string& text, std::vector<long>& out, std::string& error);

// One object's frame as written by gale sim (OBJ with f / l lines, or PLY with faces or a
// `strand` column) as geometry to draw. False with `error` set when it cannot be read.
bool loadFrameGeometry(const std::string& path, GeometryOverlay& out, std::string& error);

int runVizFrames(const VizOptions& options);
int runContactSheet(const VizOptions& options);

} // namespace gale::cli
