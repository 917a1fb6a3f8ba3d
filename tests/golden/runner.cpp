// gale_golden: runs the language's golden tests (tests/lang/**.se) and the malformed-program
// corpus (tests/malformed/*.se). Each .se file is one program whose `#` comments state what it
// must do; see tests/golden/README.md for the annotation format.
//
// usage: gale_golden [-v] [--no-fork] [--float] PATH...   (directories are searched recursively for *.se,
// sorted; each file runs in a child process so that a crash is one failure, not the end of the run)
#include "lang/diagnostics.h"
#include "lang/source.h"
#include "runtime/program.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <csignal>
#include <cstring>
#include <sys/wait.h>
#include <unistd.h>
#define GALE_GOLDEN_FORK 1
#endif

namespace fs = std::filesystem;
using namespace gale;

namespace {

// ---- expectations -----------------------------------------------------------------------------

struct ExpectedNumber {
    double value = 0.0;
    double tolerance = 0.0; // absolute
    std::string text;
};

struct ExpectedError {
    uint32_t line = 0;
    uint32_t col = 0;
    std::string text; // case-insensitive substring of the message
    std::string raw;
    bool matched = false;
};

struct SetValue {
    std::string name;
    std::vector<double> numbers;
    std::string text;
    bool isString = false;
};

struct TestCase {
    std::string path;
    bool hasExpect = false;
    std::string expectRaw;
    std::vector<ExpectedError> errors;
    std::vector<SetValue> sets;
    bool hasTime = false, hasFrame = false;
    double time = 0.0, frame = 0.0;
    bool hasPrints = false;
    std::vector<std::string> prints;
    bool checkFloat = false;
    std::vector<std::string> problems; // malformed annotations
};

std::string trim(const std::string& s) {
    size_t b = 0, e = s.size();
    while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
    return s.substr(b, e - b);
}

std::string rtrim(const std::string& s) {
    size_t e = s.size();
    while (e > 0 && (s[e - 1] == '\r' || s[e - 1] == '\n' || s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
    return s.substr(0, e);
}

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// Parses one expected number and its tolerance from the digits written: a decimal value matches
// within half a unit of its last digit (plus 1e-12 relative); an integer within 1e-9 relative.
bool parseExpectedNumber(const std::string& tok, ExpectedNumber& out) {
    out.text = tok;
    std::string t = lower(tok);
    if (t == "inf" || t == "+inf") { out.value = std::numeric_limits<double>::infinity(); return true; }
    if (t == "-inf") { out.value = -std::numeric_limits<double>::infinity(); return true; }
    if (t == "nan") { out.value = std::numeric_limits<double>::quiet_NaN(); return true; }
    char* end = nullptr;
    out.value = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0') return false;
    size_t epos = t.find('e');
    std::string mant = epos == std::string::npos ? t : t.substr(0, epos);
    int exponent = epos == std::string::npos ? 0 : std::atoi(t.c_str() + epos + 1);
    size_t dot = mant.find('.');
    int decimals = dot == std::string::npos ? 0 : static_cast<int>(mant.size() - dot - 1);
    double mag = std::fabs(out.value);
    if (dot == std::string::npos && epos == std::string::npos)
        out.tolerance = 1e-9 * mag + 1e-12;
    else
        out.tolerance = 0.5 * std::pow(10.0, exponent - decimals) + 1e-12 * mag;
    return true;
}

bool parseNumberList(const std::string& s, std::vector<double>& out) {
    out.clear();
    std::string item;
    std::stringstream ss(s);
    while (std::getline(ss, item, ',')) {
        item = trim(item);
        if (item.empty()) return false;
        char* end = nullptr;
        double v = std::strtod(item.c_str(), &end);
        if (end == item.c_str() || *end != '\0') return false;
        out.push_back(v);
    }
    return !out.empty();
}

// Finds `# key:` in a line's comment; returns the text after it.
bool annotation(const std::string& line, const char* key, std::string& rest) {
    size_t pos = 0;
    while ((pos = line.find('#', pos)) != std::string::npos) {
        size_t p = pos + 1;
        while (p < line.size() && line[p] == ' ') ++p;
        std::string k = key;
        if (line.compare(p, k.size(), k) == 0 && p + k.size() < line.size() + 1 &&
            line.compare(p + k.size(), 1, ":") == 0) {
            rest = line.substr(p + k.size() + 1);
            if (!rest.empty() && rest[0] == ' ') rest.erase(0, 1);
            rest = rtrim(rest);
            return true;
        }
        ++pos;
    }
    return false;
}

TestCase parseAnnotations(const std::string& path, const std::string& text) {
    TestCase tc;
    tc.path = path;
    std::stringstream ss(text);
    std::string line, rest;
    while (std::getline(ss, line)) {
        if (line.find('#') == std::string::npos) continue;
        if (annotation(line, "expect", rest)) {
            if (tc.hasExpect) tc.problems.push_back("more than one '# expect:' line");
            tc.hasExpect = true;
            tc.expectRaw = rest;
        } else if (annotation(line, "error", rest)) {
            ExpectedError e;
            e.raw = rest;
            unsigned l = 0, c = 0;
            int consumed = 0;
            if (std::sscanf(rest.c_str(), "%u:%u%n", &l, &c, &consumed) < 2) {
                tc.problems.push_back("bad '# error:' annotation (want L:C text): " + rest);
                continue;
            }
            e.line = l;
            e.col = c;
            e.text = trim(rest.substr(static_cast<size_t>(consumed)));
            tc.errors.push_back(e);
        } else if (annotation(line, "set", rest)) {
            size_t eq = rest.find('=');
            if (eq == std::string::npos) {
                tc.problems.push_back("bad '# set:' annotation (want NAME=VALUE): " + rest);
                continue;
            }
            SetValue sv;
            sv.name = trim(rest.substr(0, eq));
            if (!sv.name.empty() && sv.name[0] == '$') sv.name.erase(0, 1);
            std::string value = trim(rest.substr(eq + 1));
            if (!parseNumberList(value, sv.numbers)) {
                sv.isString = true;
                if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') &&
                    value.back() == value.front())
                    value = value.substr(1, value.size() - 2);
                sv.text = value;
            }
            tc.sets.push_back(sv);
        } else if (annotation(line, "time", rest)) {
            tc.hasTime = true;
            tc.time = std::strtod(rest.c_str(), nullptr);
        } else if (annotation(line, "frame", rest)) {
            tc.hasFrame = true;
            tc.frame = std::strtod(rest.c_str(), nullptr);
        } else if (annotation(line, "prints", rest)) {
            tc.hasPrints = true;
            tc.prints.push_back(rest);
        } else if (annotation(line, "precision", rest)) {
            std::string p = lower(trim(rest));
            if (p == "float") tc.checkFloat = true;
            else if (p != "double") tc.problems.push_back("unknown precision: " + rest);
        }
    }
    if (!tc.hasExpect && tc.errors.empty()) tc.problems.push_back("no '# expect:' or '# error:' line");
    if (tc.hasExpect && !tc.errors.empty()) tc.problems.push_back("both '# expect:' and '# error:' lines");
    return tc;
}

// ---- running ------------------------------------------------------------------------------------

struct Failure {
    std::string path;
    std::string message;
};

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::string formatValues(const std::vector<double>& v) {
    std::string s;
    for (size_t i = 0; i < v.size(); ++i) {
        if (i) s += ' ';
        s += formatNumber(v[i]);
    }
    return s;
}

std::vector<std::string> splitWords(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string w;
    while (ss >> w) out.push_back(w);
    return out;
}

std::vector<std::string> splitLines(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string l;
    while (std::getline(ss, l)) out.push_back(rtrim(l));
    return out;
}

// Host bindings of one test: the compile-time variable list and the evaluation request.
struct Bindings {
    std::vector<lang::HostVariable> variables;
    runtime::EvalRequest request;
    std::vector<std::vector<double>> varyingData; // storage behind request.varyings
};

void makeBindings(const TestCase& tc, Bindings& b) {
    b.variables = runtime::standardVariables();
    double t = tc.hasTime ? tc.time : 0.0;
    double fps = 24.0;
    double frame = tc.hasFrame ? tc.frame : t * fps;
    std::vector<double> P = {0.0, 0.0, 0.0};

    auto findSet = [&](const std::string& name) -> const SetValue* {
        const SetValue* found = nullptr;
        for (const SetValue& s : tc.sets)
            if (s.name == name) found = &s;
        return found;
    };

    b.request.count = 1;
    b.request.threads = 1;
    b.varyingData.reserve(b.variables.size() + tc.sets.size());
    for (lang::HostVariable& v : b.variables) {
        std::vector<double> value;
        const SetValue* s = findSet(v.name);
        if (s && !s->isString) value = s->numbers;
        else if (v.name == "t") value = {t};
        else if (v.name == "frame") value = {frame};
        else if (v.name == "fps") value = {fps};
        else if (v.name == "P") value = P;
        else if (v.name == "id" && !s) continue; // filled with the point index by the evaluator
        else value.assign(static_cast<size_t>(v.type.width), 0.0);
        if (static_cast<int>(value.size()) != v.type.width) {
            // A different width for a standard variable: rebind it with that width.
            v.type = v.type.withWidth(static_cast<int>(value.size()));
        }
        if (v.type.lifetime == lang::Lifetime::Varying) {
            b.varyingData.push_back(value);
            runtime::VaryingInput in;
            in.name = v.name;
            in.width = static_cast<int>(value.size());
            in.data = b.varyingData.back().data();
            in.pointStride = in.width;
            in.compStride = 1;
            b.request.varyings.push_back(in);
        } else {
            runtime::UniformValue u;
            u.name = v.name;
            u.value = value;
            b.request.uniforms.push_back(u);
        }
    }
    // Scene parameters named by `# set:` that are not standard variables: uniform.
    for (size_t i = 0; i < tc.sets.size(); ++i) {
        const SetValue& s = tc.sets[i];
        bool standard = false;
        for (const lang::HostVariable& v : b.variables)
            if (v.name == s.name) standard = true;
        bool later = false;
        for (size_t j = i + 1; j < tc.sets.size(); ++j)
            if (tc.sets[j].name == s.name) later = true;
        if (standard || later) continue;
        lang::HostVariable hv;
        hv.name = s.name;
        hv.type = s.isString ? lang::Type::string(lang::Lifetime::Uniform)
                             : lang::Type::fp(static_cast<int>(s.numbers.size()), lang::Lifetime::Uniform);
        b.variables.push_back(hv);
        runtime::UniformValue u;
        u.name = s.name;
        u.value = s.numbers;
        u.text = s.text;
        b.request.uniforms.push_back(u);
    }
}

std::string indent(const std::string& text) {
    std::string out;
    for (const std::string& l : splitLines(text)) out += "      | " + l + "\n";
    return out;
}

// Compares reported error diagnostics with the expected set; returns an empty string on match.
std::string compareErrors(TestCase& tc, const lang::SourceFile& file,
                          const std::vector<lang::Diagnostic>& diags) {
    std::vector<const lang::Diagnostic*> reported;
    for (const lang::Diagnostic& d : diags)
        if (d.severity == lang::Severity::Error) reported.push_back(&d);
    std::vector<bool> used(reported.size(), false);
    std::string missing, extra;
    for (ExpectedError& e : tc.errors) {
        for (size_t i = 0; i < reported.size(); ++i) {
            if (used[i]) continue;
            lang::LineCol lc = file.lineCol(reported[i]->span.begin);
            if (lc.line == e.line && lc.col == e.col &&
                lower(reported[i]->message).find(lower(e.text)) != std::string::npos) {
                used[i] = true;
                e.matched = true;
                break;
            }
        }
        if (!e.matched) missing += "      missing: " + e.raw + "\n";
    }
    for (size_t i = 0; i < reported.size(); ++i) {
        if (used[i]) continue;
        lang::LineCol lc = file.lineCol(reported[i]->span.begin);
        extra += "      unexpected: " + std::to_string(lc.line) + ":" + std::to_string(lc.col) + " " +
                 reported[i]->message + "\n";
    }
    return missing + extra;
}

template <class T>
bool evaluateOnce(const runtime::Program& program, const runtime::EvalRequest& request, bool checked,
                  std::vector<double>& values, std::string& text, runtime::EvalResult& result) {
    runtime::EvalRequest req = request;
    req.checked = checked;
    int width = program.resultIsString() ? 1 : program.resultWidth();
    std::vector<T> out(static_cast<size_t>(width > 0 ? width : 1), T(0));
    std::string str;
    runtime::EvalOutput<T> o;
    o.data = out.data();
    o.pointStride = width;
    o.compStride = 1;
    o.strings = &str;
    result = runtime::evaluate<T>(program, req, o);
    values.assign(out.begin(), out.end());
    text = str;
    return result.ok;
}

bool withinTolerance(double actual, const ExpectedNumber& e, double relFloor) {
    if (std::isnan(e.value)) return std::isnan(actual);
    if (std::isinf(e.value)) return actual == e.value;
    if (!std::isfinite(actual)) return false;
    double tol = e.tolerance;
    if (relFloor > 0) tol = std::max(tol, relFloor * std::max(1.0, std::fabs(e.value)));
    return std::fabs(actual - e.value) <= tol;
}

// Runs one test; returns an empty string on success, else what went wrong.
bool gFloatAll = false; // --float: evaluate every expect-test in float as well

std::string runTest(TestCase& tc, const std::string& source) {
    if (!tc.problems.empty()) {
        std::string s;
        for (const std::string& p : tc.problems) s += "      bad test: " + p + "\n";
        return s;
    }
    lang::SourceFile file(tc.path, source);
    Bindings b;
    makeBindings(tc, b);
    runtime::CompileSettings settings;
    settings.variables = b.variables;
    lang::DiagnosticSink sink;
    std::shared_ptr<const runtime::Program> program;
    try {
        program = runtime::Program::compile(file, settings, sink);
    } catch (const std::exception& ex) {
        return std::string("      compile threw: ") + ex.what() + "\n";
    }
    std::string rendered = lang::renderDiagnostics(file, sink);

    if (!tc.errors.empty()) {
        if (!program) {
            std::string diff = compareErrors(tc, file, sink.diagnostics());
            if (diff.empty()) return {};
            return diff + "    diagnostics:\n" + indent(rendered);
        }
        // Compiled: the expected errors must come from (checked) evaluation.
        std::vector<double> values;
        std::string text;
        runtime::EvalResult r;
        evaluateOnce<double>(*program, b.request, true, values, text, r);
        if (r.diagnostics.empty() && r.ok) {
            std::string s = "      expected errors, but the program compiled and ran: result " +
                            (program->resultIsString() ? text : formatValues(values)) + "\n";
            for (const ExpectedError& e : tc.errors) s += "      expected: " + e.raw + "\n";
            if (!rendered.empty()) s += "    diagnostics:\n" + indent(rendered);
            return s;
        }
        if (r.diagnostics.empty()) {
            // An evaluation failure without a span: one expected error, matched by its text only.
            if (tc.errors.size() == 1 && lower(r.error).find(lower(tc.errors[0].text)) != std::string::npos)
                return {};
            return "      evaluation failed without a location: " + r.error + "\n";
        }
        std::string diff = compareErrors(tc, file, r.diagnostics);
        if (diff.empty()) return {};
        lang::DiagnosticSink rs;
        for (const lang::Diagnostic& d : r.diagnostics) rs.error(d.span, d.message);
        return diff + "    runtime: " + r.error + "\n" + indent(lang::renderDiagnostics(file, rs));
    }

    if (!program) return "      expected " + tc.expectRaw + ", but compilation failed:\n" + indent(rendered);

    std::string problems;
    const bool checkFloat = tc.checkFloat || gFloatAll;
    for (int pass = 0; pass < (checkFloat ? 2 : 1); ++pass) {
        bool isFloat = pass == 1;
        const char* label = isFloat ? " (float)" : "";
        std::vector<double> values;
        std::string text;
        runtime::EvalResult r;
        try {
            if (isFloat) evaluateOnce<float>(*program, b.request, false, values, text, r);
            else evaluateOnce<double>(*program, b.request, false, values, text, r);
        } catch (const std::exception& ex) {
            return std::string("      evaluate threw: ") + ex.what() + "\n";
        }
        if (!r.ok) {
            problems += std::string("      evaluation failed") + label + ": " + r.error + "\n";
            continue;
        }
        if (program->resultIsString()) {
            if (text != tc.expectRaw)
                problems += std::string("      expected") + label + " \"" + tc.expectRaw + "\", got \"" + text + "\"\n";
        } else {
            std::vector<std::string> words = splitWords(tc.expectRaw);
            bool ok = words.size() == values.size();
            std::vector<ExpectedNumber> expected(words.size());
            for (size_t i = 0; i < words.size(); ++i) {
                if (!parseExpectedNumber(words[i], expected[i]))
                    return "      bad test: expected value is not a number: " + words[i] + "\n";
            }
            for (size_t i = 0; ok && i < words.size(); ++i)
                ok = withinTolerance(values[i], expected[i], isFloat ? 1e-5 : 0.0);
            if (!ok)
                problems += std::string("      expected") + label + " " + tc.expectRaw + ", got " +
                            formatValues(values) + " (" + lang::typeName(program->resultType()) + ")\n";
        }
        if (tc.hasPrints && !isFloat) {
            std::vector<std::string> got = splitLines(r.messages);
            if (got != tc.prints) {
                problems += "      expected prints:\n";
                for (const std::string& l : tc.prints) problems += "      | " + l + "\n";
                problems += "      got prints:\n" + indent(r.messages);
            }
        }
    }
    return problems;
}

void collect(const fs::path& p, std::vector<std::string>& out) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
        for (fs::recursive_directory_iterator it(p, ec), end; it != end; it.increment(ec)) {
            if (ec) break;
            if (it->is_regular_file(ec) && it->path().extension() == ".se") out.push_back(it->path().string());
        }
    } else if (fs::is_regular_file(p, ec)) {
        out.push_back(p.string());
    } else {
        std::cerr << "gale_golden: no such file or directory: " << p.string() << "\n";
    }
}

// Runs one file: returns an empty string on success, else the failure report.
std::string runFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return "      cannot read the file\n";
    std::stringstream ss;
    ss << in.rdbuf();
    std::string source = ss.str();
    TestCase tc = parseAnnotations(path, source);
    try {
        return runTest(tc, source);
    } catch (const std::exception& ex) {
        return std::string("      threw: ") + ex.what() + "\n";
    }
}

#ifdef GALE_GOLDEN_FORK
// Runs one file in a child process, so that a crash or a hang in the implementation is reported
// as that test's failure instead of ending the whole run.
std::string runFileIsolated(const std::string& path, int timeoutSeconds) {
    int fds[2];
    if (pipe(fds) != 0) return runFile(path);
    std::cout.flush();
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return runFile(path);
    }
    if (pid == 0) {
        close(fds[0]);
        alarm(static_cast<unsigned>(timeoutSeconds));
        std::string report = runFile(path);
        const char* p = report.data();
        size_t left = report.size();
        while (left > 0) {
            ssize_t w = write(fds[1], p, left);
            if (w <= 0) break;
            p += w;
            left -= static_cast<size_t>(w);
        }
        close(fds[1]);
        _exit(report.empty() ? 0 : 1);
    }
    close(fds[1]);
    std::string report;
    char buf[4096];
    ssize_t r;
    while ((r = read(fds[0], buf, sizeof buf)) > 0) report.append(buf, static_cast<size_t>(r));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        std::string what = sig == SIGALRM ? "timed out after " + std::to_string(timeoutSeconds) + " s"
                                          : "crashed with signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
        return report + "      " + what + "\n";
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) != 0 && report.empty())
        return "      exited with status " + std::to_string(WEXITSTATUS(status)) + "\n";
    return report;
}
#endif

} // namespace

int main(int argc, char** argv) {
    bool verbose = false;
    bool isolate = true;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "-v" || a == "--verbose") verbose = true;
        else if (a == "--no-fork") isolate = false;
        else if (a == "--float") gFloatAll = true;
        else if (a == "-h" || a == "--help") {
            std::cout << "usage: gale_golden [-v] [--no-fork] [--float] PATH...\n"
                         "Runs every .se file under each PATH (recursively, sorted) and checks its\n"
                         "annotations (# expect:, # error:, # set:, # time:, # frame:, # prints:,\n"
                         "# precision:). Prints one block per failure and a summary line. Each file\n"
                         "runs in a child process (crashes and 60 s hangs are failures) unless\n"
                         "--no-fork is given. --float also evaluates every test in float (1e-5\n"
                         "relative), not only those marked '# precision: float'.\n";
            return 0;
        } else collect(a, files);
    }
    std::sort(files.begin(), files.end());
    files.erase(std::unique(files.begin(), files.end()), files.end());
    if (files.empty()) {
        std::cerr << "gale_golden: no .se files given\n";
        std::cout << "golden: 0 passed, 0 failed\n";
        return 2;
    }

    size_t passed = 0, failed = 0;
    for (const std::string& path : files) {
#ifdef GALE_GOLDEN_FORK
        std::string problem = isolate ? runFileIsolated(path, 60) : runFile(path);
#else
        std::string problem = runFile(path);
#endif
        if (problem.empty()) {
            ++passed;
            if (verbose) std::cout << "PASS " << path << "\n";
        } else {
            ++failed;
            std::cout << "FAIL " << path << "\n" << problem;
        }
        std::cout.flush();
    }
    std::cout << "golden: " << passed << " passed, " << failed << " failed\n";
    return failed == 0 ? 0 : 1;
}
