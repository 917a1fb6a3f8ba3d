// Hand-written recursive-descent parser. Reports every syntax error it can recover from
// (synchronising at ';' and '}'), and bounds nesting so no input can overflow the stack.
#pragma once

#include "lang/ast.h"
#include "lang/diagnostics.h"

namespace gale::lang {

struct ParseLimits {
    uint32_t maxNesting = 256;        // parentheses, brackets, calls, unary chains, blocks
    uint32_t maxTreeDepth = 1024;     // depth of the expression tree (long operator chains)
    size_t maxNodes = 2'000'000;      // expression + statement nodes
    size_t maxSourceBytes = 64u << 20; // larger sources are refused up front
};

// Parse a whole program: { def } { statement } expr. Never throws; on error the returned
// Ast holds what could be recovered and `sink` holds the diagnostics.
std::unique_ptr<Ast> parseProgram(const SourceFile& file, DiagnosticSink& sink,
                                  const ParseLimits& limits = {});

} // namespace gale::lang
