// The public face of the runtime: compile source text into a Program (parse, type-check,
// fold constants, lay out registers), then evaluate it over many points — in float or
// double, over blocks of kBlockSize lanes, on any number of threads with identical results.
#pragma once

#include "lang/bytecode.h"
#include "lang/compiler.h"
#include "lang/diagnostics.h"
#include "runtime/builtins.h"

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace gale::runtime {

enum class Precision { Float, Double };

struct CompileSettings {
    // Host variables the program may read ($P, $t, ...). See standardVariables().
    std::vector<lang::HostVariable> variables;
    // 0 keeps the natural result type; n asks for FP[n] (a scalar result is promoted).
    int wantWidth = 0;
    std::shared_ptr<const FunctionTable> functions; // null: FunctionTable::standard()
    bool fold = true;
};

// $P (FP[3] varying), $t, $frame, $fps (FP[1] uniform), $id (FP[1] varying).
std::vector<lang::HostVariable> standardVariables();

// Where each register lives during evaluation (computed once per Program).
struct RegLocation {
    enum Area : uint8_t { Constant, Uniform, Varying } area = Varying;
    bool isString = false;
    int32_t offset = 0;     // first element in its area (strings: index in the string area)
    int32_t compStride = 0; // distance between components
};

class Program {
public:
    // Null when the source has errors; every diagnostic is in `sink`.
    static std::shared_ptr<const Program> compile(const lang::SourceFile& source,
                                                  const CompileSettings& settings,
                                                  lang::DiagnosticSink& sink);

    const lang::Bytecode& bytecode() const { return mBytecode; }
    const lang::Type& resultType() const { return mBytecode.resultType; }
    int resultWidth() const { return mBytecode.resultType.width; }
    bool resultIsString() const { return mBytecode.resultType.isString(); }
    const FunctionTable& functions() const { return *mFunctions; }
    const std::shared_ptr<const FunctionTable>& functionTable() const { return mFunctions; }
    std::string disassemble() const;

    // ---- evaluation layout (used by the VM) ----
    const std::vector<RegLocation>& locations() const { return mLocations; }
    // Instructions run once per evaluation call (uniform results), then once per block.
    const std::vector<int32_t>& uniformCode() const { return mUniformCode; }
    const std::vector<int32_t>& varyingCode() const { return mVaryingCode; }
    size_t uniformSize() const { return mUniformSize; }
    size_t varyingSize() const { return mVaryingSize; }
    size_t uniformStrings() const { return mUniformStrings; }
    size_t varyingStrings() const { return mVaryingStrings; }

private:
    void layout();

    lang::Bytecode mBytecode;
    std::shared_ptr<const FunctionTable> mFunctions;
    std::vector<RegLocation> mLocations;
    std::vector<int32_t> mUniformCode, mVaryingCode;
    size_t mUniformSize = 0, mVaryingSize = 0;
    size_t mUniformStrings = 0, mVaryingStrings = 0;
};

// A uniform host value for one evaluation call (a --set parameter, $t, ...).
struct UniformValue {
    std::string name;
    std::vector<double> value; // numeric value (its size is the width)
    std::string text;          // used when the variable is a string
};

// A varying host input: component k of point i is data[i * pointStride + k * compStride].
struct VaryingInput {
    std::string name;
    int width = 1;
    const double* data = nullptr;
    std::ptrdiff_t pointStride = 1;
    std::ptrdiff_t compStride = 1;
};

struct EvalRequest {
    size_t count = 1; // number of points
    std::vector<UniformValue> uniforms;
    std::vector<VaryingInput> varyings; // `id` is filled with the point index if not given
    int threads = 1;     // 0: all hardware threads. Results do not depend on it.
    bool checked = false; // report the first non-finite result with the producing op's span
};

// Where results go: component k of point i at data[i * pointStride + k * compStride];
// string results go to strings[i].
template <class T>
struct EvalOutput {
    T* data = nullptr;
    std::ptrdiff_t pointStride = 1;
    std::ptrdiff_t compStride = 1;
    std::string* strings = nullptr;
};

struct EvalResult {
    bool ok = true;
    std::string error;       // why evaluation could not run (missing binding, ...)
    std::string messages;    // printf output, in point order
    size_t nonFinite = 0;    // checked mode: points whose result is NaN or infinite
    size_t firstBadPoint = 0;
    std::vector<lang::Diagnostic> diagnostics; // checked mode: where the first one came from
};

template <class T>
EvalResult evaluate(const Program& program, const EvalRequest& request, const EvalOutput<T>& out);

extern template EvalResult evaluate<float>(const Program&, const EvalRequest&, const EvalOutput<float>&);
extern template EvalResult evaluate<double>(const Program&, const EvalRequest&, const EvalOutput<double>&);

} // namespace gale::runtime
