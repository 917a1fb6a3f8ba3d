// A scene's wind description: settings, the windicator and gust rigs, and the [[field]]
// entries, as the scene loader (scene/load.h) reads them from TOML. The bodies' sections
// ([[cloth]], [[hair]], [[collider]], [solver]) are described in scene/sim_scene.h, and
// errors in the file are scene::SceneError (scene/error.h).
#pragma once

#include "fields/keyframes.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace gale::fields {

struct SceneSettings {
    double fps = 24.0;
    int frameStart = 1;
    int frameEnd = 48;
    int substeps = 4; // minimum per frame
    std::vector<double> gravity{0.0, -9.81, 0.0};
    double airDensity = 1.225;
    // scene.time_zero: the frame at which $t = 0 (studio shots start at 1001): $t, wind and
    // gust keys and mesh sequences are shot time, $frame the studio frame number.
    double timeZero = 0.0;
    // scene.preroll: frames simulated before the first and not written, mesh-sequence bodies eased
    // from their rest pose to their pose at the first frame (run/sim_run.h).
    int preroll = 0;
    // Seconds at `frame` (the end of that frame's step).
    double frameTime(double frame) const { return (frame - timeZero) / fps; }
};

// The continuity rig: a direction arrow with an animatable intensity. Expressions see it as
// uniform `$windDir` (unit FP[3]) and `$windSpeed` (FP[1]).
struct Windicator {
    Param direction{std::vector<double>{1.0, 0.0, 0.0}};
    Param speed{0.0};
};

// A gust event: strength ramps up over `attack`, holds, decays; the front starts at the
// origin plane through (0,0,0) normal to the wind direction at `start` and sweeps along the
// wind at `travelSpeed`, so a point at distance d downwind feels it d/travelSpeed later.
struct Gust {
    std::string name;  // optional; `--set gust.NAME.strength=...` (or gust.INDEX, from 0)
    double start = 0.0;
    double attack = 0.2;
    double hold = 0.3;
    double decay = 0.6;
    Param strength{0.0}; // m/s added along the windicator direction
    double travelSpeed = 8.0;
};

struct FieldEntry {
    std::string name;              // unique in the scene (default: "field<index>")
    std::string exprPath;          // resolved against the scene's folder ("" when inline)
    std::string source;            // inline expression text (when exprPath is empty)
    std::string preset;            // an embedded preset (fields/presets.h) when both are empty
    // Where `source` starts in the scene file (1-based) when the TOML string holds it
    // verbatim (no escapes), so its diagnostics point into the scene; 0 otherwise.
    int sourceLine = 0, sourceCol = 0;
    std::map<std::string, Param> params; // overrides of the expression's parameters
    Param scale{1.0};
    std::string mask;              // inline expression multiplying the field ("" for none)
    int maskLine = 0, maskCol = 0; // as sourceLine/sourceCol, for `mask`
};

struct Scene {
    std::string path;    // the scene file
    std::string baseDir; // its folder: relative paths resolve here
    SceneSettings settings;
    std::optional<Windicator> windicator;
    std::vector<Gust> gusts;
    std::vector<FieldEntry> fields;
};

} // namespace gale::fields
