// Instruction kernels of the block VM. Each opcode of GALE_OPCODES has an exec function here;
// the dispatch switch is generated from the same X-macro. Kernels are plain loops over
// `T* __restrict` lanes, specialised for uniform (stride-0) operands.
#include "runtime/vm.h"

#include <cmath>

namespace gale::runtime {

using lang::Instr;
using lang::Op;
using lang::Reg;

template <class T>
Operand<T> ExecContext<T>::operand(Reg r) const {
    Operand<T> o;
    if (!locations) { // folding: a constant straight from the bytecode
        const lang::RegInfo& info = bc->reg(r);
        o.laneStride = 0;
        o.compStride = 1;
        if (info.aliasOf != lang::kNoReg) {
            o.data = constants + bc->reg(info.aliasOf).constIndex + info.component;
        } else if (info.kind == lang::TypeKind::String) {
            o.str = &bc->strings[static_cast<size_t>(info.constIndex)];
        } else {
            o.data = constants + info.constIndex;
            o.width = info.width;
        }
        return o;
    }
    const RegLocation& L = locations[r];
    const lang::RegInfo& info = bc->reg(r);
    o.width = info.width;
    o.compStride = L.compStride;
    o.laneStride = L.area == RegLocation::Varying ? 1 : 0;
    if (L.isString) {
        o.str = L.area == RegLocation::Constant ? constStrings + L.offset
                : L.area == RegLocation::Uniform ? uniformStrings + L.offset
                                                 : varyingStrings + L.offset;
    } else {
        o.data = L.area == RegLocation::Constant ? constants + L.offset
                 : L.area == RegLocation::Uniform ? uniform + L.offset
                                                  : varying + L.offset;
    }
    return o;
}

template <class T>
T* ExecContext<T>::out(const Instr& in, int& compStride) const {
    if (in.dst == lang::kNoReg) {
        compStride = 1;
        return foldOut;
    }
    const RegLocation& L = locations[in.dst];
    compStride = L.compStride;
    return L.area == RegLocation::Varying ? varying + L.offset : uniform + L.offset;
}

template <class T>
std::string* ExecContext<T>::outString(const Instr& in) const {
    if (in.dst == lang::kNoReg) return foldString;
    const RegLocation& L = locations[in.dst];
    return L.area == RegLocation::Varying ? varyingStrings + L.offset : uniformStrings + L.offset;
}

namespace {

// out = f(a) per component; a width-1 operand broadcasts.
template <class T, class F>
void unaryLoop(ExecContext<T>& ctx, const Instr& in, F f) {
    const Operand<T> a = ctx.operand(in.a);
    int cs;
    T* base = ctx.out(in, cs);
    const int n = ctx.n;
    for (int k = 0; k < in.width; ++k) {
        T* __restrict o = base + k * cs;
        const T* __restrict x = a.comp(k);
        if (a.uniform()) {
            const T v = f(x[0]);
            for (int i = 0; i < n; ++i) o[i] = v;
        } else {
            for (int i = 0; i < n; ++i) o[i] = f(x[i]);
        }
    }
}

template <class T, class F>
void binaryLoop(ExecContext<T>& ctx, const Instr& in, F f) {
    const Operand<T> a = ctx.operand(in.a);
    const Operand<T> b = ctx.operand(in.b);
    int cs;
    T* base = ctx.out(in, cs);
    const int n = ctx.n;
    for (int k = 0; k < in.width; ++k) {
        T* __restrict o = base + k * cs;
        const T* __restrict x = a.comp(k);
        const T* __restrict y = b.comp(k);
        if (!a.uniform() && !b.uniform()) {
            for (int i = 0; i < n; ++i) o[i] = f(x[i], y[i]);
        } else if (!a.uniform()) {
            const T yv = y[0];
            for (int i = 0; i < n; ++i) o[i] = f(x[i], yv);
        } else if (!b.uniform()) {
            const T xv = x[0];
            for (int i = 0; i < n; ++i) o[i] = f(xv, y[i]);
        } else {
            const T v = f(x[0], y[0]);
            for (int i = 0; i < n; ++i) o[i] = v;
        }
    }
}

// Comparisons and logic read component 0 and write one 0/1 component.
template <class T, class F>
void scalarTest(ExecContext<T>& ctx, const Instr& in, F f) {
    const Operand<T> a = ctx.operand(in.a);
    const Operand<T> b = ctx.operand(in.b);
    int cs;
    T* __restrict o = ctx.out(in, cs);
    const T* __restrict x = a.comp(0);
    const T* __restrict y = b.comp(0);
    const int sa = a.laneStride, sb = b.laneStride;
    for (int i = 0; i < ctx.n; ++i) o[i] = f(x[i * sa], y[i * sb]) ? T(1) : T(0);
}

// == and != compare every component of the broadcast width.
template <class T>
void equality(ExecContext<T>& ctx, const Instr& in, bool wantEqual) {
    const Operand<T> a = ctx.operand(in.a);
    const Operand<T> b = ctx.operand(in.b);
    int cs;
    T* __restrict o = ctx.out(in, cs);
    const int w = a.width > b.width ? a.width : b.width;
    for (int i = 0; i < ctx.n; ++i) {
        bool eq = true;
        for (int k = 0; k < w; ++k) eq = eq && a.at(k, i) == b.at(k, i);
        o[i] = (eq == wantEqual) ? T(1) : T(0);
    }
}

template <class T>
T floorMod(T a, T b) {
    if (b == T(0)) return T(0);
    return a - std::floor(a / b) * b;
}

// ---- one exec function per opcode ---------------------------------------------------------

template <class T> void execCopy(const Instr& in, ExecContext<T>& c) { unaryLoop(c, in, [](T x) { return x; }); }
template <class T> void execNeg(const Instr& in, ExecContext<T>& c) { unaryLoop(c, in, [](T x) { return -x; }); }
template <class T> void execInvert(const Instr& in, ExecContext<T>& c) { unaryLoop(c, in, [](T x) { return T(1) - x; }); }
template <class T> void execNot(const Instr& in, ExecContext<T>& c) {
    const Operand<T> a = c.operand(in.a);
    int cs;
    T* __restrict o = c.out(in, cs);
    const T* __restrict x = a.comp(0);
    const int sa = a.laneStride;
    for (int i = 0; i < c.n; ++i) o[i] = x[i * sa] == T(0) ? T(1) : T(0);
}
template <class T> void execAdd(const Instr& in, ExecContext<T>& c) { binaryLoop(c, in, [](T x, T y) { return x + y; }); }
template <class T> void execSub(const Instr& in, ExecContext<T>& c) { binaryLoop(c, in, [](T x, T y) { return x - y; }); }
template <class T> void execMul(const Instr& in, ExecContext<T>& c) { binaryLoop(c, in, [](T x, T y) { return x * y; }); }
template <class T> void execDiv(const Instr& in, ExecContext<T>& c) { binaryLoop(c, in, [](T x, T y) { return x / y; }); }
template <class T> void execMod(const Instr& in, ExecContext<T>& c) { binaryLoop(c, in, [](T x, T y) { return floorMod(x, y); }); }
template <class T> void execPow(const Instr& in, ExecContext<T>& c) { binaryLoop(c, in, [](T x, T y) { return std::pow(x, y); }); }
template <class T> void execLt(const Instr& in, ExecContext<T>& c) { scalarTest(c, in, [](T x, T y) { return x < y; }); }
template <class T> void execGt(const Instr& in, ExecContext<T>& c) { scalarTest(c, in, [](T x, T y) { return x > y; }); }
template <class T> void execLe(const Instr& in, ExecContext<T>& c) { scalarTest(c, in, [](T x, T y) { return x <= y; }); }
template <class T> void execGe(const Instr& in, ExecContext<T>& c) { scalarTest(c, in, [](T x, T y) { return x >= y; }); }
template <class T> void execEq(const Instr& in, ExecContext<T>& c) { equality(c, in, true); }
template <class T> void execNe(const Instr& in, ExecContext<T>& c) { equality(c, in, false); }
template <class T> void execAnd(const Instr& in, ExecContext<T>& c) {
    scalarTest(c, in, [](T x, T y) { return x != T(0) && y != T(0); });
}
template <class T> void execOr(const Instr& in, ExecContext<T>& c) {
    scalarTest(c, in, [](T x, T y) { return x != T(0) || y != T(0); });
}

template <class T> void execSelect(const Instr& in, ExecContext<T>& c) {
    const Operand<T> cond = c.operand(in.a);
    const Operand<T> a = c.operand(in.b);
    const Operand<T> b = c.operand(in.c);
    int cs;
    T* base = c.out(in, cs);
    const T* __restrict m = cond.comp(0);
    if (cond.uniform()) { // one branch for every lane: a copy
        const Operand<T>& src = m[0] != T(0) ? a : b;
        for (int k = 0; k < in.width; ++k) {
            T* __restrict o = base + k * cs;
            const T* __restrict x = src.comp(k);
            if (src.uniform()) for (int i = 0; i < c.n; ++i) o[i] = x[0];
            else for (int i = 0; i < c.n; ++i) o[i] = x[i];
        }
        return;
    }
    for (int k = 0; k < in.width; ++k) {
        T* __restrict o = base + k * cs;
        const T* __restrict x = a.comp(k);
        const T* __restrict y = b.comp(k);
        const int sa = a.laneStride, sb = b.laneStride;
        for (int i = 0; i < c.n; ++i) o[i] = m[i] != T(0) ? x[i * sa] : y[i * sb];
    }
}

template <class T> void execIndex(const Instr& in, ExecContext<T>& c) {
    const Operand<T> v = c.operand(in.a);
    const Operand<T> idx = c.operand(in.b);
    int cs;
    T* __restrict o = c.out(in, cs);
    for (int i = 0; i < c.n; ++i) {
        const T k = idx.at(0, i);
        // Truncation toward zero; out of range (and NaN) gives 0.
        if (k > T(-1) && k < T(v.width)) o[i] = v.at(static_cast<int>(k), i);
        else o[i] = T(0);
    }
}

template <class T> void execPack(const Instr& in, ExecContext<T>& c) {
    int cs;
    T* base = c.out(in, cs);
    for (int k = 0; k < in.argCount; ++k) {
        const Operand<T> a = c.operand(c.bc->args[static_cast<size_t>(in.argBegin + k)]);
        T* __restrict o = base + k * cs;
        const T* __restrict x = a.comp(0);
        if (a.uniform()) for (int i = 0; i < c.n; ++i) o[i] = x[0];
        else for (int i = 0; i < c.n; ++i) o[i] = x[i];
    }
}

template <class T> void execCall(const Instr& in, ExecContext<T>& c) {
    const Builtin& fn = c.functions->at(in.imm);
    c.scratch.resize(static_cast<size_t>(in.argCount));
    for (int k = 0; k < in.argCount; ++k) c.scratch[static_cast<size_t>(k)] = c.operand(c.bc->args[static_cast<size_t>(in.argBegin + k)]);
    KernelFrame<T> f;
    f.n = c.n;
    f.outWidth = in.width;
    const bool strOut = in.dst == lang::kNoReg ? fn.info.parsed.result.kind == lang::ParamSpec::String
                                               : c.bc->reg(in.dst).kind == lang::TypeKind::String;
    if (strOut) f.outStr = c.outString(in);
    else f.out = c.out(in, f.outCompStride);
    f.args = c.scratch.data();
    f.nargs = in.argCount;
    if (in.mask != lang::kNoReg) {
        const Operand<T> m = c.operand(in.mask);
        f.mask = m.comp(0);
        f.maskStride = m.laneStride;
    }
    f.messages = c.messages;
    f.user = fn.data.get();
    Kernel<T> k;
    if constexpr (std::is_same_v<T, float>) k = fn.kernelF;
    else k = fn.kernelD;
    if (k) k(f);
}

template <class T> void execStrCat(const Instr& in, ExecContext<T>& c) {
    const Operand<T> a = c.operand(in.a);
    const Operand<T> b = c.operand(in.b);
    std::string* o = c.outString(in);
    for (int i = 0; i < c.n; ++i) o[i] = a.string(i) + b.string(i);
}
template <class T> void execStrEq(const Instr& in, ExecContext<T>& c) {
    const Operand<T> a = c.operand(in.a);
    const Operand<T> b = c.operand(in.b);
    int cs;
    T* o = c.out(in, cs);
    for (int i = 0; i < c.n; ++i) o[i] = a.string(i) == b.string(i) ? T(1) : T(0);
}
template <class T> void execStrNe(const Instr& in, ExecContext<T>& c) {
    const Operand<T> a = c.operand(in.a);
    const Operand<T> b = c.operand(in.b);
    int cs;
    T* o = c.out(in, cs);
    for (int i = 0; i < c.n; ++i) o[i] = a.string(i) != b.string(i) ? T(1) : T(0);
}
template <class T> void execStrSelect(const Instr& in, ExecContext<T>& c) {
    const Operand<T> cond = c.operand(in.a);
    const Operand<T> a = c.operand(in.b);
    const Operand<T> b = c.operand(in.c);
    std::string* o = c.outString(in);
    for (int i = 0; i < c.n; ++i) o[i] = cond.at(0, i) != T(0) ? a.string(i) : b.string(i);
}

} // namespace

template <class T>
void execute(const Instr& in, ExecContext<T>& ctx) {
    switch (in.op) {
#define GALE_X(name, shape, doc)                                                                   \
    case Op::name: exec##name<T>(in, ctx); break;
        GALE_OPCODES(GALE_X)
#undef GALE_X
    }
}

template struct ExecContext<float>;
template struct ExecContext<double>;
template void execute<float>(const Instr&, ExecContext<float>&);
template void execute<double>(const Instr&, ExecContext<double>&);

} // namespace gale::runtime
