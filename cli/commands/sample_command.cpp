// `gale sample`: the wind of an expression or scene sampled at the cell centres of a grid and
// written as a .vdb (Vec3s grid `vel`), .npy (nx,ny,nz,3 float32) or .csv, once or per frame.
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/commands/field_input.h"
#include "fields/grid_sample.h"
#include "geometry/vdb_io.h"
#include "io/frame_pattern.h"

#include <CLI/CLI.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <unistd.h>

namespace gale::cli {

namespace {

// The output format: --format, else the -o extension, else CSV on stdout.
bool chooseFormat(const SampleOptions& o, io::GridFormat& format) {
    if (o.format == "vdb")
        format = io::GridFormat::Vdb;
    else if (o.format == "npy")
        format = io::GridFormat::Npy;
    else if (o.format == "csv")
        format = io::GridFormat::Csv;
    else if (o.output.empty() || o.output == "-")
        format = io::GridFormat::Csv;
    else if (!io::gridFormatFromPath(o.output, format)) {
        printError("cannot tell the output format from '" + o.output +
                   "': use a .vdb, .npy or .csv name, or --format");
        return false;
    }
    return true;
}

// "12.5%" progress on stderr, only when it is a terminal.
class Progress {
public:
    explicit Progress(bool enabled) : mEnabled(enabled) {}
    void show(const std::string& what, size_t done, size_t total) {
        if (!mEnabled) return;
        const int percent =
            total ? static_cast<int>(100.0 * static_cast<double>(done) / static_cast<double>(total))
                  : 100;
        std::fprintf(stderr, "\rgale: sampling %s %3d%%", what.c_str(), percent);
        std::fflush(stderr);
        mShown = true;
    }
    void clear() {
        if (!mShown) return;
        std::fprintf(stderr, "\r\033[K");
        std::fflush(stderr);
        mShown = false;
    }
    ~Progress() { clear(); }

private:
    bool mEnabled;
    bool mShown = false;
};

int writeOutput(const SampleOptions& o, const std::string& path, io::GridFormat format,
                const io::GridSpec& grid, const std::vector<float>& values, const FieldInput& input,
                double t, double frame) {
    if (path.empty() || path == "-") {
        io::IoError e = format == io::GridFormat::Npy ? io::writeGridNpy(std::cout, grid, values)
                                                      : io::writeGridCsv(std::cout, grid, values);
        std::cout.flush();
        if (e || !std::cout) {
            printError("cannot write to stdout" + (e ? ": " + e.message : std::string()));
            return kExitIo;
        }
        return kExitOk;
    }
    io::IoError e;
    if (format == io::GridFormat::Vdb) {
        geometry::VdbWriteOptions vdb;
        vdb.metadata["gale_source"] = input.name;
        vdb.floatMetadata["gale_time"] = t;
        vdb.floatMetadata["gale_frame"] = frame;
        vdb.floatMetadata["gale_fps"] = input.fps;
        e = geometry::writeVdbVelocity(path, grid, values, vdb);
    } else {
        e = io::writeGridFile(path, format, grid, values);
    }
    if (e) {
        std::cerr << e.render() << '\n';
        return e.kind == io::IoError::Io ? kExitIo : kExitInput;
    }
    return kExitOk;
}

// Removes the temporary files of frames that a killed run was writing (`wind.0007.vdb.tmp.<pid>`
// of a process that no longer runs): names of the --frames pattern only.
void removeStaleFrameTemps(const std::string& pattern) {
    namespace fs = std::filesystem;
    const fs::path p(pattern);
    const std::string folder = p.parent_path().string();
    io::FramePattern fp;
    if (io::hasFrameToken(folder) || !io::parseFramePattern(p.filename().string(), fp)) return;
    io::removeStaleTempFiles(folder, [&](const std::string& target) {
        long frame = 0;
        return io::matchFrame(fp, target, frame);
    });
}

std::string describeTime(double t, double frame, bool frames) {
    return frames ? "frame " + formatValue(frame, false) + " (t = " + formatValue(t, false) + " s)"
                  : "t = " + formatValue(t, false) + " s";
}

} // namespace

int runSample(const SampleOptions& o) {
    std::string error;
    std::vector<double> bounds;
    if (!parseNumbers(o.bounds, 6, "--bounds", bounds, error)) {
        printError(error + " (x0,y0,z0,x1,y1,z1)");
        return kExitUsage;
    }
    std::vector<int> res;
    if (!o.res.empty()) {
        std::vector<double> r;
        if (!parseNumbers(o.res, 1, "--res", r, error) &&
            !parseNumbers(o.res, 3, "--res", r, error)) {
            printError("--res '" + o.res + "': expected N or NX,NY,NZ (whole numbers >= 1)");
            return kExitUsage;
        }
        for (double v : r) {
            if (v != std::floor(v) || v < 1 || v > 1e9) {
                printError("--res '" + o.res + "': expected N or NX,NY,NZ (whole numbers >= 1)");
                return kExitUsage;
            }
            res.push_back(static_cast<int>(v));
        }
    } else if (!(o.voxel > 0) || !std::isfinite(o.voxel)) {
        printError(o.voxel == 0.0 ? "give the grid's resolution: --res N or --voxel SIZE"
                                  : "--voxel must be a positive number of metres");
        return kExitUsage;
    }
    if (o.fps < 0 || !std::isfinite(o.fps)) {
        printError("--fps must be a positive number");
        return kExitUsage;
    }
    if (!std::isfinite(o.time)) {
        printError("--time must be a finite number of seconds");
        return kExitUsage;
    }
    io::GridSpec grid;
    const std::array<double, 6> box{bounds[0], bounds[1], bounds[2],
                                    bounds[3], bounds[4], bounds[5]};
    if (!io::gridFromBounds(box, res, o.voxel, grid, error)) {
        printError(error);
        return kExitUsage;
    }
    io::GridFormat format;
    if (!chooseFormat(o, format)) return kExitUsage;
    const bool toStdout = o.output.empty() || o.output == "-";
    if (format == io::GridFormat::Vdb && toStdout) {
        printError("a .vdb grid is written to a file: give -o OUT.vdb");
        return kExitUsage;
    }
    long firstFrame = 0, lastFrame = 0;
    const bool frames = !o.frames.empty();
    std::string probe;
    if (frames) {
        if (!parseFrameRange(o.frames, firstFrame, lastFrame, error)) {
            printError(error);
            return kExitUsage;
        }
        if (toStdout || !io::framePath(o.output, firstFrame, probe)) {
            printError("--frames writes one file per frame: give -o with one run of '#' for the "
                       "frame number (wind.#.vdb -> wind.0001.vdb)");
            return kExitUsage;
        }
    }

    if (o.resume && !frames) {
        printError("--resume continues a --frames sequence: give --frames A:B and the same -o pattern");
        return kExitUsage;
    }

    FieldInput input;
    if (int rc = loadFieldInput(o.source, o.fps, input)) return rc;
    if (frames) removeStaleFrameTemps(o.output);

    Progress progress(::isatty(STDERR_FILENO) != 0);
    fields::GridSampleOptions sampling;
    sampling.threads = o.threads;
    std::vector<float> values;
    const long count = frames ? lastFrame - firstFrame + 1 : 1;
    long skipped = 0;
    for (long n = 0; n < count; ++n) {
        const long f = firstFrame + n;
        if (o.resume) {
            // Frames are written whole or not at all (temporary name, then rename), so a frame
            // file on disk is complete (an empty one, left by a crash of the machine, is redone).
            std::string path;
            io::framePath(o.output, f, path);
            std::error_code ec;
            if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) > 0 && !ec) {
                ++skipped;
                continue;
            }
        }
        fields::SampleTime when;
        when.fps = input.fps;
        when.frameZero = input.timeZero;
        when.time = frames ? input.frameTime(static_cast<double>(f)) : o.time;
        when.threads = o.threads;
        const double frameNumber =
            frames ? static_cast<double>(f) : when.time * input.fps + input.timeZero;
        const std::string label =
            frames ? "frame " + std::to_string(f) + " (" + std::to_string(n + 1) + "/" +
                         std::to_string(count) + ")"
                   : std::to_string(grid.res[0]) + "x" + std::to_string(grid.res[1]) + "x" +
                         std::to_string(grid.res[2]);
        sampling.progress = [&](size_t done, size_t total) { progress.show(label, done, total); };
        fields::SampleStatus status =
            fields::sampleGrid(*input.field, grid, when, values, sampling);
        progress.clear();
        if (!status.ok) {
            printError("cannot sample " + input.name + " at " +
                       describeTime(when.time, frameNumber, frames) + ": " + status.message);
            return kExitInput;
        }
        if (status.nonFinite > 0) {
            printError(std::to_string(status.nonFinite) + " of " +
                       std::to_string(grid.cellCount()) + " cell(s) of " + input.name +
                       " gave a non-finite velocity at " +
                       describeTime(when.time, frameNumber, frames) + "; nothing was written" +
                       (frames && n > 0 ? " for this frame" : ""));
            return kExitNumeric;
        }
        std::string path = o.output;
        if (frames) io::framePath(o.output, f, path);
        if (int rc = writeOutput(o, path, format, grid, values, input, when.time, frameNumber))
            return rc;
    }
    if (skipped > 0)
        std::cerr << "gale: --resume: " << skipped << " of " << count
                  << " frame(s) already on disk, skipped\n";
    return kExitOk;
}

Command addSampleCommand(CLI::App& app) {
    auto o = std::make_shared<SampleOptions>();
    CLI::App* sub = app.add_subcommand(
        "sample", "Sample the wind of an expression or scene at the cell centres of a grid and "
                  "write it as a .vdb (one Vec3s grid named vel), .npy (float32, shape "
                  "(nx,ny,nz,3), x slowest) or .csv (x,y,z,vx,vy,vz), once or per frame.");
    addSourceOptions(*sub, o->source, /*withType=*/false, /*scenes=*/true);
    sub->add_option("--bounds", o->bounds,
                    "The box to sample, metres: x0,y0,z0,x1,y1,z1; the grid starts at its min "
                    "corner")
        ->type_name("BOX")
        ->required();
    CLI::Option* res =
        sub->add_option("--res", o->res,
                        "Cells: N along the box's longest side (cubic voxels; the other sides "
                        "get the cells that cover them), or NX,NY,NZ exactly")
            ->type_name("N");
    CLI::Option* voxel = sub->add_option("--voxel", o->voxel,
                                         "Cubic voxel size in metres (instead of --res); each "
                                         "side gets the cells that cover it")
                             ->type_name("S");
    res->excludes(voxel);
    voxel->excludes(res);
    CLI::Option* time =
        sub->add_option("--time", o->time, "$t in seconds (default 0)")->type_name("T");
    CLI::Option* frames =
        sub->add_option(
               "--frames", o->frames,
               "Sample frames A to B (inclusive) at t = (frame - time_zero) / fps, one file each: "
               "the '#' run in -o becomes the frame number (a lone '#' pads to 4 "
               "digits, '##' to 2, ...)")
            ->type_name("A:B");
    time->excludes(frames);
    frames->excludes(time);
    sub->add_flag("--resume", o->resume,
                  "With --frames: skip the frames whose file is already on disk (each is whole: "
                  "written under a temporary name, then renamed) and write the missing ones, as "
                  "after an interrupted run; give the same source, grid and -o pattern");
    sub->add_option("--fps", o->fps, "Frames per second (default: the scene's, else 24)")
        ->type_name("FPS");
    sub->add_option("--threads", o->threads,
                    "Threads (default 0 = all hardware threads); results do not depend on it")
        ->type_name("N")
        ->check(CLI::Range(0, 4096));
    sub->add_option("-o,--output", o->output,
                    "Write here (.vdb, .npy, .csv) instead of CSV on stdout; written to a "
                    "temporary file and renamed, never half-written")
        ->type_name("OUT");
    sub->add_option("--format", o->format,
                    "Output format (default: from the -o extension, else csv)")
        ->type_name("FMT")
        ->check(CLI::IsMember({"vdb", "npy", "csv"}));
    sub->footer("Cell (i,j,k) is sampled at its centre (x0 + (i+0.5)*voxel, ...); the .vdb\n"
                "transform puts voxel (i,j,k) on that cell, and every cell is active.\n"
                "Exit codes: 1 bad expression or scene, 2 bad flags, 3 missing input or\n"
                "unwritable output, 4 non-finite velocities (nothing written for that frame).");
    return {sub, [o] { return runSample(*o); }};
}

} // namespace gale::cli
