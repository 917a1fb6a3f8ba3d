// `gale eval`: compile an expression and evaluate it once (printing the value on one line) or
// at every point of a point file (writing the points with the result columns added). A
// SCENE.toml in place of FILE.se samples the scene's summed wind the same way.
#include "cli/commands.h"
#include "cli/common.h"
#include "cli/commands/field_input.h"
#include "fields/expression_field.h"
#include "fields/scene.h"
#include "io/atomic_file.h"
#include "scene/load.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <unistd.h>

namespace gale::cli {

namespace {

// Output format from --format, else the -o extension, else CSV. False (after printing) when
// neither names a known format.
bool chooseFormat(const EvalOptions& o, io::PointFormat& format) {
    if (!o.format.empty()) {
        if (o.format == "csv")
            format = io::PointFormat::Csv;
        else if (o.format == "ply")
            format = io::PointFormat::Ply;
        else if (o.format == "ply-ascii")
            format = io::PointFormat::PlyAscii;
        else if (o.format == "json")
            format = io::PointFormat::Json;
        else if (o.format == "npy")
            format = io::PointFormat::Npy;
        else if (o.format == "obj")
            format = io::PointFormat::Obj;
        else
            return false; // CLI11 has already checked the name
        return true;
    }
    format = io::PointFormat::Csv;
    if (o.output.empty() || o.output == "-") return true;
    if (io::formatFromPath(o.output, format)) return true;
    printError("cannot tell the output format from '" + o.output +
               "': use a .csv, .ply, .json, .npy or .obj name, or --format");
    return false;
}

// Names of the result columns: value (scalar), vx,vy,vz (vector), value0.. otherwise.
std::vector<std::string> resultColumns(int width) {
    if (width == 1) return {"value"};
    if (width == 3) return {"vx", "vy", "vz"};
    std::vector<std::string> names;
    for (int k = 0; k < width; ++k) names.push_back("value" + std::to_string(k));
    return names;
}

template <class T>
runtime::EvalResult evaluateInto(const runtime::Program& program,
                                 const runtime::EvalRequest& request, int width,
                                 std::vector<double>& values, std::vector<std::string>& strings) {
    std::vector<T> buffer(request.count * static_cast<size_t>(std::max(width, 1)));
    runtime::EvalOutput<T> out;
    out.data = buffer.data();
    out.pointStride = width;
    out.compStride = 1;
    if (program.resultIsString()) {
        strings.assign(request.count, std::string());
        out.strings = strings.data();
    }
    runtime::EvalResult r = runtime::evaluate<T>(program, request, out);
    values.assign(buffer.begin(), buffer.end());
    return r;
}

int reportNonFinite(const lang::SourceFile& source, const runtime::EvalResult& r, size_t count) {
    lang::RenderOptions options;
    options.color = useColor();
    for (const lang::Diagnostic& d : r.diagnostics) {
        if (d.span.begin == 0 && d.span.end == 0)
            printError(d.message);
        else
            std::cerr << lang::renderDiagnostic(source, d, options);
    }
    printError(std::to_string(r.nonFinite) + " of " + std::to_string(count) +
               " point(s) gave a non-finite result (first: point " +
               std::to_string(r.firstBadPoint) + "); nothing was written");
    return kExitNumeric;
}

// Prints one value line, or writes it to -o.
int writeValueLine(const EvalOptions& o, std::string line) {
    line += '\n';
    if (!o.output.empty() && o.output != "-") return writeTextFileAtomic(o.output, line);
    std::cout << line << std::flush;
    return std::cout ? kExitOk : kExitIo;
}

// Adds the result columns (point-major `values`, `width` per point) to the points, replacing
// columns of the same names; returns their indices.
std::vector<int> addResultColumns(io::PointSet& points, const std::vector<double>& values,
                                  int width, bool asFloat) {
    std::vector<int> added;
    for (const std::string& name : resultColumns(width)) added.push_back(points.addColumn(name));
    if (points.float32.size() < points.names.size())
        points.float32.resize(points.names.size(), false);
    const size_t n = points.size();
    for (int k = 0; k < width; ++k) {
        std::vector<double>& col =
            points.columns[static_cast<size_t>(added[static_cast<size_t>(k)])];
        for (size_t i = 0; i < n; ++i)
            col[i] = values[i * static_cast<size_t>(width) + static_cast<size_t>(k)];
        points.float32[static_cast<size_t>(added[static_cast<size_t>(k)])] = asFloat;
    }
    return added;
}

// Writes the points with the result columns (point-major `values`, `width` per point) added,
// replacing columns of the same names.
int writePointResults(const EvalOptions& o, io::PointSet& points, const std::vector<double>& values,
                      int width, bool asFloat, io::PointFormat format) {
    const std::vector<int> added = addResultColumns(points, values, width, asFloat);
    const std::vector<int> npyColumns = format == io::PointFormat::Npy ? added : std::vector<int>{};
    if (o.output.empty() || o.output == "-") {
        io::IoError e = io::writePoints(std::cout, points, format, npyColumns);
        std::cout.flush();
        if (e || !std::cout) {
            printError("cannot write to stdout" + (e ? ": " + e.message : std::string()));
            return e.kind == io::IoError::Data ? kExitInput : kExitIo;
        }
        return kExitOk;
    }
    io::IoError e = io::writePointsFile(o.output, points, format, npyColumns);
    if (e) {
        std::cerr << e.render() << '\n';
        return e.kind == io::IoError::Data ? kExitInput : kExitIo;
    }
    return kExitOk;
}

// Checks that the points (or a CSV header) have x, y, z columns; returns an exit code.
int checkXyz(const std::string& path, const io::PointSet& points) {
    if (points.find("x") < 0 || points.find("y") < 0 || points.find("z") < 0) {
        std::string have;
        for (const std::string& n : points.names) have += (have.empty() ? "" : ", ") + n;
        std::cerr << (path == "-" ? std::string("<stdin>") : path)
                  << ": error: the points need x, y and z columns (found: "
                  << (have.empty() ? std::string("none") : have) << ")\n";
        return kExitInput;
    }
    return kExitOk;
}

// Reads --points and checks for x, y, z; returns an exit code.
int loadEvalPoints(const std::string& path, io::PointSet& points) {
    if (int rc = loadPoints(path, points)) return rc;
    return checkXyz(path, points);
}

// ---- streaming: CSV points in, CSV out, a chunk at a time (memory bounded by the chunk) ----

constexpr size_t kStreamChunk = size_t(1) << 20; // points per chunk

// Points stream when they are read from CSV and written as CSV, unless --checked output goes to
// stdout (a non-finite value found late must leave no output, and stdout cannot be taken back).
bool streamsPoints(const EvalOptions& o, io::PointFormat format) {
    io::PointFormat in = io::PointFormat::Csv;
    if (o.points != "-" && !io::formatFromPath(o.points, in)) return false;
    const bool toStdout = o.output.empty() || o.output == "-";
    return in == io::PointFormat::Csv && format == io::PointFormat::Csv && !(o.checked && toStdout);
}

struct PointStream {
    std::ifstream file;
    std::unique_ptr<io::CsvPointReader> reader;
    io::PointSet header; // the columns, no rows
};

int printIoError(const io::IoError& e) {
    std::cerr << e.render() << '\n';
    return e.kind == io::IoError::Io ? kExitIo : kExitInput;
}

// Opens --points and reads its header (which must name x, y and z); returns an exit code.
int openPointStream(const std::string& path, PointStream& s) {
    std::istream* in = &std::cin;
    std::string name = "<stdin>";
    if (path == "-") {
        // std::cin is synchronised with C stdio and reads a character at a time (3x slower
        // here); its own descriptor, reopened, is buffered. std::cin is the fallback (a socket).
        // A regular file reopened starts at 0: continue where standard input stands.
        const off_t at = ::lseek(0, 0, SEEK_CUR);
        s.file.open("/dev/stdin", std::ios::binary);
        if (s.file && at > 0) s.file.seekg(at);
        if (s.file) in = &s.file;
    } else {
        name = path;
        std::error_code ec;
        if (std::filesystem::is_directory(path, ec))
            return printIoError(io::ioErrorAt(path, "cannot read", EISDIR));
        errno = 0;
        s.file.open(path, std::ios::binary);
        if (!s.file) return printIoError(io::ioErrorAt(path, "cannot open", errno));
        in = &s.file;
    }
    s.reader = std::make_unique<io::CsvPointReader>(*in, name);
    if (io::IoError e = s.reader->readHeader(s.header)) return printIoError(e);
    return checkXyz(path, s.header);
}

// Evaluates one chunk (points first .. first + chunk.size() - 1) and adds its result columns;
// adds the number of points with a non-finite result to `bad` (--checked); returns an exit code.
using ChunkEval = std::function<int(io::PointSet& chunk, size_t first, size_t& bad)>;

// Reads, evaluates and writes chunk after chunk. After a chunk with non-finite results
// (--checked) the rest is still evaluated, to count them, but nothing more is written and the
// output file is not created: `reportBad(bad, total)` gives the exit code.
int streamPoints(const EvalOptions& o, PointStream& s, const ChunkEval& eval,
                 const std::function<int(size_t bad, size_t total)>& reportBad) {
    io::IoError writeError;
    auto run = [&](std::ostream* out) -> int {
        io::PointSet chunk;
        size_t total = 0, bad = 0;
        for (bool first = true;; first = false) {
            if (io::IoError e = s.reader->readRows(chunk, kStreamChunk)) return printIoError(e);
            const size_t n = chunk.size();
            if (n == 0 && !first) break;
            if (int rc = eval(chunk, total, bad)) return rc;
            total += n;
            if (bad > 0) out = nullptr;
            if (out) {
                writeError = io::writePointsCsv(*out, chunk, first);
                if (writeError) return kExitIo;
            }
            if (n == 0) break;
        }
        return bad > 0 ? reportBad(bad, total) : kExitOk;
    };
    if (o.output.empty() || o.output == "-") {
        const int rc = run(&std::cout);
        std::cout.flush();
        if (rc == kExitIo && writeError) {
            printError("cannot write to stdout: " + writeError.message);
            return kExitIo;
        }
        if (rc == kExitOk && !std::cout) {
            printError("cannot write to stdout");
            return kExitIo;
        }
        return rc;
    }
    int rc = kExitOk;
    io::IoError e = io::writeFileAtomic(o.output, [&](const std::string& tmp) -> io::IoError {
        errno = 0;
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) return io::ioErrorAt(o.output, "cannot write", errno);
        rc = run(&f);
        if (rc == kExitIo && writeError) return io::ioErrorAt(o.output, "cannot write", errno);
        if (rc) { // already reported; the temporary file is removed
            io::IoError stop;
            stop.kind = io::IoError::Data;
            return stop;
        }
        f.flush();
        const int err = errno;
        f.close();
        if (f.fail()) return io::ioErrorAt(o.output, "cannot write", err);
        return io::IoError{};
    });
    if (rc && !(rc == kExitIo && writeError)) return rc;
    if (e) return printIoError(e);
    return kExitOk;
}

// `gale eval SCENE.toml`: the scene's summed wind at the origin or at every point. --set
// overrides scene keys by dotted path; --fps defaults to the scene's.
int runEvalScene(const EvalOptions& o, bool fpsGiven, bool havePoints, io::PointFormat format) {
    if (o.disasm) {
        printError("--disasm needs an expression (FILE.se or -e EXPR), not a scene");
        return kExitUsage;
    }
    if (o.source.type == "float") {
        printError("a scene's wind is a vector: --type float cannot apply to " + o.source.file);
        return kExitUsage;
    }
    fields::Scene scene;
    std::vector<scene::SceneError> errors;
    gale::scene::SceneLoadOptions options;
    options.sets = o.source.sets;
    if (!gale::scene::loadScene(o.source.file, scene, errors, options))
        return printSceneErrors(errors);
    const bool asFloat = o.precision != "double";
    std::string report;
    fields::FieldPtr field = fields::buildSceneField(
        scene, asFloat ? runtime::Precision::Float : runtime::Precision::Double, report,
        useColor(), o.source.allowPaths);
    if (!report.empty()) std::cerr << report << std::flush;
    if (!field) return kExitInput;

    const double fps = fpsGiven ? o.fps : scene.settings.fps;
    fields::SampleTime when;
    when.fps = fps;
    when.frameZero = scene.settings.timeZero;
    when.time = o.hasTime ? o.time : o.hasFrame ? (o.frame - scene.settings.timeZero) / fps : 0.0;
    when.threads = o.threads >= 0 ? o.threads : havePoints ? 0 : 1;
    if (havePoints && streamsPoints(o, format)) {
        PointStream stream;
        if (int rc = openPointStream(o.points, stream)) return rc;
        std::vector<double> positions, velocities;
        auto eval = [&](io::PointSet& chunk, size_t, size_t& bad) -> int {
            const size_t n = chunk.size();
            positions.assign(3 * n, 0.0);
            const int axes[3] = {chunk.find("x"), chunk.find("y"), chunk.find("z")};
            for (int k = 0; k < 3; ++k) {
                const std::vector<double>& col = chunk.columns[static_cast<size_t>(axes[k])];
                for (size_t i = 0; i < n; ++i) positions[3 * i + static_cast<size_t>(k)] = col[i];
            }
            velocities.assign(3 * n, 0.0);
            fields::SampleStatus status =
                field->sample(positions.data(), n, when, velocities.data());
            if (!status.ok) {
                printError("cannot evaluate " + o.source.file + ": " + status.message);
                return kExitInput;
            }
            if (status.nonFinite > 0) {
                if (o.checked)
                    bad += status.nonFinite;
                else
                    printError("warning: " + status.message);
            }
            addResultColumns(chunk, velocities, 3, asFloat);
            return kExitOk;
        };
        return streamPoints(o, stream, eval, [](size_t bad, size_t total) {
            printError(std::to_string(bad) + " of " + std::to_string(total) +
                       " point(s) gave a non-finite velocity; nothing was written");
            return kExitNumeric;
        });
    }
    io::PointSet points;
    if (havePoints) {
        if (int rc = loadEvalPoints(o.points, points)) return rc;
    }
    const size_t n = havePoints ? points.size() : 1;
    std::vector<double> positions(3 * n, 0.0);
    if (havePoints) {
        const int axes[3] = {points.find("x"), points.find("y"), points.find("z")};
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k)
                positions[3 * i + static_cast<size_t>(k)] =
                    points.columns[static_cast<size_t>(axes[k])][i];
    }
    std::vector<double> velocities(3 * n, 0.0);
    fields::SampleStatus status = field->sample(positions.data(), n, when, velocities.data());
    if (!status.ok) {
        printError("cannot evaluate " + o.source.file + ": " + status.message);
        return kExitInput;
    }
    if (status.nonFinite > 0) {
        if (o.checked) {
            printError(std::to_string(status.nonFinite) + " of " + std::to_string(n) +
                       " point(s) gave a non-finite velocity; nothing was written");
            return kExitNumeric;
        }
        printError("warning: " + status.message);
    }
    if (!havePoints) {
        std::string line;
        for (int k = 0; k < 3; ++k)
            line += (k ? " " : "") + formatValue(velocities[static_cast<size_t>(k)], asFloat);
        return writeValueLine(o, line);
    }
    return writePointResults(o, points, velocities, 3, asFloat, format);
}

int runEvalImpl(const EvalOptions& o, bool fpsGiven);

} // namespace

int runEval(const EvalOptions& o) { return runEvalImpl(o, true); }

namespace {

int runEvalImpl(const EvalOptions& o, bool fpsGiven) {
    if (o.source.file == "-" && o.points == "-") {
        printError("the expression and the points cannot both come from stdin");
        return kExitUsage;
    }
    if (!(o.fps > 0) || !std::isfinite(o.fps)) {
        printError("--fps must be a positive number");
        return kExitUsage;
    }
    const bool scene = o.source.expr.empty() && isSceneFile(o.source.file);
    std::vector<SetValue> sets;
    if (!scene && !parseSets(o.source.sets, sets)) return kExitUsage;
    const bool havePoints = !o.points.empty();
    io::PointFormat format = io::PointFormat::Csv;
    if (havePoints) {
        io::PointFormat inFormat;
        if (o.points != "-" && !io::formatFromPath(o.points, inFormat)) {
            printError("cannot tell the point file type of '" + o.points +
                       "': use .csv, .ply or .obj");
            return kExitUsage;
        }
        if (!chooseFormat(o, format)) return kExitUsage;
    } else if (!o.format.empty()) {
        printError("--format needs --points (without points the value is printed as text)");
        return kExitUsage;
    }
    if (scene) return runEvalScene(o, fpsGiven, havePoints, format);
    lang::SourceFile source;
    if (int rc = loadSource(o.source.file, o.source.expr, source)) return rc;

    // Time: --time and --frame each default from the other through --fps.
    const double t = o.hasTime ? o.time : o.hasFrame ? o.frame / o.fps : 0.0;
    const double frame = o.hasFrame ? o.frame : t * o.fps;

    const bool stream = havePoints && streamsPoints(o, format);
    PointStream pointStream;
    io::PointSet points;
    if (stream) {
        if (int rc = openPointStream(o.points, pointStream)) return rc;
        points = pointStream.header; // no rows: the columns give the variables' types
    } else if (havePoints) {
        if (int rc = loadEvalPoints(o.points, points)) return rc;
    }
    Bindings bindings(t, frame, o.fps);
    if (havePoints) bindings.addPoints(points);
    // Declared parameters (`$speed = 5;  # 0, 40`) become uniforms that --set overrides.
    const lang::SourceFile compiled = bindParameters(source, bindings);
    bindings.addSets(sets);

    const geometry::FileAccess files = geometry::fileAccessFor(o.source.file, o.source.allowPaths);
    std::shared_ptr<const runtime::Program> program = compileAndReport(
        compiled, bindings.variables(), wantWidthFor(o.source.type), &source, &files);
    if (!program) return kExitInput;
    if (o.disasm) {
        std::cout << program->disassemble() << std::flush;
        return std::cout ? kExitOk : kExitIo;
    }
    if (havePoints && program->resultIsString()) {
        printError("the expression gives a string (" + source.name() +
                   "), which cannot be stored in a point file");
        return kExitInput;
    }

    // One value (no --points) is evaluated in double unless asked otherwise: speed is moot
    // there, and double gives SeExpr2's numbers exactly. Point sets default to float.
    const bool asFloat = o.precision.empty() ? havePoints : o.precision == "float";
    const int width = program->resultIsString() ? 1 : program->resultWidth();
    if (stream) {
        std::vector<double> ids, values;
        std::vector<std::string> strings;
        runtime::EvalResult firstBad; // --checked: the evaluation that found the first one
        const std::vector<fields::ParameterDecl> params = fields::findParameters(source);
        auto eval = [&](io::PointSet& chunk, size_t first, size_t& bad) -> int {
            const size_t n = chunk.size();
            ids.resize(n);
            for (size_t i = 0; i < n; ++i) ids[i] = static_cast<double>(first + i);
            Bindings b(t, frame, o.fps);
            b.setVarying("id", 1, ids.data(), 1, 1); // the point's index in the whole file
            b.addPoints(chunk);
            for (const fields::ParameterDecl& p : params) b.setUniform(p.name, p.defaultValue);
            b.addSets(sets); // (the order of bindParameters: columns, parameters, --set)
            runtime::EvalRequest request;
            request.count = n;
            b.fillRequest(request);
            request.threads = o.threads >= 0 ? o.threads : 0;
            request.checked = o.checked;
            runtime::EvalResult r =
                asFloat ? evaluateInto<float>(*program, request, width, values, strings)
                        : evaluateInto<double>(*program, request, width, values, strings);
            if (!r.messages.empty()) std::cerr << r.messages << std::flush;
            if (!r.ok) {
                printError("cannot evaluate " + source.name() + ": " + r.error);
                return kExitInput;
            }
            if (r.nonFinite > 0) {
                const size_t count = r.nonFinite;
                if (bad == 0) {
                    firstBad = std::move(r);
                    firstBad.firstBadPoint += first;
                }
                bad += count;
            }
            addResultColumns(chunk, values, width, asFloat);
            return kExitOk;
        };
        return streamPoints(o, pointStream, eval, [&](size_t bad, size_t total) {
            firstBad.nonFinite = bad;
            return reportNonFinite(source, firstBad, total);
        });
    }

    runtime::EvalRequest request;
    request.count = havePoints ? points.size() : 1;
    bindings.fillRequest(request);
    request.threads = o.threads >= 0 ? o.threads : havePoints ? 0 : 1;
    request.checked = o.checked;
    std::vector<double> values;
    std::vector<std::string> strings;
    runtime::EvalResult r = asFloat
                                ? evaluateInto<float>(*program, request, width, values, strings)
                                : evaluateInto<double>(*program, request, width, values, strings);
    if (!r.messages.empty()) std::cerr << r.messages << std::flush;
    if (!r.ok) {
        printError("cannot evaluate " + source.name() + ": " + r.error);
        return kExitInput;
    }
    if (o.checked && r.nonFinite > 0) return reportNonFinite(source, r, request.count);

    if (!havePoints) {
        std::string line;
        if (program->resultIsString()) {
            line = strings.empty() ? std::string() : strings[0];
        } else {
            for (int k = 0; k < width; ++k) {
                if (k) line += ' ';
                line += formatValue(values[static_cast<size_t>(k)], asFloat);
            }
        }
        return writeValueLine(o, line);
    }
    return writePointResults(o, points, values, width, asFloat, format);
}

} // namespace

Command addEvalCommand(CLI::App& app) {
    auto o = std::make_shared<EvalOptions>();
    CLI::App* sub = app.add_subcommand(
        "eval", "Evaluate an expression once (printing the value on one line: '7', '1 2 3', a "
                "string raw) or at every point of --points (writing the points with vx,vy,vz or "
                "value columns added).");
    addSourceOptions(*sub, o->source);
    sub->add_option("--points", o->points,
                    "Evaluate at every point of this file: .csv with a header naming x,y,z, .ply "
                    "(ascii or binary), .obj vertices; '-' reads CSV from stdin. Every column "
                    "becomes a varying variable: $P from x,y,z, $N from nx,ny,nz, others by name")
        ->type_name("IN");
    sub->add_option_function<double>(
           "--time",
           [o](const double& v) {
               o->time = v;
               o->hasTime = true;
           },
           "$t in seconds (default: --frame / --fps, else 0)")
        ->type_name("T");
    sub->add_option_function<double>(
           "--frame",
           [o](const double& v) {
               o->frame = v;
               o->hasFrame = true;
           },
           "$frame (default: --time * --fps)")
        ->type_name("F");
    CLI::Option* fps = sub->add_option("--fps", o->fps,
                                       "$fps, frames per second (a scene's own fps by default)")
                           ->capture_default_str();
    sub->add_option("--precision", o->precision,
                    "Evaluate in float or double (default: float with --points, double for a "
                    "single value)")
        ->check(CLI::IsMember({"float", "double"}));
    sub->add_option("--threads", o->threads,
                    "Threads; 0 = all hardware threads (default: all with --points, else 1). "
                    "Results do not depend on it")
        ->type_name("N")
        ->check(CLI::Range(0, 4096));
    sub->add_option("-o,--output", o->output,
                    "Write here instead of stdout ('-' is stdout); written to a temporary file "
                    "and renamed, never half-written. Without --points the value line is written")
        ->type_name("OUT");
    sub->add_option("--format", o->format,
                    "Point output format (default: from the -o extension, else csv). ply is "
                    "binary little-endian with float properties; npy holds only the result "
                    "columns, float32, shape (N,3) or (N,)")
        ->type_name("FMT")
        ->check(CLI::IsMember({"csv", "ply", "ply-ascii", "json", "npy", "obj"}));
    sub->add_flag("--disasm", o->disasm,
                  "Print the compiled program's bytecode instead of evaluating");
    sub->add_flag("--checked", o->checked,
                  "Check every result for NaN/infinity: report the operation that produced the "
                  "first one and exit 4 without writing output");
    sub->footer("Standard variables: $P (position, varying; (0,0,0) without --points), $t,\n"
                "$frame, $fps (uniform), $id (point index, varying).\n"
                "A SCENE.toml in place of FILE samples the scene's summed wind (vx vy vz);\n"
                "--set then overrides scene keys by dotted path (windicator.speed=12,\n"
                "field.NAME.params.PARAM=3, scene.fps=30).");
    return {sub, [o, fps] { return runEvalImpl(*o, fps->count() > 0); }};
}

} // namespace gale::cli
