// How the compiler sees built-in functions: a name, a typed signature (which is also the
// documentation `gale builtins` prints), a fold flag and a docstring. The table itself and
// the kernels live in runtime/; lang only type-checks calls against it.
#pragma once

#include "lang/diagnostics.h"
#include "lang/types.h"

#include <string>
#include <string_view>
#include <vector>

namespace gale::lang {

// A call being type-checked, handed to a function's extra validation hook.
struct CallSite {
    std::string_view name;
    Span span;     // the whole call
    Span nameSpan; // the function name
    std::vector<Type> argTypes;
    std::vector<Span> argSpans;
    // For each argument: its value when it is a compile-time constant float (all components),
    // else empty. Lets a hook check e.g. that interpolation codes are 0..4.
    std::vector<std::vector<double>> constValues;
    std::vector<const std::string*> constStrings; // constant string arguments, else null
    DiagnosticSink* sink = nullptr;
    // A hook may override the result type the signature gives (kind and width; the compiler
    // fills the lifetime).
    Type resultType = Type::error();
    // The function's FunctionInfo::hookData (e.g. the folder its file names resolve against).
    const void* data = nullptr;
};

// One parameter of a parsed signature.
struct ParamSpec {
    enum Kind : uint8_t { Float, String, Any } kind = Float;
    int width = 1;          // Float: fixed width, or 0 for the broadcast width `n`
    std::string name;
    bool hasDefault = false;
    double defaultValue = 0.0;
};

struct ParsedSignature {
    ParamSpec result;               // kind/width of the result (width 0 = broadcast width n)
    std::vector<ParamSpec> params;
    bool variadic = false;          // the last parameter repeats (`...`)
    int minArgs = 0;                // parameters before the first default
};

// Parse "FP[3] rotate(FP[3] v, FP[3] axis, FP[1] angle)". Types: FP[k], FP[n] (the broadcast
// width shared by all FP[n] parameters and the result), STRING, ANY; `= number` gives a
// default; a trailing `...` makes the last parameter repeat. Returns false with a message on
// malformed input (a bug in a table, caught by a unit test).
bool parseSignature(std::string_view text, ParsedSignature& out, std::string* error);

struct FunctionInfo {
    std::string_view name;
    std::string_view signature; // "FP[n] clamp(FP[n] x, FP[n] lo, FP[n] hi)"
    std::string_view doc;       // one line
    bool foldable = true;       // pure: may be folded when its arguments are constant, and
                                // hoisted (run once per batch) when they are uniform
    bool sideEffects = false;   // printf: never folded or hoisted, runs only on active lanes
    // SeExpr2's scalar-parameter rule for its ramp and colour built-ins (curve, ccurve, hsi,
    // midhsi, saturate, rotate): a vector passed to a fixed FP[1] parameter gives its first
    // component, instead of a width error.
    bool firstComponent = false;
    // Optional extra validation after the signature matched; reports to site.sink and
    // returns false on error; may set site.resultType.
    bool (*validate)(CallSite& site) = nullptr;
    // Handed to `validate` as CallSite::data; owned by the host (runtime::Builtin::data).
    const void* hookData = nullptr;
    // Host variables the compiler appends as extra arguments after the declared ones (e.g.
    // gust(P) also reads $t). A variable the host does not define is passed as the constant
    // `fallback`.
    struct Implicit {
        std::string_view variable;
        double fallback = 0.0;
    };
    std::vector<Implicit> implicitArgs;
    // Filled by the table from `signature` once.
    ParsedSignature parsed;
};

class FunctionScope {
public:
    virtual ~FunctionScope() = default;
    // The function called `name`, or null. `index` receives the value stored in Instr::imm.
    virtual const FunctionInfo* findFunction(std::string_view name, int32_t* index) const = 0;
    // Names for "did you mean" suggestions.
    virtual std::vector<std::string_view> functionNames() const = 0;
};

// Closest candidate by edit distance (for "did you mean 'sin'?"), or empty.
std::string_view closestName(std::string_view name, const std::vector<std::string_view>& candidates);

} // namespace gale::lang
