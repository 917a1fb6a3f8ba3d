// The Python module's exception classes (python/errors.h).
#include "python/errors.h"

namespace gale::python {

namespace {

// Owned references, never released: the classes live as long as the interpreter.
PyObject* gTypes[5] = {};

py::object newType(py::module_& m, const char* name, py::tuple bases, const char* doc) {
    py::dict attrs;
    attrs["__doc__"] = doc;
    attrs["__module__"] = "gale";
    py::object type = py::reinterpret_borrow<py::object>(reinterpret_cast<PyObject*>(&PyType_Type));
    py::object t = type(name, bases, attrs);
    m.attr(name) = t;
    return t;
}

PyObject* keep(py::object o) {
    return o.release().ptr();
}

} // namespace

void addErrors(py::module_& m) {
    py::object exception = py::reinterpret_borrow<py::object>(PyExc_Exception);
    py::object valueError = py::reinterpret_borrow<py::object>(PyExc_ValueError);
    py::object osError = py::reinterpret_borrow<py::object>(PyExc_OSError);
    py::object error = newType(m, "Error", py::make_tuple(exception), "Every error gale raises.");
    gTypes[int(ErrorKind::Compile)] = keep(newType(
        m, "CompileError", py::make_tuple(error),
        "An expression did not compile: str() is the text `gale check` prints; .diagnostics "
        "lists each problem as a dict (severity, message, line, col, notes)."));
    gTypes[int(ErrorKind::Scene)] =
        keep(newType(m, "SceneError", py::make_tuple(error),
                     "A scene file (or a `set` override) is wrong: str() names file:line:col."));
    gTypes[int(ErrorKind::Simulation)] =
        keep(newType(m, "SimulationError", py::make_tuple(error),
                     "A simulation failed numerically (non-finite state that halving the substep "
                     "could not fix)."));
    gTypes[int(ErrorKind::Argument)] =
        keep(newType(m, "ArgumentError", py::make_tuple(error, valueError),
                     "A bad argument: shape, dtype, NaN point, unknown parameter."));
    gTypes[int(ErrorKind::Io)] = keep(newType(m, "IOError", py::make_tuple(error, osError),
                                              "A file could not be read or written."));
}

py::object errorType(ErrorKind kind) {
    return py::reinterpret_borrow<py::object>(gTypes[int(kind)]);
}

void raise(ErrorKind kind, const std::string& message) {
    PyErr_SetString(gTypes[int(kind)], message.c_str());
    throw py::error_already_set();
}

} // namespace gale::python
