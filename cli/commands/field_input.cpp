// Loading the wind of `gale sample` / `gale viz` (an expression or a scene) as a Field, with
// diagnostics on stderr, and the shared number-list and frame-range flag parsers.
#include "cli/commands/field_input.h"

#include "cli/common.h"
#include "fields/expression_field.h"
#include "scene/load.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <iostream>
#include <sstream>

namespace gale::cli {

namespace {

std::string trim(const std::string& s) {
    const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

bool parseDouble(const std::string& text, double& out) {
    std::string t = trim(text);
    const char* a = t.data();
    const char* e = a + t.size();
    if (t.size() > 1 && *a == '+') ++a;
    std::from_chars_result r = std::from_chars(a, e, out);
    return !t.empty() && r.ec == std::errc() && r.ptr == e && std::isfinite(out);
}

bool parseLong(const std::string& text, long& out) {
    std::string t = trim(text);
    const char* a = t.data();
    const char* e = a + t.size();
    if (t.size() > 1 && *a == '+') ++a;
    std::from_chars_result r = std::from_chars(a, e, out);
    return !t.empty() && r.ec == std::errc() && r.ptr == e;
}

// An ExpressionField with values for the --set variables that are not declared parameters
// (bound as extra uniforms, as `gale eval` binds every --set).
class ExtraUniformField : public fields::Field {
public:
    ExtraUniformField(std::shared_ptr<const fields::ExpressionField> field,
                      std::vector<runtime::UniformValue> uniforms)
        : mField(std::move(field)), mUniforms(std::move(uniforms)) {}
    fields::SampleStatus sample(const double* positions, size_t count,
                                const fields::SampleTime& when, double* velocities) const override {
        return mField->sampleWith(positions, count, when, velocities, mUniforms, {});
    }
    std::string describe() const override { return mField->describe(); }

private:
    std::shared_ptr<const fields::ExpressionField> mField;
    std::vector<runtime::UniformValue> mUniforms;
};

// FILE.se | -e EXPR: --set NAME=VALUE overrides the parameter NAME when the source declares
// one (`$speed = 4;`), else binds $NAME as a uniform variable.
int loadExpression(const SourceOptions& source, FieldInput& out) {
    std::vector<SetValue> sets;
    if (!parseSets(source.sets, sets)) return kExitUsage;
    lang::SourceFile file;
    if (int rc = loadSource(source.file, source.expr, file)) return rc;
    const std::vector<fields::ParameterDecl> declared = fields::findParameters(file);
    fields::ExpressionFieldOptions options;
    options.precision = runtime::Precision::Float;
    options.files = geometry::fileAccessFor(source.file, source.allowPaths);
    std::vector<runtime::UniformValue> extras;
    for (const SetValue& s : sets) {
        const bool isParameter =
            std::any_of(declared.begin(), declared.end(),
                        [&](const fields::ParameterDecl& d) { return d.name == s.name; });
        if (isParameter && !s.isString) {
            options.params[s.name] =
                s.value.size() == 1 ? fields::Param(s.value[0]) : fields::Param(s.value);
            continue;
        }
        // A later --set of the same name wins.
        auto same = [&](const auto& v) { return v.name == s.name; };
        options.extraVariables.erase(
            std::remove_if(options.extraVariables.begin(), options.extraVariables.end(), same),
            options.extraVariables.end());
        extras.erase(std::remove_if(extras.begin(), extras.end(), same), extras.end());
        runtime::UniformValue u;
        u.name = s.name;
        if (s.isString) {
            u.text = s.text;
            options.extraVariables.push_back({s.name, lang::Type::string(lang::Lifetime::Uniform)});
        } else {
            u.value = s.value;
            options.extraVariables.push_back(
                {s.name,
                 lang::Type::fp(static_cast<int>(s.value.size()), lang::Lifetime::Uniform)});
        }
        extras.push_back(std::move(u));
    }
    lang::DiagnosticSink sink;
    std::shared_ptr<fields::ExpressionField> field =
        fields::ExpressionField::compile(file, options, sink);
    if (!sink.diagnostics().empty()) {
        lang::RenderOptions render;
        render.color = useColor();
        std::cerr << lang::renderDiagnostics(file, sink, render) << std::flush;
    }
    if (!field || sink.hasErrors()) return kExitInput;
    out.name = file.name();
    if (extras.empty())
        out.field = field;
    else
        out.field = std::make_shared<ExtraUniformField>(field, std::move(extras));
    return kExitOk;
}

// SCENE.toml: --set KEY=VALUE overrides a scene key by its dotted path.
int loadSceneInput(const SourceOptions& source, FieldInput& out) {
    auto scene = std::make_shared<fields::Scene>();
    std::vector<scene::SceneError> errors;
    gale::scene::SceneLoadOptions options;
    options.sets = source.sets;
    if (!gale::scene::loadScene(source.file, *scene, errors, options))
        return printSceneErrors(errors);
    std::string report;
    fields::FieldPtr field =
        fields::buildSceneField(*scene, runtime::Precision::Float, report, useColor(),
                                source.allowPaths);
    if (!report.empty()) std::cerr << report << (report.back() == '\n' ? "" : "\n") << std::flush;
    if (!field) return kExitInput;
    out.name = source.file;
    out.field = field;
    out.scene = scene;
    return kExitOk;
}

} // namespace

bool isSceneFile(const std::string& path) {
    if (path.size() < 5) return false;
    std::string ext = path.substr(path.size() - 5);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".toml";
}

int loadFieldInput(const SourceOptions& source, double fpsOverride, FieldInput& out) {
    const bool scene = source.expr.empty() && isSceneFile(source.file);
    int rc = scene ? loadSceneInput(source, out) : loadExpression(source, out);
    if (rc) return rc;
    out.fps = fpsOverride > 0 ? fpsOverride : out.scene ? out.scene->settings.fps : 24.0;
    out.timeZero = out.scene ? out.scene->settings.timeZero : 0.0;
    return kExitOk;
}

bool parseNumbers(const std::string& text, size_t count, const std::string& flag,
                  std::vector<double>& out, std::string& error) {
    out.clear();
    std::stringstream parts(text);
    std::string part;
    while (std::getline(parts, part, ',')) {
        double v = 0.0;
        if (!parseDouble(part, v)) {
            error = flag + " '" + text + "': '" + trim(part) + "' is not a finite number";
            return false;
        }
        out.push_back(v);
    }
    if (out.size() != count || (!text.empty() && text.back() == ',')) {
        error = flag + " '" + text + "': expected " + std::to_string(count) +
                " comma-separated numbers";
        return false;
    }
    return true;
}

bool parseFrameRange(const std::string& text, long& first, long& last, std::string& error) {
    const size_t colon = text.find(':');
    bool ok;
    if (colon == std::string::npos) {
        ok = parseLong(text, first);
        last = first;
    } else {
        ok = parseLong(text.substr(0, colon), first) && parseLong(text.substr(colon + 1), last);
    }
    if (!ok) {
        error = "--frames '" + text + "': expected A:B with whole frame numbers (1:48)";
        return false;
    }
    if (last < first) {
        error = "--frames '" + text + "': the last frame comes before the first";
        return false;
    }
    if (last - first >= kMaxFrames) {
        error = "--frames '" + text + "': more than " + std::to_string(kMaxFrames) +
                " frames; split the range into several runs";
        return false;
    }
    return true;
}

} // namespace gale::cli
