// Preview renders of simulations: `gale viz SCENE.toml --frames A:B` (one picture per frame with the
// simulated cloth and hair over the slice, the windicator and the gust timeline) and
// `gale viz --contact-sheet WEDGEDIR` (a grid of thumbnails of a wedge's variants), plus the
// `gale viz` helpers both share with the plain slice pictures (defined in cli/commands/viz_command.cpp).
#pragma once

#include "cli/commands.h"
#include "cli/commands/field_input.h"
#include "fields/scene.h"
#include "viz/overlays.h"
#include "viz/picture.h"

#include <string>
#include <vector>

namespace gale::cli {

// ---- shared with cli/commands/viz_command.cpp ----
// "z=0" -> axis 2, value 0.
bool parsePlane(const std::string& text, int& axis, double& value, std::string& error);
// "1024x768" (or one number for a square), 200x150 to 16384x16384.
bool parseSize(const std::string& text, int& w, int& h, std::string& error);
// Up to 3 decimals without trailing zeros: 28.8, 24, 0.125.
std::string shortNumber(double v);
std::string axisName(int a);
// Samples the wind at every pixel of `slice` (nu, nv, bounds, axes and plane set) at time t.
// Prints the problem and returns an exit code (0 on success; 4 for non-finite velocities).
int sampleSlice(const FieldInput& input, double t, int threads, viz::Slice& slice);

// ---- preview renders ----
// Frames named by --frames: "A:B", "A:B:STEP" or a list "12,24,48" (ascending, no repeats
// needed). False with `error` set otherwise.
bool parseFrameList(const std::string& text, std::vector<long>& out, std::string& error);

int runVizFrames(const VizOptions& options);
int runContactSheet(const VizOptions& options);

} // namespace gale::cli
