// Helpers shared by the subcommands: sources, --set values, host bindings, compiling with
// diagnostics on stderr, number output and atomic text files.
#include "cli/common.h"
#include "io/atomic_file.h"

#include "fields/expression_field.h"

#include <CLI/CLI.hpp>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <unistd.h>

namespace gale::cli {

void printError(const std::string& message) {
    std::cerr << "gale: " << message << '\n';
}

int printSceneErrors(const std::vector<scene::SceneError>& errors) {
    bool io = false;
    for (const scene::SceneError& e : errors) {
        std::string text = e.render();
        if (text.empty() || text.back() != '\n') text += '\n';
        std::cerr << text;
        io = io || e.io;
    }
    std::cerr << std::flush;
    return io ? kExitIo : kExitInput;
}

bool useColor() {
    const char* noColor = std::getenv("NO_COLOR");
    if (noColor && *noColor) return false;
    return ::isatty(STDERR_FILENO) != 0;
}

bool readTextFile(const std::string& path, std::string& text, std::string& error) {
    if (path == "-") {
        std::ostringstream ss;
        ss << std::cin.rdbuf();
        text = ss.str();
        if (std::cin.bad()) {
            error = std::strerror(errno);
            return false;
        }
        return true;
    }
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        error = std::strerror(EISDIR);
        return false;
    }
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error = errno ? std::strerror(errno) : "cannot open";
        return false;
    }
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) {
        error = std::strerror(errno);
        return false;
    }
    return true;
}

int loadSource(const std::string& file, const std::string& expr, lang::SourceFile& out) {
    if (!file.empty() && !expr.empty()) {
        printError("give either an expression file or -e EXPR, not both");
        return kExitUsage;
    }
    if (file.empty() && expr.empty()) {
        printError("no expression: give an expression file (FILE.se) or -e EXPR");
        return kExitUsage;
    }
    if (!expr.empty()) {
        out = lang::SourceFile("<expr>", expr);
        return kExitOk;
    }
    std::string text, error;
    if (!readTextFile(file, text, error)) {
        printError("cannot read '" + file + "': " + error);
        return kExitIo;
    }
    out = lang::SourceFile(file == "-" ? "<stdin>" : file, std::move(text));
    return kExitOk;
}

static bool validName(const std::string& s) {
    if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
    for (char c : s)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.')) return false;
    return true;
}

static std::string trim(const std::string& s) {
    size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

bool parseSets(const std::vector<std::string>& sets, std::vector<SetValue>& out) {
    out.clear();
    for (const std::string& s : sets) {
        size_t eq = s.find('=');
        SetValue v;
        v.name = trim(eq == std::string::npos ? s : s.substr(0, eq));
        if (!v.name.empty() && v.name[0] == '$') v.name.erase(0, 1);
        if (eq == std::string::npos || !validName(v.name)) {
            printError("--set '" + s +
                       "': expected NAME=VALUE with a variable name such as "
                       "speed or wind.gain");
            return false;
        }
        std::string value = trim(s.substr(eq + 1));
        if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') &&
            value.back() == value.front()) {
            v.isString = true;
            v.text = value.substr(1, value.size() - 2);
            out.push_back(std::move(v));
            continue;
        }
        std::stringstream parts(value);
        std::string part;
        bool ok = !value.empty();
        while (ok && std::getline(parts, part, ',')) {
            part = trim(part);
            const char* a = part.data();
            const char* e = a + part.size();
            if (part.size() > 1 && *a == '+') ++a;
            double d = 0.0;
            std::from_chars_result r = std::from_chars(a, e, d);
            ok = !part.empty() && r.ec == std::errc() && r.ptr == e;
            v.value.push_back(d);
        }
        if (ok && !value.empty() && value.back() == ',') ok = false;
        if (!ok || v.value.empty() || v.value.size() > static_cast<size_t>(lang::kMaxWidth)) {
            printError("--set '" + s + "': the value must be a number, up to " +
                       std::to_string(lang::kMaxWidth) +
                       " comma-separated numbers (1,2,3), or a "
                       "quoted string");
            return false;
        }
        out.push_back(std::move(v));
    }
    return true;
}

int wantWidthFor(const std::string& type) {
    if (type == "float") return 1;
    if (type == "vector") return 3;
    return 0;
}

// ---- Bindings ----

Bindings::Bindings(double t, double frame, double fps) {
    static const double kOrigin[3] = {0.0, 0.0, 0.0};
    for (const lang::HostVariable& v : runtime::standardVariables()) declare(v.name, v.type);
    setVarying("P", 3, kOrigin, 0, 1);
    setUniform("t", {t});
    setUniform("frame", {frame});
    setUniform("fps", {fps});
    // $id stays declared without an input: the VM fills it with the point index.
}

void Bindings::declare(const std::string& name, lang::Type type) {
    // By index, not a scan: 10^5 parameters must not take quadratic time.
    const auto [at, fresh] = mIndex.emplace(name, mVariables.size());
    if (!fresh) {
        mVariables[at->second].type = type;
        return;
    }
    mVariables.push_back({name, type});
}

void Bindings::forget(const std::string& name) {
    if (mBound.insert(name).second) return; // never bound: nothing to drop
    for (size_t i = mUniforms.size(); i-- > 0;)
        if (mUniforms[i].name == name)
            mUniforms.erase(mUniforms.begin() + static_cast<std::ptrdiff_t>(i));
    for (size_t i = mVaryings.size(); i-- > 0;)
        if (mVaryings[i].name == name)
            mVaryings.erase(mVaryings.begin() + static_cast<std::ptrdiff_t>(i));
}

void Bindings::setUniform(const std::string& name, std::vector<double> value) {
    declare(name, lang::Type::fp(static_cast<int>(value.size()), lang::Lifetime::Uniform));
    forget(name);
    runtime::UniformValue u;
    u.name = name;
    u.value = std::move(value);
    mUniforms.push_back(std::move(u));
}

void Bindings::setUniformString(const std::string& name, std::string text) {
    declare(name, lang::Type::string(lang::Lifetime::Uniform));
    forget(name);
    runtime::UniformValue u;
    u.name = name;
    u.text = std::move(text);
    mUniforms.push_back(std::move(u));
}

void Bindings::setVarying(const std::string& name, int width, const double* data,
                          std::ptrdiff_t pointStride, std::ptrdiff_t compStride) {
    declare(name, lang::Type::fp(width, lang::Lifetime::Varying));
    forget(name);
    runtime::VaryingInput v;
    v.name = name;
    v.width = width;
    v.data = data;
    v.pointStride = pointStride;
    v.compStride = compStride;
    mVaryings.push_back(v);
}

void Bindings::addPoints(const io::PointSet& points) {
    const size_t n = points.size();
    for (const io::PointVariable& pv : io::pointVariables(points)) {
        const int width = static_cast<int>(pv.columns.size());
        if (width == 1) {
            setVarying(pv.name, 1, points.columns[static_cast<size_t>(pv.columns[0])].data(), 1, 1);
            continue;
        }
        std::vector<double>& aos = mStorage.emplace_back(n * static_cast<size_t>(width));
        for (int k = 0; k < width; ++k) {
            const std::vector<double>& col =
                points.columns[static_cast<size_t>(pv.columns[static_cast<size_t>(k)])];
            for (size_t i = 0; i < n; ++i)
                aos[i * static_cast<size_t>(width) + static_cast<size_t>(k)] = col[i];
        }
        setVarying(pv.name, width, aos.data(), width, 1);
    }
}

void Bindings::addSets(const std::vector<SetValue>& sets) {
    for (const SetValue& s : sets) {
        if (s.isString)
            setUniformString(s.name, s.text);
        else
            setUniform(s.name, s.value);
    }
}

void Bindings::fillRequest(runtime::EvalRequest& request) const {
    request.uniforms = mUniforms;
    request.varyings = mVaryings;
}

// ---- compiling, points, output ----

std::shared_ptr<const runtime::Program>
compileAndReport(const lang::SourceFile& source, const std::vector<lang::HostVariable>& variables,
                 int wantWidth, const lang::SourceFile* shown, const geometry::FileAccess* files) {
    runtime::CompileSettings settings;
    settings.variables = variables;
    settings.wantWidth = wantWidth;
    settings.functions = files ? fields::fieldFunctions(*files) : fields::fieldFunctions();
    lang::DiagnosticSink sink;
    std::shared_ptr<const runtime::Program> program =
        runtime::Program::compile(source, settings, sink);
    if (!sink.diagnostics().empty()) {
        lang::RenderOptions options;
        options.color = useColor();
        std::cerr << lang::renderDiagnostics(shown ? *shown : source, sink, options) << std::flush;
    }
    if (sink.hasErrors()) return nullptr;
    return program;
}

lang::SourceFile bindParameters(const lang::SourceFile& source, Bindings& bindings) {
    const std::vector<fields::ParameterDecl> params = fields::findParameters(source);
    for (const fields::ParameterDecl& p : params) bindings.setUniform(p.name, p.defaultValue);
    return fields::withoutParameters(source, params);
}

int loadPoints(const std::string& path, io::PointSet& points) {
    io::IoError e = io::readPoints(path, points, &std::cin);
    if (!e) return kExitOk;
    std::cerr << e.render() << '\n';
    return e.kind == io::IoError::Io ? kExitIo : kExitInput;
}

std::string formatValue(double v, bool asFloat) {
    if (!asFloat || !std::isfinite(v)) return io::formatNumber(v);
    char buf[64];
    std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, static_cast<float>(v));
    return std::string(buf, r.ptr);
}

int writeTextFileAtomic(const std::string& path, const std::string& text) {
    io::IoError e = io::writeBytesAtomic(path, text);
    if (e) {
        printError(e.render());
        return kExitIo;
    }
    return kExitOk;
}


std::string wrapHelp(const std::string& text, size_t width) {
    std::string out, word;
    size_t lineLength = 0;
    auto flushWord = [&] {
        if (word.empty()) return;
        if (lineLength > 0 && lineLength + 1 + word.size() > width) {
            out += '\n';
            lineLength = 0;
        } else if (lineLength > 0) {
            out += ' ';
            ++lineLength;
        }
        out += word;
        lineLength += word.size();
        word.clear();
    };
    for (char c : text) {
        if (c == ' ') {
            flushWord();
        } else if (c == '\n') {
            flushWord();
            out += '\n';
            lineLength = 0;
        } else {
            word += c;
        }
    }
    flushWord();
    return out;
}

void addAllowPathOption(CLI::App& app, std::vector<std::string>& allowPaths) {
    app.add_option("--allow-path", allowPaths,
                   "Let files named by expressions (sdf(\"body.obj\", $P), vdb(...)) come from "
                   "this folder too; by default they must be inside the folder of the "
                   "expression or scene file. Repeatable")
        ->type_name("DIR")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void addSourceOptions(CLI::App& app, SourceOptions& options, bool withType, bool scenes) {
    CLI::Option* file =
        scenes ? app.add_option("file", options.file,
                                "Expression file (.se; '-' reads stdin) or scene file (.toml)")
                     ->type_name("FILE|SCENE")
               : app.add_option("file", options.file, "Expression file (.se); '-' reads it from stdin")
                     ->type_name("FILE");
    CLI::Option* expr =
        app.add_option("-e,--expr", options.expr, "Expression text instead of a file")
            ->type_name("EXPR");
    file->excludes(expr);
    expr->excludes(file);
    app.add_option("--set", options.sets,
                   scenes ? "Expression: override parameter (or bind variable) $NAME with a number or "
                            "x,y,z. Scene: override a key by its dotted path (windicator.speed=12). "
                            "Repeatable"
                          : "Bind host variable $NAME as a uniform: a number (5), a vector (1,2,3) or a "
                            "quoted string; repeatable")
        ->type_name("NAME=VALUE")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    addAllowPathOption(app, options.allowPaths);
    if (withType)
        app.add_option("--type", options.type,
                       "Wanted result: auto keeps the expression's width; float wants FP[1] (a "
                       "vector result is an error); vector wants FP[3] (a scalar is promoted)")
            ->check(CLI::IsMember({"auto", "float", "vector"}))
            ->capture_default_str();
}

bool parseFrames(const std::string& text, int& a, int& b) {
    const size_t colon = text.find(':');
    if (colon == std::string::npos) return false;
    try {
        size_t used = 0;
        a = std::stoi(text.substr(0, colon), &used);
        if (used != colon) return false;
        const std::string rest = text.substr(colon + 1);
        b = std::stoi(rest, &used);
        if (used != rest.size()) return false;
    } catch (...) {
        return false;
    }
    return b >= a && static_cast<long>(b) - a < kMaxFrames;
}

} // namespace gale::cli
