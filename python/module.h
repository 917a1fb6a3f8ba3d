// The classes of the `gale` Python module (python/): a compiled expression and a loaded scene,
// and the functions that add them to the module.
#pragma once

#include "python/errors.h"

#include "fields/expression_field.h"
#include "fields/field.h"
#include "fields/scene.h"
#include "lang/source.h"
#include "runtime/program.h"

#include <pybind11/numpy.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace gale::python {

class Expression {
public:
    Expression(const std::optional<std::string>& path, const std::optional<std::string>& source,
               const std::vector<std::string>& allowPaths);
    py::array eval(const py::object& points, std::optional<double> t, std::optional<double> frame,
                   const py::object& params, const std::string& precision, int threads, double fps,
                   const py::object& out) const;
    py::dict params() const;
    int width() const;
    const lang::SourceFile& source() const { return mSource; }

private:
    std::string mPath;
    lang::SourceFile mSource; // as written (diagnostics are rendered against it)
    std::vector<fields::ParameterDecl> mParams;
    std::shared_ptr<const runtime::Program> mProgram;
};

void addExpression(py::module_& m);
void addScene(py::module_& m);

} // namespace gale::python
