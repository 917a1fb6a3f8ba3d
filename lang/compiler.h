// Type checker and code generator in one walk over the AST: infers FP[n]/STRING types and
// lifetimes, merges variables after if/else, inlines `def` functions per call site
// (monomorphised), folds constant work through the host's folder, and emits Bytecode.
#pragma once

#include "lang/ast.h"
#include "lang/bytecode.h"
#include "lang/diagnostics.h"
#include "lang/functions.h"

#include <optional>
#include <string>
#include <vector>

namespace gale::lang {

// Evaluates one instruction whose operands are all constant, so its result can become a
// constant (the runtime implements this with the same kernels the VM runs).
class ConstantFolder {
public:
    virtual ~ConstantFolder() = default;
    // Writes the destination's components to `values` (numeric) or `text` (string).
    virtual bool fold(const Bytecode& bc, const Instr& instr, std::vector<double>& values,
                      std::string& text) const = 0;
};

struct HostVariable {
    std::string name; // without '$'
    Type type;        // width and lifetime (uniform or varying)
};

struct CompileOptions {
    std::vector<HostVariable> variables;
    const FunctionScope* functions = nullptr;
    const ConstantFolder* folder = nullptr; // null: no folding
    // The host's wanted result: 0 keeps the natural type; 1..16 asks for FP[n] (a scalar
    // result is promoted, another width is an error).
    int wantWidth = 0;
    bool allowStringResult = true;
    size_t maxInstructions = 1'000'000;
    uint32_t maxInlineDepth = 64;
    // def calls expanded in all (each inlines the body: a def calling another twice doubles).
    size_t maxInlinedCalls = 100'000;
};

// Null when there were errors (all of them are in `sink`).
std::optional<Bytecode> compile(const Ast& ast, const CompileOptions& options, DiagnosticSink& sink);

} // namespace gale::lang
