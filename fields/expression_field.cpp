// Expression fields: the parameter idiom (`$speed = 5; # 0, 40`) found and blanked so scenes and
// keyframes can override it, compilation against the field layer's built-ins and rigs, batch
// sampling through the block VM, and a scene's [[field]] entries summed into one field.
#include "fields/expression_field.h"

#include "fields/presets.h"
#include "fields/rigs.h"
#include "geometry/builtins.h"
#include "lang/lexer.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unordered_set>

namespace gale::fields {

using lang::TokenKind;

namespace {

bool isHostName(const std::string& name) {
    static const char* const kNames[] = {"P", "t", "frame", "fps", "id", "windDir", "windSpeed"};
    for (const char* n : kNames)
        if (name == n) return true;
    return false;
}

// A number at s[pos] (optionally signed); advances pos. Locale-independent.
bool readNumber(std::string_view s, size_t& pos, double& out) {
    while (pos < s.size() && (s[pos] == ' ' || s[pos] == '\t')) ++pos;
    size_t begin = pos;
    if (pos < s.size() && s[pos] == '+') ++begin, ++pos;
    std::from_chars_result r = std::from_chars(s.data() + pos, s.data() + s.size(), out);
    if (r.ec != std::errc() || !std::isfinite(out)) {
        pos = begin;
        return false;
    }
    pos = static_cast<size_t>(r.ptr - s.data());
    return true;
}

std::string trimmed(std::string_view s) {
    size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
    return a == std::string_view::npos ? std::string() : std::string(s.substr(a, b - a + 1));
}

// The comment after a declaration: `# min, max rest` (brackets optional) or free text.
void parseRangeComment(std::string_view line, ParameterDecl& decl) {
    size_t pos = line.find_first_not_of(" \t");
    if (pos == std::string_view::npos || line[pos] != '#') return;
    std::string_view comment = line.substr(pos + 1);
    size_t p = comment.find_first_not_of(" \t");
    if (p == std::string_view::npos) return;
    bool bracket = comment[p] == '[';
    if (bracket) ++p;
    double lo = 0.0, hi = 0.0;
    size_t q = p;
    bool ok = readNumber(comment, q, lo);
    while (ok && q < comment.size() && (comment[q] == ' ' || comment[q] == '\t')) ++q;
    ok = ok && q < comment.size() && comment[q] == ',';
    if (ok) ++q;
    ok = ok && readNumber(comment, q, hi);
    if (ok && bracket) {
        while (q < comment.size() && (comment[q] == ' ' || comment[q] == '\t')) ++q;
        ok = q < comment.size() && comment[q] == ']';
        if (ok) ++q;
    }
    // The range must end the comment or be followed by a space (not "2,3rd").
    ok = ok && (q == comment.size() || comment[q] == ' ' || comment[q] == '\t' || comment[q] == '\r');
    if (!ok) {
        decl.doc = trimmed(comment);
        return;
    }
    decl.hasRange = true;
    decl.min = lo;
    decl.max = hi;
    decl.doc = trimmed(comment.substr(q));
}

} // namespace

std::vector<ParameterDecl> findParameters(const lang::SourceFile& source) {
    std::vector<ParameterDecl> out;
    lang::DiagnosticSink scratch; // the compiler reports lexical errors, not this scan
    lang::Lexer lexer(source, scratch);
    std::vector<lang::Token> tokens;
    for (lang::Token t = lexer.next(); t.kind != TokenKind::End; t = lexer.next())
        tokens.push_back(std::move(t));
    auto kindAt = [&](size_t i) { return i < tokens.size() ? tokens[i].kind : TokenKind::End; };
    // A signed number at i: returns the index after it, or 0.
    auto number = [&](size_t i, double& v) -> size_t {
        double sign = 1.0;
        if (kindAt(i) == TokenKind::Minus || kindAt(i) == TokenKind::Plus) {
            if (kindAt(i) == TokenKind::Minus) sign = -1.0;
            ++i;
        }
        if (kindAt(i) != TokenKind::Number) return 0;
        v = sign * tokens[i].number;
        return i + 1;
    };

    std::unordered_set<std::string> seen; // names in `out`
    int depth = 0;              // (), [], {} nesting
    bool statementStart = true; // the previous token ended a statement (or there is none)
    for (size_t i = 0; i < tokens.size(); ++i) {
        const TokenKind k = tokens[i].kind;
        if (depth == 0 && statementStart && k == TokenKind::Variable &&
            kindAt(i + 1) == TokenKind::Assign) {
            ParameterDecl decl;
            decl.name = tokens[i].text;
            size_t j = i + 2;
            double v = 0.0;
            if (kindAt(j) == TokenKind::LBracket) {
                ++j;
                for (;;) {
                    size_t next = number(j, v);
                    if (!next) {
                        j = 0;
                        break;
                    }
                    decl.defaultValue.push_back(v);
                    j = next;
                    if (kindAt(j) == TokenKind::Comma) {
                        ++j;
                        continue;
                    }
                    j = kindAt(j) == TokenKind::RBracket ? j + 1 : 0;
                    break;
                }
            } else {
                j = number(j, v);
                if (j) decl.defaultValue.push_back(v);
            }
            const bool known = seen.count(decl.name) > 0; // (a set: 10^5 parameters stay fast)
            if (j && kindAt(j) == TokenKind::Semicolon && !isHostName(decl.name) && !known &&
                decl.defaultValue.size() <= static_cast<size_t>(lang::kMaxWidth)) {
                decl.span = {tokens[i].span.begin, tokens[j].span.end};
                const lang::LineCol end = source.lineCol(tokens[j].span.end);
                decl.line = static_cast<int>(source.lineCol(tokens[i].span.begin).line);
                std::string_view line = source.lineText(end.line);
                parseRangeComment(line.substr(std::min<size_t>(end.col - 1, line.size())), decl);
                seen.insert(decl.name);
                out.push_back(std::move(decl));
                i = j;
                statementStart = true;
                continue;
            }
        }
        if (k == TokenKind::LParen || k == TokenKind::LBracket || k == TokenKind::LBrace) ++depth;
        if ((k == TokenKind::RParen || k == TokenKind::RBracket || k == TokenKind::RBrace) && depth > 0)
            --depth;
        statementStart = k == TokenKind::Semicolon || k == TokenKind::RBrace;
    }
    return out;
}

lang::SourceFile withoutParameters(const lang::SourceFile& source,
                                   const std::vector<ParameterDecl>& params) {
    std::string text = source.text();
    for (const ParameterDecl& p : params)
        for (uint32_t i = p.span.begin; i < p.span.end && i < text.size(); ++i)
            if (text[i] != '\n' && text[i] != '\r') text[i] = ' ';
    return lang::SourceFile(source.name(), std::move(text));
}

std::vector<lang::HostVariable> fieldVariables(const Scene* scene) {
    std::vector<lang::HostVariable> vars = runtime::standardVariables();
    if (scene && scene->windicator) {
        vars.push_back({"windDir", lang::Type::fp(3, lang::Lifetime::Uniform)});
        vars.push_back({"windSpeed", lang::Type::fp(1, lang::Lifetime::Uniform)});
    }
    return vars;
}

// ---- ExpressionField ----

std::shared_ptr<ExpressionField> ExpressionField::compile(const lang::SourceFile& source,
                                                          const ExpressionFieldOptions& options,
                                                          lang::DiagnosticSink& sink) {
    auto field = std::shared_ptr<ExpressionField>(new ExpressionField());
    field->mOptions = options;
    field->mName = options.name.empty() ? source.name() : options.name;
    if (options.scene && options.scene->windicator) field->mWindicator = options.scene->windicator;
    field->mOptions.scene = nullptr;
    field->mParameters = findParameters(source);

    // Overrides must name declared parameters and fit their width (or be scalars).
    std::string declared;
    for (const ParameterDecl& p : field->mParameters)
        declared += (declared.empty() ? "" : ", ") + p.name;
    std::vector<std::string_view> names;
    for (const ParameterDecl& p : field->mParameters) names.push_back(p.name);
    bool ok = true;
    for (const auto& [name, param] : options.params) {
        auto it = std::find_if(field->mParameters.begin(), field->mParameters.end(),
                               [&name = name](const ParameterDecl& p) { return p.name == name; });
        if (it == field->mParameters.end()) {
            sink.error({0, 0}, "'" + name + "' is not a parameter of " + source.name());
            std::string_view close = lang::closestName(name, names);
            if (!close.empty()) sink.note("did you mean '" + std::string(close) + "'?");
            sink.note(declared.empty()
                          ? std::string("it declares no parameters (a top-level `$name = value;` "
                                        "statement declares one)")
                          : "its parameters: " + declared);
            ok = false;
            continue;
        }
        const int want = static_cast<int>(it->defaultValue.size());
        if (param.width() != want && param.width() != 1) {
            sink.error(it->span, "parameter '" + name + "' is FP[" + std::to_string(want) +
                                     "] but its override has " + std::to_string(param.width()) +
                                     " components");
            ok = false;
        }
    }
    if (!ok) return nullptr;

    runtime::CompileSettings settings;
    settings.variables = fieldVariables(options.scene);
    for (const ParameterDecl& p : field->mParameters) {
        auto it = options.params.find(p.name);
        field->mValues.push_back(it != options.params.end() ? it->second : Param(p.defaultValue));
        settings.variables.push_back(
            {p.name, lang::Type::fp(static_cast<int>(p.defaultValue.size()), lang::Lifetime::Uniform)});
    }
    for (const lang::HostVariable& v : options.extraVariables) {
        auto same = [&](const lang::HostVariable& h) { return h.name == v.name; };
        settings.variables.erase(
            std::remove_if(settings.variables.begin(), settings.variables.end(), same),
            settings.variables.end());
        settings.variables.push_back(v);
    }
    settings.wantWidth = 3;
    settings.functions = options.functions     ? options.functions
                         : options.scene       ? sceneFunctions(*options.scene)
                                               : fieldFunctions();
    if (options.files)
        settings.functions = geometry::withFileAccess(settings.functions, *options.files);
    field->mOptions.functions = settings.functions;
    const lang::SourceFile blanked = withoutParameters(source, field->mParameters);
    field->mProgram = runtime::Program::compile(blanked, settings, sink);
    if (!field->mProgram || sink.hasErrors()) return nullptr;
    return field;
}

std::vector<std::vector<double>> ExpressionField::parameterValues(double t) const {
    std::vector<std::vector<double>> out;
    for (const Param& p : mValues) out.push_back(p.at(t));
    return out;
}

SampleStatus ExpressionField::sample(const double* positions, size_t count, const SampleTime& when,
                                     double* velocities) const {
    return sampleWith(positions, count, when, velocities, {}, {});
}

SampleStatus ExpressionField::sampleWith(const double* positions, size_t count,
                                         const SampleTime& when, double* velocities,
                                         const std::vector<runtime::UniformValue>& uniforms,
                                         const std::vector<runtime::VaryingInput>& varyings) const {
    SampleStatus status;
    if (count == 0) return status;
    runtime::EvalRequest request;
    request.count = count;
    request.threads = when.threads;
    request.varyings.push_back({"P", 3, positions, 3, 1});
    request.uniforms.push_back({"t", {when.time}, {}});
    request.uniforms.push_back({"frame", {when.time * when.fps + when.frameZero}, {}});
    request.uniforms.push_back({"fps", {when.fps}, {}});
    for (size_t i = 0; i < mParameters.size(); ++i)
        request.uniforms.push_back({mParameters[i].name, mValues[i].at(when.time), {}});
    if (mWindicator) {
        const Windicator& w = *mWindicator;
        const Vec3 dir = windDirectionAt(w, when.time);
        request.uniforms.push_back({"windDir", {dir[0], dir[1], dir[2]}, {}});
        request.uniforms.push_back({"windSpeed", {w.speed.scalarAt(when.time)}, {}});
    }
    // Extra variables: the caller's values, else zero.
    static const double kZero = 0.0;
    for (const lang::HostVariable& v : mOptions.extraVariables) {
        auto sameU = [&](const runtime::UniformValue& u) { return u.name == v.name; };
        auto sameV = [&](const runtime::VaryingInput& u) { return u.name == v.name; };
        auto u = std::find_if(uniforms.begin(), uniforms.end(), sameU);
        auto w = std::find_if(varyings.begin(), varyings.end(), sameV);
        if (u != uniforms.end())
            request.uniforms.push_back(*u);
        else if (w != varyings.end())
            request.varyings.push_back(*w);
        else if (v.type.lifetime == lang::Lifetime::Varying)
            request.varyings.push_back({v.name, 1, &kZero, 0, 0});
        else
            request.uniforms.push_back({v.name, {0.0}, {}});
    }

    runtime::EvalResult r;
    if (mOptions.precision == runtime::Precision::Float) {
        std::vector<float> buffer(3 * count);
        runtime::EvalOutput<float> out;
        out.data = buffer.data();
        out.pointStride = 3;
        out.compStride = 1;
        r = runtime::evaluate<float>(*mProgram, request, out);
        for (size_t i = 0; i < 3 * count; ++i) velocities[i] = static_cast<double>(buffer[i]);
    } else {
        runtime::EvalOutput<double> out;
        out.data = velocities;
        out.pointStride = 3;
        out.compStride = 1;
        r = runtime::evaluate<double>(*mProgram, request, out);
    }
    if (!r.ok) {
        std::fill(velocities, velocities + 3 * count, 0.0);
        status.ok = false;
        status.message = "cannot evaluate " + mName + ": " + r.error;
        return status;
    }
    status.nonFinite = zeroNonFinite(velocities, count);
    if (status.nonFinite)
        status.message = std::to_string(status.nonFinite) + " point(s) of " + mName +
                         " gave a non-finite velocity (set to zero)";
    return status;
}

std::string ExpressionField::describe() const {
    std::ostringstream out;
    out << mName;
    if (mParameters.empty()) return out.str();
    out << " (";
    for (size_t i = 0; i < mParameters.size(); ++i) {
        out << (i ? ", " : "") << mParameters[i].name << " = ";
        if (mValues[i].isKeyed()) {
            out << "keyframed";
            continue;
        }
        const std::vector<double> v = mValues[i].at(0.0);
        if (v.size() > 1) out << '[';
        for (size_t k = 0; k < v.size(); ++k) out << (k ? ", " : "") << v[k];
        if (v.size() > 1) out << ']';
    }
    out << ")";
    return out.str();
}

// ---- The field layer's built-ins ----

std::shared_ptr<const runtime::FunctionTable> fieldFunctions() {
    static const std::shared_ptr<const runtime::FunctionTable> table = [] {
        auto t = std::make_shared<runtime::FunctionTable>(*runtime::FunctionTable::standard());
        addGustBuiltins(*t);
        addTurbulenceBuiltins(*t);
        geometry::addGeometryBuiltins(*t, geometry::FileAccess{});
        return std::shared_ptr<const runtime::FunctionTable>(std::move(t));
    }();
    return table;
}

std::shared_ptr<const runtime::FunctionTable> fieldFunctions(const geometry::FileAccess& access) {
    return geometry::withFileAccess(fieldFunctions(), access);
}

// ---- Scenes ----

namespace {

// Inline text placed at (line, col) of a file named `name`: earlier lines are empty, the first
// line is indented, so diagnostics show the scene's own line and column.
lang::SourceFile positionedSource(const std::string& name, const std::string& text, int line,
                                  int col) {
    if (line <= 0 || col <= 0) return lang::SourceFile(name, text);
    std::string padded(static_cast<size_t>(line - 1), '\n');
    padded.append(static_cast<size_t>(col - 1), ' ');
    padded += text;
    return lang::SourceFile(name, std::move(padded));
}

} // namespace

bool fieldSource(const Scene& scene, const FieldEntry& entry, lang::SourceFile& out,
                 std::string& error) {
    if (!entry.exprPath.empty()) {
        std::error_code ec;
        errno = 0;
        std::ifstream in;
        if (!std::filesystem::is_directory(entry.exprPath, ec))
            in.open(entry.exprPath, std::ios::binary);
        if (!in) {
            const int err = errno ? errno : EISDIR;
            error = "cannot read '" + entry.exprPath + "': " + std::strerror(err);
            return false;
        }
        std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        if (in.bad()) {
            error = "cannot read '" + entry.exprPath + "': " + std::strerror(errno);
            return false;
        }
        out = lang::SourceFile(entry.exprPath, std::move(text));
        return true;
    }
    if (!entry.preset.empty()) {
        const Preset* p = findPreset(entry.preset);
        if (!p) {
            error = "no preset called '" + entry.preset + "' (presets: " + presetNames() + ")";
            return false;
        }
        out = lang::SourceFile("<preset " + std::string(p->name) + ".se>", std::string(p->text));
        return true;
    }
    const std::string name = entry.sourceLine > 0 ? scene.path
                                                  : scene.path + " [[field]] '" + entry.name + "'";
    out = positionedSource(name, entry.source, entry.sourceLine, entry.sourceCol);
    return true;
}

FieldPtr buildSceneField(const Scene& scene, runtime::Precision precision, std::string& report,
                         bool color, const std::vector<std::string>& allowPaths) {
    lang::RenderOptions render;
    render.color = color;
    const std::shared_ptr<const runtime::FunctionTable> functions = sceneFunctions(scene);
    std::vector<SumField::Term> terms;
    bool ok = true;
    auto compileOne = [&](const lang::SourceFile& source, const std::map<std::string, Param>& params,
                          const std::string& name,
                          const std::string& exprPath) -> std::shared_ptr<ExpressionField> {
        ExpressionFieldOptions options;
        // Files named by the expression: relative to its file (the scene for inline text),
        // inside the scene's folder.
        geometry::FileAccess files =
            geometry::fileAccessFor(exprPath.empty() ? scene.path : exprPath, allowPaths);
        files.rootDir = scene.baseDir.empty() ? "." : scene.baseDir;
        options.files = files;
        options.params = params;
        options.precision = precision;
        options.scene = &scene;
        options.functions = functions;
        options.name = name;
        lang::DiagnosticSink sink;
        std::shared_ptr<ExpressionField> field = ExpressionField::compile(source, options, sink);
        if (!sink.diagnostics().empty()) report += lang::renderDiagnostics(source, sink, render);
        return field;
    };
    for (const FieldEntry& entry : scene.fields) {
        lang::SourceFile source;
        std::string error;
        if (!fieldSource(scene, entry, source, error)) {
            report += scene.path + ": error: [[field]] '" + entry.name + "': " + error + "\n";
            ok = false;
            continue;
        }
        const std::string what = entry.exprPath.empty() && entry.preset.empty()
                                     ? "field '" + entry.name + "'"
                                     : "field '" + entry.name + "' (" +
                                           (entry.preset.empty() ? entry.exprPath
                                                                 : "preset " + entry.preset) +
                                           ")";
        std::shared_ptr<ExpressionField> field =
            compileOne(source, entry.params, what, entry.exprPath);
        std::shared_ptr<ExpressionField> mask;
        if (!entry.mask.empty()) {
            const std::string maskName = entry.maskLine > 0
                                             ? scene.path
                                             : scene.path + " [[field]] '" + entry.name + "' mask";
            mask = compileOne(positionedSource(maskName, entry.mask, entry.maskLine, entry.maskCol),
                              {}, "mask of field '" + entry.name + "'", std::string());
            if (!mask) ok = false;
        }
        if (!field || !ok) {
            ok = false;
            continue;
        }
        FieldPtr result = field;
        if (mask) result = std::make_shared<MaskedField>(result, mask);
        SumField::Term term;
        if (entry.scale.isKeyed() || entry.scale.width() != 1) {
            term.field = std::make_shared<ScaledField>(result, entry.scale);
        } else {
            term.field = result;
            term.scale = entry.scale.scalarAt(0.0);
        }
        terms.push_back(std::move(term));
    }
    if (!ok) return nullptr;
    return std::make_shared<SumField>(std::move(terms));
}

} // namespace gale::fields
