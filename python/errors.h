// The Python module's exceptions (gale.Error and its subclasses) and the argument checks the
// bindings share: every bad argument raises one of them, nothing reaches the interpreter as a
// crash.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

namespace gale::python {

namespace py = pybind11;

// Creates gale.Error (Exception), gale.CompileError, gale.SceneError, gale.SimulationError
// (each an Error) and gale.ArgumentError (an Error and a ValueError) in `m`.
void addErrors(py::module_& m);

enum class ErrorKind { Compile, Scene, Simulation, Argument, Io };

// Raises the exception of `kind` with `message` (never returns).
[[noreturn]] void raise(ErrorKind kind, const std::string& message);
// The exception object of `kind` (for raising with attributes set).
py::object errorType(ErrorKind kind);

} // namespace gale::python
