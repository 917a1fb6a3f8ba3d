// DiagnosticSink (collects errors, warnings and notes, capped at kMaxErrors errors) and the
// clang-style renderer: `file:line:col: error: message`, the source line, a caret underline.
#include "lang/diagnostics.h"

namespace gale::lang {

namespace {

constexpr const char* kReset = "\033[0m";
constexpr const char* kBold = "\033[1m";
constexpr const char* kRed = "\033[1;31m";
constexpr const char* kMagenta = "\033[1;35m";
constexpr const char* kCyan = "\033[1;36m";
constexpr const char* kGreen = "\033[1;32m";

// Lines longer than this are shown as a window around the span.
constexpr size_t kMaxLineShown = 200;
constexpr size_t kWindowBefore = 60;
constexpr size_t kWindowSize = 160;

bool isContinuationByte(char c) {
    return (static_cast<unsigned char>(c) & 0xC0) == 0x80;
}

const char* severityText(Severity s) {
    switch (s) {
    case Severity::Error:
        return "error:";
    case Severity::Warning:
        return "warning:";
    case Severity::Note:
        return "note:";
    }
    return "error:";
}

const char* severityColor(Severity s) {
    switch (s) {
    case Severity::Error:
        return kRed;
    case Severity::Warning:
        return kMagenta;
    case Severity::Note:
        return kCyan;
    }
    return kRed;
}

// `file:line:col: error: message\n` (or without the location when `withLoc` is false).
void renderHeader(std::string& out, const SourceFile& file, bool withLoc, Span span, Severity sev,
                  const std::string& message, const RenderOptions& opt) {
    if (opt.color) out += kBold;
    if (withLoc) {
        LineCol lc = file.lineCol(span.begin);
        out += file.name().empty() ? std::string("<input>") : file.name();
        out += ':';
        out += std::to_string(lc.line);
        out += ':';
        out += std::to_string(lc.col);
        out += ": ";
    }
    if (opt.color) {
        out += severityColor(sev);
        out += severityText(sev);
        out += kReset;
        out += kBold;
    } else {
        out += severityText(sev);
    }
    out += ' ';
    out += message;
    if (opt.color) out += kReset;
    out += '\n';
}

// The source line of `span.begin` and a `^~~~` underline of the span (clipped to that line).
void renderSnippet(std::string& out, const SourceFile& file, Span span, const RenderOptions& opt) {
    LineCol lc = file.lineCol(span.begin);
    std::string_view line = file.lineText(lc.line);
    size_t start = lc.col - 1;
    if (start > line.size()) start = line.size();
    uint32_t lineBegin = span.begin >= lc.col - 1 ? span.begin - (lc.col - 1) : 0;
    size_t end = span.end > lineBegin ? span.end - lineBegin : 0;
    if (end > line.size()) end = line.size(); // continues past this line: underline to its end
    if (end < start + 1) end = start + 1;     // empty span, or one at the end of the line

    // Window very long lines around the span.
    size_t winBegin = 0;
    size_t winEnd = line.size();
    if (line.size() > kMaxLineShown) {
        winBegin = start > kWindowBefore ? start - kWindowBefore : 0;
        while (winBegin > 0 && isContinuationByte(line[winBegin])) --winBegin;
        winEnd = winBegin + kWindowSize < line.size() ? winBegin + kWindowSize : line.size();
        while (winEnd < line.size() && isContinuationByte(line[winEnd])) ++winEnd;
        if (end > winEnd) end = winEnd > start + 1 ? winEnd : start + 1;
    }
    bool dotsBefore = winBegin > 0;
    bool dotsAfter = winEnd < line.size();

    out += "    ";
    if (dotsBefore) out += "...";
    for (size_t i = winBegin; i < winEnd; ++i) {
        unsigned char c = static_cast<unsigned char>(line[i]);
        // Control bytes would corrupt a terminal; each still takes one column.
        out += (c < 0x20 && c != '\t') || c == 0x7F ? ' ' : static_cast<char>(c);
    }
    if (dotsAfter) out += "...";
    out += '\n';

    out += "    ";
    if (dotsBefore) out += "   ";
    for (size_t i = winBegin; i < start && i < line.size(); ++i) {
        if (line[i] == '\t')
            out += '\t';
        else if (!isContinuationByte(line[i]))
            out += ' ';
    }
    if (opt.color) out += kGreen;
    out += '^';
    for (size_t i = start + 1; i < end; ++i)
        if (i >= line.size() || !isContinuationByte(line[i])) out += '~';
    if (opt.color) out += kReset;
    out += '\n';
}

} // namespace

Diagnostic& DiagnosticSink::error(Span span, std::string message) {
    if (mErrorCount > kMaxErrors) {
        mDropped = Diagnostic{};
        return mDropped;
    }
    Diagnostic d;
    d.severity = Severity::Error;
    d.span = span;
    d.message =
        mErrorCount == kMaxErrors ? std::string("too many errors; stopping") : std::move(message);
    ++mErrorCount;
    mDiagnostics.push_back(std::move(d));
    if (mErrorCount > kMaxErrors) {
        // The "too many errors" entry stands in for this error, which is dropped.
        mDropped = Diagnostic{};
        return mDropped;
    }
    return mDiagnostics.back();
}

Diagnostic& DiagnosticSink::warning(Span span, std::string message) {
    if (mErrorCount > kMaxErrors) {
        mDropped = Diagnostic{};
        return mDropped;
    }
    Diagnostic d;
    d.severity = Severity::Warning;
    d.span = span;
    d.message = std::move(message);
    mDiagnostics.push_back(std::move(d));
    return mDiagnostics.back();
}

void DiagnosticSink::note(std::string message) {
    if (mDiagnostics.empty() || mErrorCount > kMaxErrors) return;
    mDiagnostics.back().notes.push_back({std::move(message), Span{}, false});
}

void DiagnosticSink::note(Span span, std::string message) {
    if (mDiagnostics.empty() || mErrorCount > kMaxErrors) return;
    mDiagnostics.back().notes.push_back({std::move(message), span, true});
}

void DiagnosticSink::clear() {
    mDiagnostics.clear();
    mDropped = Diagnostic{};
    mErrorCount = 0;
}

std::string renderDiagnostic(const SourceFile& file, const Diagnostic& d,
                             const RenderOptions& opt) {
    std::string out;
    renderHeader(out, file, true, d.span, d.severity, d.message, opt);
    renderSnippet(out, file, d.span, opt);
    for (const DiagnosticNote& n : d.notes) {
        if (!n.hasSpan) {
            renderHeader(out, file, false, Span{}, Severity::Note, n.message, opt);
            continue;
        }
        renderHeader(out, file, true, n.span, Severity::Note, n.message, opt);
        // A note about the very span just shown does not repeat the source line.
        if (n.span.begin != d.span.begin || n.span.end != d.span.end)
            renderSnippet(out, file, n.span, opt);
    }
    return out;
}

std::string renderDiagnostics(const SourceFile& file, const DiagnosticSink& sink,
                              const RenderOptions& opt) {
    std::string out;
    for (const Diagnostic& d : sink.diagnostics()) out += renderDiagnostic(file, d, opt);
    return out;
}

} // namespace gale::lang
