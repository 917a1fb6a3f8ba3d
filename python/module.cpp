// `import gale`: the module's definition (PYBIND11_MODULE): errors, compile/Expression,
// Scene/Frame. Built by python/CMakeLists.txt into build/python/gale*.so.
#include "python/module.h"

PYBIND11_MODULE(gale, m) {
    m.doc() =
        "gale: wind fields for cloth and hair. gale.compile(path | source=...) -> Expression; "
        "gale.Scene(path, set={...}) -> sample(), simulate(). See docs/python.md.";
    m.attr("__version__") = GALE_VERSION;
    gale::python::addErrors(m);
    gale::python::addExpression(m);
    gale::python::addScene(m);
}
