// A velocity field written as an expression: compiled once (wanting FP[3]), evaluated over
// batches of points by the block VM. Parameters declared in the file (`$speed = 5; # 0, 40`)
// become uniform variables that a scene, --set or keyframes override by name.
#pragma once

#include "fields/field.h"
#include "fields/keyframes.h"
#include "fields/scene.h"
#include "runtime/program.h"

#include <map>
#include <memory>
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
};

// Scans a source for parameter declarations (the SeExpr editors' slider idiom).
std::vector<ParameterDecl> findParameters(const lang::SourceFile& source);

struct ExpressionFieldOptions {
    std::map<std::string, Param> params; // overrides by parameter name (may be keyframed)
    runtime::Precision precision = runtime::Precision::Float;
    const Scene* scene = nullptr;        // windicator/gust rigs: $windDir, $windSpeed, gust(P)
    std::vector<lang::HostVariable> extraVariables;
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
    std::string describe() const override;

    const runtime::Program& program() const { return *mProgram; }
    const std::vector<ParameterDecl>& parameters() const { return mParameters; }

private:
    std::shared_ptr<const runtime::Program> mProgram;
    std::vector<ParameterDecl> mParameters;
    ExpressionFieldOptions mOptions;
    std::string mName;
};

// The standard built-ins plus the field layer's (gust, fftturb, ...).
std::shared_ptr<const runtime::FunctionTable> fieldFunctions();

// Registration of the field layer's built-ins (each defined in its own file).
void addGustBuiltins(runtime::FunctionTable& t);       // rigs.cpp: gust(P)
void addTurbulenceBuiltins(runtime::FunctionTable& t); // fftturb.cpp: fftturb, fftturb4

// The summed, compiled wind of a scene: every [[field]] with its params and scale. Diagnostics
// of expression files are rendered (file:line:col + caret) into `report`. Null on errors.
FieldPtr buildSceneField(const Scene& scene, runtime::Precision precision, std::string& report,
                         bool color = false);

} // namespace gale::fields
