// `gale eval`: compile an expression and evaluate it once (printing the value on one line) or
// at every point of a point file (writing the points with the result columns added).
#include "cli/commands.h"
#include "cli/common.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <memory>

namespace gale::cli {

namespace {

// Output format from --format, else the -o extension, else CSV. False (after printing) when
// neither names a known format.
bool chooseFormat(const EvalOptions& o, fields::PointFormat& format) {
    if (!o.format.empty()) {
        if (o.format == "csv")
            format = fields::PointFormat::Csv;
        else if (o.format == "ply")
            format = fields::PointFormat::Ply;
        else if (o.format == "ply-ascii")
            format = fields::PointFormat::PlyAscii;
        else if (o.format == "json")
            format = fields::PointFormat::Json;
        else if (o.format == "npy")
            format = fields::PointFormat::Npy;
        else if (o.format == "obj")
            format = fields::PointFormat::Obj;
        else
            return false; // CLI11 has already checked the name
        return true;
    }
    format = fields::PointFormat::Csv;
    if (o.output.empty() || o.output == "-") return true;
    if (fields::formatFromPath(o.output, format)) return true;
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

} // namespace

int runEval(const EvalOptions& o) {
    if (o.source.file == "-" && o.points == "-") {
        printError("the expression and the points cannot both come from stdin");
        return kExitUsage;
    }
    if (!(o.fps > 0) || !std::isfinite(o.fps)) {
        printError("--fps must be a positive number");
        return kExitUsage;
    }
    std::vector<SetValue> sets;
    if (!parseSets(o.source.sets, sets)) return kExitUsage;
    const bool havePoints = !o.points.empty();
    fields::PointFormat format = fields::PointFormat::Csv;
    if (havePoints) {
        fields::PointFormat inFormat;
        if (o.points != "-" && !fields::formatFromPath(o.points, inFormat)) {
            printError("cannot tell the point file type of '" + o.points +
                       "': use .csv, .ply or .obj");
            return kExitUsage;
        }
        if (!chooseFormat(o, format)) return kExitUsage;
    } else if (!o.format.empty()) {
        printError("--format needs --points (without points the value is printed as text)");
        return kExitUsage;
    }
    lang::SourceFile source;
    if (int rc = loadSource(o.source.file, o.source.expr, source)) return rc;

    // Time: --time and --frame each default from the other through --fps.
    const double t = o.hasTime ? o.time : o.hasFrame ? o.frame / o.fps : 0.0;
    const double frame = o.hasFrame ? o.frame : t * o.fps;

    fields::PointSet points;
    if (havePoints) {
        if (int rc = loadPoints(o.points, points)) return rc;
        if (points.find("x") < 0 || points.find("y") < 0 || points.find("z") < 0) {
            std::string have;
            for (const std::string& n : points.names) have += (have.empty() ? "" : ", ") + n;
            std::cerr << (o.points == "-" ? std::string("<stdin>") : o.points)
                      << ": error: the points need x, y and z columns (found: "
                      << (have.empty() ? std::string("none") : have) << ")\n";
            return kExitInput;
        }
    }
    Bindings bindings(t, frame, o.fps);
    if (havePoints) bindings.addPoints(points);
    bindings.addSets(sets);

    std::shared_ptr<const runtime::Program> program =
        compileAndReport(source, bindings.variables(), wantWidthFor(o.source.type));
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

    runtime::EvalRequest request;
    request.count = havePoints ? points.size() : 1;
    bindings.fillRequest(request);
    request.threads = o.threads >= 0 ? o.threads : havePoints ? 0 : 1;
    request.checked = o.checked;
    // One value (no --points) is evaluated in double unless asked otherwise: speed is moot
    // there, and double gives SeExpr2's numbers exactly. Point sets default to float.
    const bool asFloat = o.precision.empty() ? havePoints : o.precision == "float";
    const int width = program->resultIsString() ? 1 : program->resultWidth();
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

    const bool toStdout = o.output.empty() || o.output == "-";
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
        line += '\n';
        if (!toStdout) return writeTextFileAtomic(o.output, line);
        std::cout << line << std::flush;
        return std::cout ? kExitOk : kExitIo;
    }

    // The points with the result columns added (replacing columns of the same names).
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
    const std::vector<int> npyColumns =
        format == fields::PointFormat::Npy ? added : std::vector<int>{};
    if (toStdout) {
        fields::IoError e = fields::writePoints(std::cout, points, format, npyColumns);
        std::cout.flush();
        if (e || !std::cout) {
            printError("cannot write to stdout" + (e ? ": " + e.message : std::string()));
            return e.kind == fields::IoError::Data ? kExitInput : kExitIo;
        }
        return kExitOk;
    }
    fields::IoError e = fields::writePointsFile(o.output, points, format, npyColumns);
    if (e) {
        std::cerr << e.render() << '\n';
        return e.kind == fields::IoError::Data ? kExitInput : kExitIo;
    }
    return kExitOk;
}

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
    sub->add_option("--fps", o->fps, "$fps, frames per second")->capture_default_str();
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
                "$frame, $fps (uniform), $id (point index, varying).");
    return {sub, [o] { return runEval(*o); }};
}

} // namespace gale::cli
