// libFuzzer harness: bytes -> source -> lex, parse, type-check, fold and compile (with the
// standard host variables and built-ins), then disassemble and render every diagnostic.
// It must never crash, hang, leak or trip a sanitizer, whatever the bytes.
#include "lang/diagnostics.h"
#include "lang/lexer.h"
#include "runtime/program.h"

#include <cstddef>
#include <cstdint>
#include <string>

using namespace gale;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const lang::SourceFile source("fuzz.se", std::string(reinterpret_cast<const char*>(data), size));

    // The lexer alone, to the end of the input (it must terminate on any bytes).
    {
        lang::DiagnosticSink sink;
        lang::Lexer lexer(source, sink);
        for (size_t i = 0; i <= size + 1; ++i)
            if (lexer.next().kind == lang::TokenKind::End) break;
    }

    // The whole pipeline, with and without constant folding, natural type and FP[3] wanted.
    for (int variant = 0; variant < 2; ++variant) {
        runtime::CompileSettings settings;
        settings.variables = runtime::standardVariables();
        settings.fold = variant == 0;
        settings.wantWidth = variant == 0 ? 0 : 3;
        lang::DiagnosticSink sink;
        std::shared_ptr<const runtime::Program> program = runtime::Program::compile(source, settings, sink);
        const std::string rendered = lang::renderDiagnostics(source, sink);
        if (program) {
            const std::string text = program->disassemble();
            if (text.empty() && !program->bytecode().code.empty()) __builtin_trap();
        } else if (!sink.hasErrors()) {
            __builtin_trap(); // a failed compile must say why
        }
        (void)rendered;
    }
    return 0;
}
