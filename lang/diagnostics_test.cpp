// Diagnostics tests: the sink's error cap and notes, and the exact clang-style rendering
// (carets, tildes, tabs, line ends, long lines, notes, colour).
#include "lang/diagnostics.h"

#include <catch2/catch.hpp>

using namespace gale::lang;

namespace {

// The span of the first occurrence of `needle` in the file's text.
Span spanOf(const SourceFile& f, const std::string& needle) {
    size_t p = f.text().find(needle);
    REQUIRE(p != std::string::npos);
    return {static_cast<uint32_t>(p), static_cast<uint32_t>(p + needle.size())};
}

} // namespace

TEST_CASE("diagnostics: the example from the spec renders exactly", "[diagnostics]") {
    SourceFile f("wind.se", "a = 1;\nb = 2;\nx = sinn($P);\nx");
    DiagnosticSink sink;
    Span s = spanOf(f, "sinn");
    sink.error(s, "unknown function 'sinn'");
    sink.note(s, "did you mean 'sin'?");
    CHECK(renderDiagnostics(f, sink) == "wind.se:3:5: error: unknown function 'sinn'\n"
                                        "    x = sinn($P);\n"
                                        "        ^~~~\n"
                                        "wind.se:3:5: note: did you mean 'sin'?\n");
}

TEST_CASE("diagnostics: indented source keeps its columns", "[diagnostics]") {
    SourceFile f("wind.se", "\n\n  x = sinn($P);\n");
    DiagnosticSink sink;
    sink.error(spanOf(f, "sinn"), "unknown function 'sinn'");
    CHECK(renderDiagnostics(f, sink) == "wind.se:3:7: error: unknown function 'sinn'\n"
                                        "      x = sinn($P);\n"
                                        "          ^~~~\n");
}

TEST_CASE("diagnostics: tabs are copied into the underline", "[diagnostics]") {
    SourceFile f("t.se", "\tx =\t$P  +\t[1,2];");
    DiagnosticSink sink;
    sink.error(spanOf(f, "[1,2]"), "width mismatch");
    CHECK(renderDiagnostics(f, sink) == "t.se:1:12: error: width mismatch\n"
                                        "    \tx =\t$P  +\t[1,2];\n"
                                        "    \t   \t     \t^~~~~\n");
}

TEST_CASE("diagnostics: empty spans, spans past the line end, multi-line spans", "[diagnostics]") {
    SourceFile f("t.se", "x = 1\ny = (2 +\n  3);\nz");
    DiagnosticSink sink;
    sink.error(Span{5, 5}, "expected ';' after the assignment"); // just after `1`
    Span multi = {static_cast<uint32_t>(f.text().find('(')),
                  static_cast<uint32_t>(f.text().find(')') + 1)};
    sink.warning(multi, "spans two lines");
    sink.error(Span{4, 100}, "runs off the end");
    CHECK(renderDiagnostics(f, sink) == "t.se:1:6: error: expected ';' after the assignment\n"
                                        "    x = 1\n"
                                        "         ^\n"
                                        "t.se:2:5: warning: spans two lines\n"
                                        "    y = (2 +\n"
                                        "        ^~~~\n"
                                        "t.se:1:5: error: runs off the end\n"
                                        "    x = 1\n"
                                        "        ^\n");
}

TEST_CASE("diagnostics: notes with and without spans", "[diagnostics]") {
    SourceFile f("t.se", "if (a) { x = 1; }\ny = x;\ny");
    DiagnosticSink sink;
    sink.error(Span{static_cast<uint32_t>(f.text().find("y = x") + 4),
                    static_cast<uint32_t>(f.text().find("y = x") + 5)},
               "'x' is undefined here");
    sink.note(spanOf(f, "x = 1"), "it is assigned only in this branch");
    sink.note("assign it before the 'if' or in both branches");
    CHECK(renderDiagnostics(f, sink) == "t.se:2:5: error: 'x' is undefined here\n"
                                        "    y = x;\n"
                                        "        ^\n"
                                        "t.se:1:10: note: it is assigned only in this branch\n"
                                        "    if (a) { x = 1; }\n"
                                        "             ^~~~~\n"
                                        "note: assign it before the 'if' or in both branches\n");
}

TEST_CASE("diagnostics: an empty file and a span at its end", "[diagnostics]") {
    SourceFile f("t.se", "");
    DiagnosticSink sink;
    sink.error(Span{0, 0}, "empty program");
    CHECK(renderDiagnostics(f, sink) == "t.se:1:1: error: empty program\n"
                                        "    \n"
                                        "    ^\n");
}

TEST_CASE("diagnostics: CRLF line ends and control bytes", "[diagnostics]") {
    SourceFile f("t.se", "x = 1 @\r\ny");
    DiagnosticSink sink;
    sink.error(spanOf(f, "@"), "unexpected character '@'");
    CHECK(renderDiagnostic(f, sink.diagnostics()[0]) ==
          "t.se:1:7: error: unexpected character '@'\n"
          "    x = 1 @\n"
          "          ^\n");
    SourceFile g("t.se", std::string("a\x1b[31mb", 7));
    DiagnosticSink s2;
    s2.error(Span{6, 7}, "b");
    // The escape byte is shown as a space, so no terminal sequence leaks through.
    CHECK(renderDiagnostics(g, s2) == "t.se:1:7: error: b\n"
                                      "    a [31mb\n"
                                      "          ^\n");
}

TEST_CASE("diagnostics: UTF-8 text before the span takes one column per character",
          "[diagnostics]") {
    SourceFile f("t.se", "x = \"\xc2\xb0"
                         "C\" + y");
    DiagnosticSink sink;
    sink.error(spanOf(f, "y"), "bad");
    CHECK(renderDiagnostics(f, sink) == "t.se:1:13: error: bad\n"
                                        "    x = \"\xc2\xb0"
                                        "C\" + y\n"
                                        "               ^\n");
}

TEST_CASE("diagnostics: long lines are windowed around the span", "[diagnostics]") {
    std::string line = "x = 1";
    for (int i = 0; i < 300; ++i) line += " + 1";
    line += " + oops";
    for (int i = 0; i < 300; ++i) line += " + 1";
    SourceFile f("t.se", line);
    DiagnosticSink sink;
    Span s = spanOf(f, "oops");
    sink.error(s, "unknown variable 'oops'");
    std::string out = renderDiagnostics(f, sink);
    // header, source, underline
    size_t nl1 = out.find('\n');
    size_t nl2 = out.find('\n', nl1 + 1);
    size_t nl3 = out.find('\n', nl2 + 1);
    REQUIRE(nl3 == out.size() - 1);
    std::string src = out.substr(nl1 + 1, nl2 - nl1 - 1);
    std::string under = out.substr(nl2 + 1, nl3 - nl2 - 1);
    CHECK(out.substr(0, nl1) == "t.se:1:1209: error: unknown variable 'oops'");
    CHECK(src.size() < 220);
    CHECK(src.substr(0, 7) == "    ...");
    CHECK(src.substr(src.size() - 3) == "...");
    size_t caret = under.find('^');
    REQUIRE(caret != std::string::npos);
    CHECK(src.substr(caret, 4) == "oops");
    CHECK(under.substr(caret) == "^~~~");
}

TEST_CASE("diagnostics: colour", "[diagnostics]") {
    SourceFile f("t.se", "x + y");
    DiagnosticSink sink;
    sink.error(Span{4, 5}, "bad");
    sink.note("hint");
    sink.warning(Span{0, 1}, "careful");
    RenderOptions opt;
    opt.color = true;
    std::string out = renderDiagnostics(f, sink, opt);
    CHECK(out == "\033[1mt.se:1:5: \033[1;31merror:\033[0m\033[1m bad\033[0m\n"
                 "    x + y\n"
                 "        \033[1;32m^\033[0m\n"
                 "\033[1m\033[1;36mnote:\033[0m\033[1m hint\033[0m\n"
                 "\033[1mt.se:1:1: \033[1;35mwarning:\033[0m\033[1m careful\033[0m\n"
                 "    x + y\n"
                 "    \033[1;32m^\033[0m\n");
}

TEST_CASE("diagnostics: the sink caps errors", "[diagnostics]") {
    DiagnosticSink sink;
    CHECK_FALSE(sink.hasErrors());
    sink.note("ignored: no diagnostic yet");
    CHECK(sink.diagnostics().empty());
    sink.warning(Span{0, 1}, "w");
    CHECK_FALSE(sink.hasErrors());
    for (int i = 0; i < 150; ++i) {
        Diagnostic& d = sink.error(Span{0, 1}, "e" + std::to_string(i));
        sink.note("n");
        (void)d;
    }
    CHECK(sink.errorCount() == DiagnosticSink::kMaxErrors + 1);
    REQUIRE(sink.diagnostics().size() == DiagnosticSink::kMaxErrors + 2);
    CHECK(sink.diagnostics()[1].message == "e0");
    CHECK(sink.diagnostics()[1].notes.size() == 1);
    CHECK(sink.diagnostics()[DiagnosticSink::kMaxErrors].message == "e99");
    const Diagnostic& last = sink.diagnostics().back();
    CHECK(last.message == "too many errors; stopping");
    CHECK(last.notes.empty()); // notes of dropped errors go nowhere
    // Writing through the reference of a dropped error is harmless.
    Diagnostic& dropped = sink.error(Span{0, 0}, "dropped");
    dropped.message = "scribble";
    CHECK(sink.diagnostics().back().message == "too many errors; stopping");
    sink.clear();
    CHECK(sink.diagnostics().empty());
    CHECK(sink.errorCount() == 0);
    sink.error(Span{0, 0}, "again");
    CHECK(sink.diagnostics().size() == 1);
}

TEST_CASE("diagnostics: error() returns the recorded diagnostic", "[diagnostics]") {
    DiagnosticSink sink;
    Diagnostic& d = sink.error(Span{1, 2}, "m");
    d.notes.push_back({"added directly", Span{}, false});
    REQUIRE(sink.diagnostics().size() == 1);
    CHECK(sink.diagnostics()[0].notes.size() == 1);
    CHECK(sink.diagnostics()[0].severity == Severity::Error);
    CHECK(sink.hasErrors());
}
