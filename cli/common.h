// Helpers shared by the subcommands: reading sources, --set values, host bindings (standard
// variables, point columns, --set uniforms), compiling with diagnostics printed, number
// output and atomic text files.
#pragma once

#include "cli/commands.h"
#include "io/pointset.h"
#include "lang/source.h"
#include "runtime/program.h"
#include "scene/error.h"

#include <deque>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace CLI {
class App;
class Option;
} // namespace CLI

namespace gale::geometry {
struct FileAccess;
} // namespace gale::geometry

namespace gale::cli {

// "gale: <message>" on stderr.
void printError(const std::string& message);

// Prints every scene error (file:line:col, source line, caret, notes) to stderr; returns the exit
// code they call for: 3 when a file could not be read, else 1.
int printSceneErrors(const std::vector<scene::SceneError>& errors);
// Colour diagnostics when stderr is a terminal and NO_COLOR is unset or empty.
bool useColor();

// Reads a whole file ("-": stdin). On failure `error` is the strerror text.
bool readTextFile(const std::string& path, std::string& text, std::string& error);
// The expression of FILE | -e EXPR as a SourceFile named by the path ("<stdin>" for "-")
// or "<expr>". Returns an exit code (0 on success) after printing any problem.
int loadSource(const std::string& file, const std::string& expr, lang::SourceFile& out);

// --set NAME=VALUE: a number, a comma-separated vector, or a quoted string ("text").
struct SetValue {
    std::string name;
    std::vector<double> value;
    bool isString = false;
    std::string text;
};
// Parses every --set; prints the problem and returns false on a malformed one.
bool parseSets(const std::vector<std::string>& sets, std::vector<SetValue>& out);

// --type auto|float|vector -> CompileSettings::wantWidth.
int wantWidthFor(const std::string& type);

// Host variables and their values for one evaluation: the standard ones, a point set's
// columns (varying), --set values (uniform). A later binding of a name replaces an earlier.
class Bindings {
public:
    // $P = (0,0,0) for one point, $t, $frame, $fps uniforms, $id filled by the VM.
    Bindings(double t, double frame, double fps);

    void setUniform(const std::string& name, std::vector<double> value);
    void setUniformString(const std::string& name, std::string text);
    // Component k of point i at data[i * pointStride + k * compStride]; `data` must outlive
    // the evaluation.
    void setVarying(const std::string& name, int width, const double* data,
                    std::ptrdiff_t pointStride, std::ptrdiff_t compStride);
    // Every column of `points` as a varying variable (P from x,y,z, ...); multi-component
    // variables are interleaved into storage owned here. `points` must outlive evaluation.
    void addPoints(const io::PointSet& points);
    void addSets(const std::vector<SetValue>& sets);

    const std::vector<lang::HostVariable>& variables() const { return mVariables; }
    void fillRequest(runtime::EvalRequest& request) const;

private:
    void declare(const std::string& name, lang::Type type);
    void forget(const std::string& name);

    std::vector<lang::HostVariable> mVariables;
    std::vector<runtime::UniformValue> mUniforms;
    std::vector<runtime::VaryingInput> mVaryings;
    std::deque<std::vector<double>> mStorage;
    std::unordered_map<std::string, size_t> mIndex; // name -> index in mVariables
    std::unordered_set<std::string> mBound;         // names with a uniform or varying value
};

// Compiles `source` against the field layer's built-ins (the standard ones plus gust, fftturb,
// ...), printing every diagnostic (errors and warnings) to stderr, rendered against `shown`
// when given (the text before parameters were blanked). File names in the expression (sdf(),
// vdb(), ...) resolve under `files` (null: the current folder). Null on errors.
std::shared_ptr<const runtime::Program>
compileAndReport(const lang::SourceFile& source, const std::vector<lang::HostVariable>& variables,
                 int wantWidth, const lang::SourceFile* shown = nullptr,
                 const geometry::FileAccess* files = nullptr);

// Adds `--allow-path DIR` (repeatable) to a subcommand.
void addAllowPathOption(CLI::App& app, std::vector<std::string>& allowPaths);

// The parameter idiom (`$speed = 5;  # 0, 40`): binds each declared parameter as a uniform of
// its default value (a later --set of the same name replaces it) and returns the source with
// the declarations blanked, so the bindings win.
lang::SourceFile bindParameters(const lang::SourceFile& source, Bindings& bindings);

// Reads a point file, printing IoError::render() on failure; returns an exit code.
int loadPoints(const std::string& path, io::PointSet& points);

// Shortest round-trip text of a value computed in float (`asFloat`) or double.
std::string formatValue(double v, bool asFloat);

// Writes `text` to `path` through a temporary file and a rename; prints the problem and
// returns kExitIo on failure.
int writeTextFileAtomic(const std::string& path, const std::string& text);

// The most frames one --frames range may span (sample, viz, sim, wedge): 100000 is over an hour
// at 24 fps; a longer run is split into several.
constexpr long kMaxFrames = 100'000;

// `--frames A:B` of sim and wedge: two whole numbers, A <= B, at most kMaxFrames frames (a
// single frame is refused).
bool parseFrames(const std::string& text, int& a, int& b);

// A JSON string literal (the point-set writer's escaping, so every JSON gale writes agrees).
using io::jsonString;

// Word-wraps help text to `width` columns (CLI11 indents the continuation lines).
std::string wrapHelp(const std::string& text, size_t width = 62);

// Adds `FILE` / `-e,--expr` / `--set` / `--type` / `--allow-path` to a subcommand.
void addSourceOptions(CLI::App& app, SourceOptions& options, bool withType = true,
                      bool scenes = false);

} // namespace gale::cli
