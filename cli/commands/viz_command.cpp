// `gale viz`: a picture (PNG or SVG) of a slice of the wind: speed colours with a legend,
// arrows or streamlines, and, for scenes, the windicator, gust fronts and a gust timeline.
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/commands/field_input.h"
#include "cli/commands/preview.h"
#include "fields/grid_sample.h"
#include "fields/rigs.h"
#include "viz/cairo_render.h"
#include "viz/slice_marks.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

namespace gale::cli {

// (The helpers up to sceneOverlays are shared with the preview renders: cli/commands/preview.h.)

// "z=0" -> axis 2, value 0.
bool parsePlane(const std::string& text, int& axis, double& value, std::string& error) {
    const size_t eq = text.find('=');
    std::string name = eq == std::string::npos ? text : text.substr(0, eq);
    name.erase(
        std::remove_if(name.begin(), name.end(), [](unsigned char c) { return std::isspace(c); }),
        name.end());
    std::vector<double> v;
    if (eq == std::string::npos || name.size() != 1 ||
        std::string("xyzXYZ").find(name[0]) == std::string::npos ||
        !parseNumbers(text.substr(eq + 1), 1, "--plane", v, error)) {
        error = "--plane '" + text + "': expected x=C, y=C or z=C (metres), e.g. z=0";
        return false;
    }
    axis = std::tolower(static_cast<unsigned char>(name[0])) - 'x';
    value = v[0];
    return true;
}

// "1024x768" (or one number for a square).
bool parseSize(const std::string& text, int& w, int& h, std::string& error) {
    const size_t x = text.find_first_of("xX");
    std::vector<double> a, b;
    std::string e;
    bool ok = x == std::string::npos ? parseNumbers(text, 1, "--size", a, e)
                                     : parseNumbers(text.substr(0, x), 1, "--size", a, e) &&
                                           parseNumbers(text.substr(x + 1), 1, "--size", b, e);
    if (ok) {
        w = static_cast<int>(a[0]);
        h = static_cast<int>(b.empty() ? a[0] : b[0]);
        ok = a[0] == w && (b.empty() || b[0] == h) && w >= 200 && h >= 150 && w <= 16384 &&
             h <= 16384;
    }
    if (!ok)
        error = "--size '" + text +
                "': expected WIDTHxHEIGHT in pixels, from 200x150 to "
                "16384x16384 (e.g. 1024x1024)";
    return ok;
}

// Up to 3 decimals without trailing zeros: 28.8, 24, 0.125.
std::string shortNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f", v);
    std::string out = buf;
    while (out.back() == '0') out.pop_back();
    if (out.back() == '.') out.pop_back();
    return out == "-0" ? "0" : out;
}

std::string axisName(int a) {
    return std::string(1, static_cast<char>('x' + a));
}

int sampleSlice(const FieldInput& input, double t, int threads, viz::Slice& slice) {
    fields::SampleTime when;
    when.time = t;
    when.fps = input.fps;
    when.frameZero = input.timeZero;
    when.threads = threads;
    const size_t n = static_cast<size_t>(slice.nu) * static_cast<size_t>(slice.nv);
    const fields::SampleStatus status = viz::sampleSlice(*input.field, when, slice);
    if (!status.ok) {
        printError("cannot sample " + input.name + ": " + status.message);
        return kExitInput;
    }
    if (status.nonFinite > 0) {
        printError(std::to_string(status.nonFinite) + " of " + std::to_string(n) +
                   " sample(s) of " + input.name + " gave a non-finite velocity at t = " +
                   formatValue(t, false) + " s; no picture was written");
        return kExitNumeric;
    }
    return kExitOk;
}

int runViz(const VizOptions& o) {
    // Preview renders of simulated frames, and contact sheets of wedges (cli/commands/preview.cpp).
    if (!o.contactSheet.empty()) return runContactSheet(o);
    if (!o.frames.empty()) return runVizFrames(o);
    std::string error;
    int normal = 2;
    double planeValue = 0.0;
    if (!parsePlane(o.plane, normal, planeValue, error)) {
        printError(error);
        return kExitUsage;
    }
    std::vector<double> b;
    if (o.bounds.empty()) {
        printError("--bounds is required (u0,v0,u1,v1 in the plane's axes), except with --frames or "
                   "--contact-sheet");
        return kExitUsage;
    }
    if (!parseNumbers(o.bounds, 4, "--bounds", b, error)) {
        printError(error + " (u0,v0,u1,v1 in the plane's axes)");
        return kExitUsage;
    }
    int uAxis = 0, vAxis = 1;
    viz::planeAxes(normal, uAxis, vAxis);
    if (!(b[2] > b[0]) || !(b[3] > b[1])) {
        printError("--bounds '" + o.bounds + "': expected " + axisName(uAxis) + "0," +
                   axisName(vAxis) + "0," + axisName(uAxis) + "1," + axisName(vAxis) + "1 with " +
                   axisName(uAxis) + "1 > " + axisName(uAxis) + "0 and " + axisName(vAxis) +
                   "1 > " + axisName(vAxis) + "0");
        return kExitUsage;
    }
    int width = 0, height = 0;
    if (!parseSize(o.size, width, height, error)) {
        printError(error);
        return kExitUsage;
    }
    viz::ImageFormat format;
    if (!viz::imageFormatFromPath(o.output, format)) {
        printError("cannot tell the picture format from '" + o.output +
                   "': use a .png or .svg name");
        return kExitUsage;
    }
    if (o.fps < 0 || !std::isfinite(o.fps) || !std::isfinite(o.time) || o.speedMax < 0 ||
        !std::isfinite(o.speedMax) || o.arrowSpacing < 0 || !std::isfinite(o.arrowSpacing)) {
        printError(
            "--fps, --speed-max and --arrow-spacing must be positive numbers, --time finite");
        return kExitUsage;
    }

    FieldInput input;
    if (int rc = loadFieldInput(o.source, o.fps, input)) return rc;
    const double t = o.time;
    viz::SliceOverlays overlays;
    if (input.scene) overlays = viz::sceneOverlays(*input.scene, t);

    viz::SliceLayout layout;
    if (!viz::layoutSlice(width, height, b[2] - b[0], b[3] - b[1], overlays.timeline.present,
                          layout)) {
        printError(
            "--size " + o.size + " " +
            viz::sliceTooSmall(width, height, b[2] - b[0], b[3] - b[1], overlays.timeline.present));
        return kExitUsage;
    }
    viz::Slice slice;
    slice.nu = layout.plotW;
    slice.nv = layout.plotH;
    slice.bounds = {b[0], b[1], b[2], b[3]};
    slice.uAxis = uAxis;
    slice.vAxis = vAxis;
    slice.normalAxis = normal;
    slice.planeValue = planeValue;
    if (int rc = sampleSlice(input, t, o.threads, slice)) return rc;

    viz::RenderSettings settings;
    settings.format = format;
    settings.title = input.name;
    settings.subtitle = "slice " + axisName(normal) + " = " + formatValue(planeValue, false) +
                        " m   \u00b7   t = " + shortNumber(t) + " s (frame " +
                        shortNumber(t * input.fps + input.timeZero) + " at " + shortNumber(input.fps) +
                        " fps)";
    settings.time = t;
    settings.style = o.style == "streamlines" ? viz::FlowStyle::Streamlines
                     : o.style == "none"      ? viz::FlowStyle::None
                                              : viz::FlowStyle::Arrows;
    settings.speedMax = o.speedMax;
    settings.arrowSpacing = o.arrowSpacing;
    io::IoError e = viz::renderSlice(o.output, layout, slice, overlays, settings);
    if (e) {
        std::cerr << e.render() << '\n';
        return e.kind == io::IoError::Io ? kExitIo : kExitInput;
    }
    return kExitOk;
}

Command addVizCommand(CLI::App& app) {
    auto o = std::make_shared<VizOptions>();
    CLI::App* sub = app.add_subcommand(
        "viz",
        "Draw a slice of the wind as a PNG or SVG picture: colour = speed (viz::viridis, with "
        "a legend in m/s), arrows or streamlines for the in-plane direction, and for "
        "scenes the windicator arrow, gust fronts and a gust timeline.");
    addSourceOptions(*sub, o->source, /*withType=*/false, /*scenes=*/true);
    sub->add_option("--plane", o->plane,
                    "The slice: z=C (drawn with x right, y up), y=C (x right, z up) or x=C (z "
                    "right, y up)")
        ->type_name("PLANE")
        ->capture_default_str();
    sub->add_option("--bounds", o->bounds,
                    "The slice's extent in metres along the drawn axes: u0,v0,u1,v1 (for z=C: "
                    "x0,y0,x1,y1). Required, except with --frames (default: around the simulated "
                    "geometry of every frame) and --contact-sheet")
        ->type_name("BOX");
    sub->add_option("--time", o->time, "$t in seconds")->capture_default_str()->type_name("T");
    sub->add_option("--fps", o->fps, "Frames per second (default: the scene's, else 24)")
        ->type_name("FPS");
    sub->add_option("--size", o->size, "Picture size in pixels")
        ->type_name("WxH")
        ->capture_default_str();
    sub->add_option("-o,--output", o->output,
                    "The picture: .png or .svg (written to a temporary file and renamed)")
        ->type_name("OUT")
        ->required();
    sub->add_option("--style", o->style, "Direction marks: arrows, streamlines or none")
        ->type_name("STYLE")
        ->check(CLI::IsMember({"arrows", "streamlines", "none"}))
        ->capture_default_str();
    sub->add_option("--speed-max", o->speedMax,
                    "Top of the colour scale in m/s, to compare pictures (default: a round "
                    "number above the slice's maximum)")
        ->type_name("V");
    sub->add_option("--arrow-spacing", o->arrowSpacing,
                    "Pixels between arrows or streamlines (default: about 22 across)")
        ->type_name("PX");
    sub->add_option("--frames", o->frames,
                    "Preview renders of a scene's simulation: one picture per frame A to B (OUT has a # "
                    "run for the frame number), drawing the simulated cloth and hair (shaded) over the "
                    "slice, the windicator with its current speed and the gust timeline. With "
                    "--contact-sheet: the frames shown, as A:B, A:B:STEP or a list 12,24,48")
        ->type_name("A:B");
    sub->add_option("--sim", o->sim, "With --frames: the gale sim output folder holding the frames "
                                     "(default: sim, gale sim's default)")
        ->type_name("OUTDIR");
    sub->add_option("--contact-sheet", o->contactSheet,
                    "A contact sheet of a gale wedge output folder: one row of thumbnails per variant "
                    "(labelled with its values), one column per --frames frame; OUT is a .png")
        ->type_name("WEDGEDIR");
    sub->add_flag("--no-field", o->noField, "With --frames: a plain backdrop instead of the field slice "
                                            "(the default for contact sheets)");
    sub->add_flag("--strain", o->strain, "With --frames: colour the cloth and hair by strain (edge length "
                                         "over rest length − 1: teal −25 %, the material's colour 0, "
                                         "yellow, red +25 % and beyond; as gale live draws it)");
    sub->add_option("--cell", o->cell, "Contact sheet thumbnail size in pixels")
        ->type_name("WxH")
        ->capture_default_str();
    sub->add_option("--threads", o->threads, "Threads (default 0 = all hardware threads)")
        ->type_name("N")
        ->check(CLI::Range(0, 4096));
    sub->footer("Arrows show the in-plane part of the wind, scaled to the largest (see the\n"
                "key); the colour is the full 3-D speed. Scenes add the windicator arrow, the\n"
                "front and tail of every gust crossing the slice, and a gust timeline.\n"
                "Exit codes: 1 bad expression or scene, 2 bad flags, 3 unwritable picture,\n"
                "4 non-finite velocities (no picture written).");
    return {sub, [o] { return runViz(*o); }};
}

} // namespace gale::cli
