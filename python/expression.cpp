// gale.compile and gale.Expression: an expression file or source text compiled once (its
// declared parameters as uniforms, as `gale eval` binds them), evaluated on (N, 3) numpy arrays
// of points with the GIL released. Compile errors raise gale.CompileError with the text
// `gale check` prints.
#include "python/module.h"

#include "fields/expression_field.h"
#include "geometry/file_policy.h"
#include "lang/diagnostics.h"
#include "runtime/program.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>

namespace gale::python {

namespace {

const char* severityName(lang::Severity s) {
    return s == lang::Severity::Error ? "error" : s == lang::Severity::Warning ? "warning" : "note";
}

py::list diagnosticList(const lang::SourceFile& source, const lang::DiagnosticSink& sink) {
    py::list out;
    for (const lang::Diagnostic& d : sink.diagnostics()) {
        const lang::LineCol at = source.lineCol(d.span.begin);
        py::dict item;
        item["severity"] = severityName(d.severity);
        item["message"] = d.message;
        item["file"] = source.name();
        item["line"] = at.line;
        item["col"] = at.col;
        py::list notes;
        for (const lang::DiagnosticNote& n : d.notes) notes.append(n.message);
        item["notes"] = notes;
        out.append(item);
    }
    return out;
}

// How many of the n doubles at p are infinite or NaN (exponent bits all set), reading only
// each value's high word: a loop the compiler vectorises with baseline SSE2.
uint32_t nonFiniteCount(const double* p, size_t n) {
    uint32_t count = 0;
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(p);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    constexpr size_t kHigh = 4;
#else
    constexpr size_t kHigh = 0;
#endif
    for (size_t i = 0; i < n; ++i) {
        uint32_t high;
        std::memcpy(&high, bytes + 8 * i + kHigh, 4);
        count += (high & 0x7ff00000u) == 0x7ff00000u;
    }
    return count;
}

py::object valueObject(const std::vector<double>& v) {
    if (v.size() == 1) return py::float_(v[0]);
    py::list l;
    for (double x : v) l.append(x);
    return l;
}

} // namespace

Expression::Expression(const std::optional<std::string>& path,
                       const std::optional<std::string>& source,
                       const std::vector<std::string>& allowPaths) {
    if (path.has_value() == source.has_value())
        raise(ErrorKind::Argument,
              "gale.compile takes a file name or source=TEXT, not both or neither");
    std::string text;
    if (path) {
        std::ifstream in(*path, std::ios::binary);
        if (!in) raise(ErrorKind::Io, *path + ": cannot read: " + std::strerror(errno));
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        mPath = *path;
    } else {
        text = *source;
    }
    // The names `gale check FILE` and `gale check -e TEXT` give, so the messages match.
    mSource = lang::SourceFile(path ? *path : "<expr>", text);
    mParams = fields::findParameters(mSource);
    std::vector<lang::HostVariable> variables = runtime::standardVariables();
    for (const fields::ParameterDecl& p : mParams)
        variables.push_back({p.name, lang::Type::fp(static_cast<int>(p.defaultValue.size()),
                                                    lang::Lifetime::Uniform)});
    const lang::SourceFile compiled = fields::withoutParameters(mSource, mParams);
    runtime::CompileSettings settings;
    settings.variables = variables;
    settings.functions =
        fields::fieldFunctions(geometry::fileAccessFor(path ? *path : "", allowPaths));
    lang::DiagnosticSink sink;
    mProgram = runtime::Program::compile(compiled, settings, sink);
    if (sink.diagnostics().empty()) return;
    const std::string text2 = lang::renderDiagnostics(mSource, sink);
    if (!sink.hasErrors()) {
        if (PyErr_WarnEx(PyExc_UserWarning, text2.c_str(), 1) != 0) throw py::error_already_set();
        return;
    }
    py::object type = errorType(ErrorKind::Compile);
    py::object err = type(text2);
    err.attr("diagnostics") = diagnosticList(mSource, sink);
    PyErr_SetObject(type.ptr(), err.ptr());
    throw py::error_already_set();
}

py::dict Expression::params() const {
    py::dict out;
    for (const fields::ParameterDecl& p : mParams) {
        py::dict d;
        d["value"] = valueObject(p.defaultValue);
        d["min"] = p.hasRange ? py::object(py::float_(p.min)) : py::object(py::none());
        d["max"] = p.hasRange ? py::object(py::float_(p.max)) : py::object(py::none());
        out[py::str(p.name)] = d;
    }
    return out;
}

int Expression::width() const {
    return mProgram->resultIsString() ? 0 : mProgram->resultWidth();
}

py::array Expression::eval(const py::object& pointsObj, std::optional<double> t,
                           std::optional<double> frame, const py::object& paramsObj,
                           const std::string& precision, int threads, double fps,
                           const py::object& outObj) const {
    if (precision != "float" && precision != "double")
        raise(ErrorKind::Argument,
              "precision must be \"float\" or \"double\", not \"" + precision + "\"");
    if (!(fps > 0) || !std::isfinite(fps))
        raise(ErrorKind::Argument, "fps must be a positive number");
    if (threads < 0) raise(ErrorKind::Argument, "threads must not be negative (0: all)");
    if (mProgram->resultIsString())
        raise(ErrorKind::Argument,
              "the expression gives a string (" + mSource.name() + "), not numbers");
    if ((t && !std::isfinite(*t)) || (frame && !std::isfinite(*frame)))
        raise(ErrorKind::Argument, "t and frame must be finite numbers");

    // The points: a float64 array is read in place through its strides; anything else
    // (float32) is converted once to float64, which the VM's inputs are.
    if (!py::isinstance<py::array>(pointsObj))
        raise(ErrorKind::Argument, "P must be a numpy array of shape (N, 3), float32 or float64");
    py::array points = py::reinterpret_borrow<py::array>(pointsObj);
    if (points.ndim() != 2 || points.shape(1) != 3)
        raise(ErrorKind::Argument, "P must have shape (N, 3), not " +
                                       std::string(py::str(py::getattr(points, "shape"))));
    const bool f64 = points.dtype().is(py::dtype::of<double>());
    const bool f32 = points.dtype().is(py::dtype::of<float>());
    if (!f64 && !f32)
        raise(ErrorKind::Argument,
              "P must be float32 or float64, not " + std::string(py::str(points.dtype())));
    const size_t n = static_cast<size_t>(points.shape(0));
    py::array_t<double> converted;
    const double* data = nullptr;
    std::ptrdiff_t pointStride = 3, compStride = 1;
    if (f64 && points.strides(0) % 8 == 0 && points.strides(1) % 8 == 0) {
        data = static_cast<const double*>(points.data());
        pointStride = points.strides(0) / 8;
        compStride = points.strides(1) / 8;
    } else {
        converted = py::array_t<double, py::array::c_style | py::array::forcecast>(points);
        data = converted.data();
    }
    // Uniforms: $t and $frame each default from the other through fps, as `gale eval` does.
    const double tv = t ? *t : frame ? *frame / fps : 0.0;
    const double fv = frame ? *frame : tv * fps;
    runtime::EvalRequest request;
    request.count = n;
    request.threads = threads;
    request.uniforms.push_back({"t", {tv}, ""});
    request.uniforms.push_back({"frame", {fv}, ""});
    request.uniforms.push_back({"fps", {fps}, ""});
    std::vector<std::vector<double>> values;
    for (const fields::ParameterDecl& p : mParams) values.push_back(p.defaultValue);
    if (!paramsObj.is_none()) {
        if (!py::isinstance<py::dict>(paramsObj))
            raise(ErrorKind::Argument, "params must be a dict {name: value}");
        for (auto item : py::reinterpret_borrow<py::dict>(paramsObj)) {
            const std::string name = py::str(item.first);
            size_t at = 0;
            while (at < mParams.size() && mParams[at].name != name) ++at;
            if (at == mParams.size()) {
                std::string declared;
                for (const fields::ParameterDecl& p : mParams)
                    declared += (declared.empty() ? "" : ", ") + p.name;
                raise(ErrorKind::Argument,
                      "unknown parameter '" + name + "' for " + mSource.name() +
                          (declared.empty() ? " (it declares none)"
                                            : " (declared: " + declared + ")"));
            }
            std::vector<double> v;
            try {
                if (py::isinstance<py::sequence>(item.second) &&
                    !py::isinstance<py::str>(item.second))
                    v = item.second.cast<std::vector<double>>();
                else
                    v = {item.second.cast<double>()};
            } catch (const py::cast_error&) {
                raise(ErrorKind::Argument,
                      "parameter '" + name + "' must be a number or a list of numbers");
            }
            if (v.size() != mParams[at].defaultValue.size())
                raise(ErrorKind::Argument, "parameter '" + name + "' has " +
                                               std::to_string(mParams[at].defaultValue.size()) +
                                               " component(s), not " + std::to_string(v.size()));
            for (double x : v)
                if (!std::isfinite(x))
                    raise(ErrorKind::Argument, "parameter '" + name + "' must be finite");
            values[at] = v;
        }
    }
    for (size_t i = 0; i < mParams.size(); ++i)
        request.uniforms.push_back({mParams[i].name, values[i], ""});
    const int w = mProgram->resultWidth();
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(n)};
    if (w != 1) shape.push_back(w);
    bool usesId = false;
    for (const lang::HostInput& in : mProgram->bytecode().inputs)
        usesId = usesId || in.name == "id";

    // In chunks that stay in cache: each chunk is evaluated, then its points are checked
    // (finite) from cache, so the check costs no second pass over memory; a non-finite point
    // raises and the result is dropped. Chunks run one VM thread each, on `threads` threads
    // (tbb), in any order: the VM's lanes do not depend on how points are split. $id is the
    // point's index in the whole array, as one call would number it.
    const size_t workers = threads == 0
                               ? static_cast<size_t>(tbb::this_task_arena::max_concurrency())
                               : static_cast<size_t>(threads);
    const size_t kChunk =
        workers <= 1 ? size_t(1) << 16
                     : std::clamp<size_t>(n / (8 * workers), size_t(1) << 12, size_t(1) << 16);
    const size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<std::string> chunkMessages(chunks);
    std::vector<size_t> chunkBad(chunks, n);
    std::vector<std::string> chunkError(chunks);
    runtime::EvalResult r;
    py::array out;
    auto run = [&](auto* typed) {
        using T = std::remove_pointer_t<decltype(typed)>;
        py::array result;
        if (outObj.is_none()) {
            result = py::array_t<T>(shape);
        } else {
            // out=: the caller's array, written in place (no allocation per call).
            if (!py::isinstance<py::array>(outObj))
                raise(ErrorKind::Argument, "out must be a numpy array");
            result = py::reinterpret_borrow<py::array>(outObj);
            bool ok = result.dtype().is(py::dtype::of<T>()) &&
                      result.ndim() == static_cast<py::ssize_t>(shape.size()) &&
                      (result.flags() & py::array::c_style) && result.writeable();
            for (size_t k = 0; ok && k < shape.size(); ++k)
                ok = result.shape(static_cast<py::ssize_t>(k)) == shape[k];
            if (!ok)
                raise(ErrorKind::Argument, std::string("out must be a writeable C-contiguous ") +
                                               (sizeof(T) == 4 ? "float32" : "float64") +
                                               " array of shape (" + std::to_string(n) +
                                               (w == 1 ? "" : ", " + std::to_string(w)) + ")");
        }
        T* dst = static_cast<T*>(result.mutable_data());
        auto doChunk = [&](size_t c) {
            const size_t at = c * kChunk, m = std::min(kChunk, n - at);
            const double* p = data + static_cast<std::ptrdiff_t>(at) * pointStride;
            std::vector<double> ids(usesId ? m : 0);
            for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<double>(at + i);
            runtime::EvalRequest chunk = request;
            chunk.count = m;
            chunk.threads = 1;
            chunk.varyings.push_back({"P", 3, p, pointStride, compStride});
            if (usesId) chunk.varyings.push_back({"id", 1, ids.data(), 1, 1});
            runtime::EvalOutput<T> o;
            o.data = dst + at * static_cast<size_t>(w);
            o.pointStride = w;
            o.compStride = 1;
            runtime::EvalResult cr = runtime::evaluate<T>(*mProgram, chunk, o);
            chunkMessages[c] = std::move(cr.messages);
            if (!cr.ok) chunkError[c] = cr.error.empty() ? "evaluation failed" : cr.error;
            // Checked after the chunk's evaluation, while its points are still in cache (a
            // check first would add a pass over memory the evaluation cannot overlap).
            const bool contiguous = pointStride == 3 && compStride == 1;
            if (contiguous && nonFiniteCount(p, 3 * m) == 0) return;
            for (size_t i = 0; i < m && chunkBad[c] == n; ++i)
                for (int k = 0; k < 3; ++k)
                    if (!std::isfinite(
                            p[static_cast<std::ptrdiff_t>(i) * pointStride + k * compStride]))
                        chunkBad[c] = at + i;
        };
        {
            py::gil_scoped_release release;
            if (workers <= 1 || chunks == 1) {
                for (size_t c = 0; c < chunks; ++c) doChunk(c);
            } else {
                tbb::task_arena arena(static_cast<int>(workers));
                arena.execute([&] { tbb::parallel_for(size_t(0), chunks, doChunk); });
            }
        }
        out = result;
    };
    if (precision == "float")
        run(static_cast<float*>(nullptr));
    else
        run(static_cast<double*>(nullptr));
    std::string messages;
    for (size_t c = 0; c < chunks; ++c) messages += chunkMessages[c];
    for (size_t c = 0; c < chunks; ++c)
        if (chunkBad[c] != n)
            raise(ErrorKind::Argument, "P[" + std::to_string(chunkBad[c]) +
                                           "] is not finite (NaN or infinite); "
                                           "every point must be a finite position");
    for (size_t c = 0; c < chunks; ++c)
        if (!chunkError[c].empty()) {
            r.ok = false;
            r.error = chunkError[c];
            break;
        }
    r.messages = messages;
    if (!r.messages.empty()) py::module_::import("sys").attr("stderr").attr("write")(r.messages);
    if (!r.ok) raise(ErrorKind::Argument, "cannot evaluate " + mSource.name() + ": " + r.error);
    return out;
}

void addExpression(py::module_& m) {
    py::class_<Expression, std::shared_ptr<Expression>>(
        m, "Expression",
        "A compiled expression (gale.compile); safe to evaluate from "
        "several threads at once")
        .def("eval", &Expression::eval, py::arg("P"), py::kw_only(), py::arg("t") = py::none(),
             py::arg("frame") = py::none(), py::arg("params") = py::none(),
             py::arg("precision") = "float", py::arg("threads") = 0, py::arg("fps") = 24.0,
             py::arg("out") = py::none(),
             "Evaluates at the points P ((N, 3) float32 or float64; float64 is read in place). $t "
             "and $frame "
             "default from each other through fps; params overrides declared parameters by name. "
             "Returns (N,) "
             "for a scalar expression, else (N, k): float32 with precision=\"float\", float64 with "
             "\"double\". "
             "threads=0 uses every core; the result does not depend on it. The GIL is released "
             "meanwhile.")
        .def_property_readonly(
            "params", &Expression::params,
            "The declared parameters: {name: {\"value\", \"min\", \"max\"}} (None when no range)")
        .def_property_readonly("width", &Expression::width, "Components of the result (1: scalar)")
        .def_property_readonly("name", [](const Expression& e) { return e.source().name(); })
        .def("__repr__", [](const Expression& e) {
            return "<gale.Expression " + e.source().name() + " FP[" + std::to_string(e.width()) +
                   "]>";
        });
    m.def(
        "compile",
        [](std::optional<std::string> path, std::optional<std::string> source,
           std::vector<std::string> allow) {
            return std::make_shared<Expression>(path, source, allow);
        },
        py::arg("path") = py::none(), py::kw_only(), py::arg("source") = py::none(),
        py::arg("allow_paths") = std::vector<std::string>(),
        "Compiles an expression file, or source text with source=...; raises gale.CompileError "
        "(str(): the "
        "text `gale check` prints, .diagnostics: the list). Files the expression names (sdf(), "
        "vdb()) resolve "
        "against its folder or one of allow_paths.");
}

} // namespace gale::python
