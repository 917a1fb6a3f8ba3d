// Diagnostics with source spans, collected in a sink and rendered with a caret underline.
// Library code never prints: the CLI renders what the sink holds.
#pragma once

#include "lang/source.h"

#include <string>
#include <vector>

namespace gale::lang {

enum class Severity { Error, Warning, Note };

struct DiagnosticNote {
    std::string message;
    Span span;
    bool hasSpan = false;
};

struct Diagnostic {
    Severity severity = Severity::Error;
    Span span;
    std::string message;
    std::vector<DiagnosticNote> notes;
};

class DiagnosticSink {
public:
    // Stop collecting after this many errors (one more "too many errors" is recorded).
    static constexpr size_t kMaxErrors = 100;

    Diagnostic& error(Span span, std::string message);
    Diagnostic& warning(Span span, std::string message);
    // Attach a note to the last diagnostic (no-op when there is none).
    void note(std::string message);
    void note(Span span, std::string message);

    const std::vector<Diagnostic>& diagnostics() const { return mDiagnostics; }
    bool hasErrors() const { return mErrorCount > 0; }
    size_t errorCount() const { return mErrorCount; }
    void clear();

private:
    std::vector<Diagnostic> mDiagnostics;
    Diagnostic mDropped; // target of error() once the limit is reached
    size_t mErrorCount = 0;
};

struct RenderOptions {
    bool color = false;
};

// `file:line:col: error: message`, the source line, a caret/tilde underline, then notes.
std::string renderDiagnostic(const SourceFile& file, const Diagnostic& d, const RenderOptions& opt = {});
std::string renderDiagnostics(const SourceFile& file, const DiagnosticSink& sink,
                              const RenderOptions& opt = {});

} // namespace gale::lang
