// A velocity field written as an expression: compiled once (wanting FP[3]), evaluated over
// batches of points by the block VM. Parameters declared in the file (`$speed = 5; # 0, 40`)
// become uniform variables that a scene, --set or keyframes override by name.
#pragma once

#include "fields/field.h"
#include "fields/keyframes.h"
#include "fields/scene.h"
#include "geometry/file_policy.h"
#include "runtime/program.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace gale::fields {

// A tunable parameter declared by an expression file: a top-level `$name = number;` or
// `$name = [a, b, c];` statement, optionally followed on the same line by `# min, max`.
struct ParameterDecl {
    std::string name;
    std::vector<double> defaultValue;
    bool hasRange = false;
    double min = 0.0, max = 0.0;
    int line = 0; // 1-based source line of the declaration
    lang::Span span;  // the statement, `$` to `;`
    std::string doc;  // the rest of the comment after the range (or the whole comment)
};

// Scans a source for parameter declarations (the SeExpr editors' slider idiom). Only the first
// declaration of a name counts; the host's own variables ($P, $t, $frame, $fps, $id, $windDir,
// $windSpeed) are never parameters.
std::vector<ParameterDecl> findParameters(const lang::SourceFile& source);

// The source with every declaration statement blanked to spaces (newlines kept, so every other
// byte keeps its line and column): the parameters then come from host bindings.
lang::SourceFile withoutParameters(const lang::SourceFile& source,
                                   const std::vector<ParameterDecl>& params);

// Host variables an ExpressionField binds besides the parameters: the standard ones, plus
// $windDir (FP[3]) and $windSpeed when `scene` has a [windicator].
std::vector<lang::HostVariable> fieldVariables(const Scene* scene);

struct ExpressionFieldOptions {
    std::map<std::string, Param> params; // overrides by parameter name (may be keyframed)
    runtime::Precision precision = runtime::Precision::Float;
    // Windicator and gust rigs ($windDir, $windSpeed, gust(P)); read during compile() only (the
    // field copies what it needs), so the scene need not outlive the field.
    const Scene* scene = nullptr;
    // More host variables: given values through sampleWith(), zero when sample() is used.
    std::vector<lang::HostVariable> extraVariables;
    // The built-ins; null: sceneFunctions(*scene) with a scene, else fieldFunctions().
    std::shared_ptr<const runtime::FunctionTable> functions;
    std::string name; // for describe() (default: the source's name)
    // Where file names in the expression (sdf("body.obj", ...), vdb(...)) resolve and which
    // folders they may reach: when set, the geometry built-ins of `functions` are rebound to it
    // (withFileAccess); unset, they resolve against the current folder.
    std::optional<geometry::FileAccess> files;
};

class ExpressionField : public Field {
public:
    // Null on errors (all in `sink`, against `source`). Unknown names in `options.params` are
    // errors too (reported with a note listing the declared parameters).
    static std::shared_ptr<ExpressionField> compile(const lang::SourceFile& source,
                                                    const ExpressionFieldOptions& options,
                                                    lang::DiagnosticSink& sink);

    SampleStatus sample(const double* positions, size_t count, const SampleTime& when,
                        double* velocities) const override;
    // The same with values for extraVariables (uniforms, or varyings of `count` points).
    SampleStatus sampleWith(const double* positions, size_t count, const SampleTime& when,
                            double* velocities, const std::vector<runtime::UniformValue>& uniforms,
                            const std::vector<runtime::VaryingInput>& varyings) const;
    std::string describe() const override;

    const runtime::Program& program() const { return *mProgram; }
    const std::vector<ParameterDecl>& parameters() const { return mParameters; }
    // The value each parameter takes at time t (override or default), by declaration order.
    std::vector<std::vector<double>> parameterValues(double t) const;

private:
    std::shared_ptr<const runtime::Program> mProgram;
    std::vector<ParameterDecl> mParameters;
    std::vector<Param> mValues; // per parameter: the override, else the default
    ExpressionFieldOptions mOptions;        // (with `scene` cleared: the field keeps no pointer)
    std::optional<Windicator> mWindicator; // a copy of the scene's, for $windDir and $windSpeed
    std::string mName;
};

// The standard built-ins plus the field layer's (gust, fftturb, sdf, vdb, ...). File names in
// expressions resolve against the current folder.
std::shared_ptr<const runtime::FunctionTable> fieldFunctions();
// The same with the geometry built-ins resolving file names under `access` (a new table).
std::shared_ptr<const runtime::FunctionTable> fieldFunctions(const geometry::FileAccess& access);

// Registration of the field layer's built-ins (each defined in its own file).
void addGustBuiltins(runtime::FunctionTable& t);       // rigs.cpp: gust(P)
void addTurbulenceBuiltins(runtime::FunctionTable& t); // fftturb.cpp: fftturb, fftturb4
// sdf, sdfgrad, shadow, vdb, meshvel: geometry/builtins.h (addGeometryBuiltins, withFileAccess)

// The expression of a [[field]] entry (its file, preset or inline source) as a SourceFile.
// Inline text held verbatim in the scene is placed at its line and column in a file named after
// the scene, so diagnostics point into the scene. False with `error` when a file is unreadable.
bool fieldSource(const Scene& scene, const FieldEntry& entry, lang::SourceFile& out,
                 std::string& error);

// The summed, compiled wind of a scene: every [[field]] with its params and scale. Diagnostics
// of expression files are rendered (file:line:col + caret) into `report`. Null on errors.
// File names in a field's expression resolve against its file's folder (the scene's for inline
// source) and must stay inside the scene's folder or one of `allowPaths` (--allow-path).
FieldPtr buildSceneField(const Scene& scene, runtime::Precision precision, std::string& report,
                         bool color = false, const std::vector<std::string>& allowPaths = {});

} // namespace gale::fields
