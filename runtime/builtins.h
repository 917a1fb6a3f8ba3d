// The built-in function table: each built-in declared once with its signature (argument
// names and types), fold flag, docstring and float/double kernels. The compiler type-checks
// against it, the VM dispatches through it, and `gale builtins` prints it.
#pragma once

#include "lang/functions.h"
#include "runtime/kernel.h"

#include <memory>
#include <string>
#include <vector>

namespace gale::runtime {

struct Builtin {
    lang::FunctionInfo info;
    Kernel<float> kernelF = nullptr;
    Kernel<double> kernelD = nullptr;
    // Data the kernels receive as KernelFrame::user (kept alive by the table). Must be safe to
    // read from many threads at once.
    std::shared_ptr<const void> data;
};

// A scalar function F<T>::apply lifted to a Builtin whose kernels broadcast over FP[n].
template <template <class> class F>
Builtin mapBuiltin1(std::string_view name, std::string_view sig, std::string_view doc) {
    Builtin b;
    b.info.name = name; b.info.signature = sig; b.info.doc = doc;
    b.kernelF = &mapKernel1<F, float>; b.kernelD = &mapKernel1<F, double>;
    return b;
}
template <template <class> class F>
Builtin mapBuiltin2(std::string_view name, std::string_view sig, std::string_view doc) {
    Builtin b;
    b.info.name = name; b.info.signature = sig; b.info.doc = doc;
    b.kernelF = &mapKernel2<F, float>; b.kernelD = &mapKernel2<F, double>;
    return b;
}
template <template <class> class F>
Builtin mapBuiltin3(std::string_view name, std::string_view sig, std::string_view doc) {
    Builtin b;
    b.info.name = name; b.info.signature = sig; b.info.doc = doc;
    b.kernelF = &mapKernel3<F, float>; b.kernelD = &mapKernel3<F, double>;
    return b;
}
template <template <class> class F>
Builtin mapBuiltin5(std::string_view name, std::string_view sig, std::string_view doc) {
    Builtin b;
    b.info.name = name; b.info.signature = sig; b.info.doc = doc;
    b.kernelF = &mapKernel5<F, float>; b.kernelD = &mapKernel5<F, double>;
    return b;
}
// A built-in with hand-written kernels K<float>, K<double> (template functions).
template <class K>
Builtin kernelBuiltin(std::string_view name, std::string_view sig, std::string_view doc) {
    Builtin b;
    b.info.name = name; b.info.signature = sig; b.info.doc = doc;
    b.kernelF = &K::template run<float>; b.kernelD = &K::template run<double>;
    return b;
}

class FunctionTable : public lang::FunctionScope {
public:
    FunctionTable() = default;

    // The standard library: every built-in of the language.
    static std::shared_ptr<const FunctionTable> standard();

    // Adds (or replaces, by name) a built-in; parses its signature. Returns false with a
    // message when the signature is malformed.
    bool add(Builtin b, std::string* error = nullptr);

    const lang::FunctionInfo* findFunction(std::string_view name, int32_t* index) const override;
    std::vector<std::string_view> functionNames() const override;

    const Builtin& at(int32_t index) const { return mBuiltins[static_cast<size_t>(index)]; }
    size_t size() const { return mBuiltins.size(); }
    const std::vector<Builtin>& all() const { return mBuiltins; }

private:
    std::vector<Builtin> mBuiltins;
};

// Registration functions, one per source file of built-ins (each appends to the table).
void addMathBuiltins(FunctionTable& t);   // builtins_math.cpp: math, remap, vector, selection,
                                          // colour
void addCurveBuiltins(FunctionTable& t);  // builtins_curve.cpp: spline, curve, ccurve
void addStringBuiltins(FunctionTable& t); // builtins_string.cpp: sprintf, printf (getVar is
                                          // compiled by the compiler itself)
void addNoiseBuiltins(FunctionTable& t);  // noise*.cpp: the SeExpr2 noise family, curl noise

} // namespace gale::runtime
