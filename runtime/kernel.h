// The calling convention between the VM and built-in kernels, and helpers that turn a scalar
// function into a block kernel. A kernel runs over a whole block of lanes at once; operands
// are SoA arrays (component k of lane i), and a constant/uniform operand has lane stride 0.
#pragma once

#include <cstdint>
#include <string>
#include <type_traits>

namespace gale::runtime {

// Lanes per block: every varying register holds this many values per component.
constexpr int kBlockSize = 256;

template <class T>
struct Operand {
    const T* data = nullptr;          // numeric operand (null for a string operand)
    const std::string* str = nullptr; // string operand: str[lane * laneStride]
    int width = 1;
    int laneStride = 0; // 0: one value for every lane (constant or uniform); 1: one per lane
    int compStride = 0; // distance between components in `data`

    bool uniform() const { return laneStride == 0; }
    // Component k (a width-1 operand broadcasts) of lane i.
    T at(int k, int i) const { return data[(width == 1 ? 0 : k) * compStride + i * laneStride]; }
    const T* comp(int k) const { return data + (width == 1 ? 0 : k) * compStride; }
    const std::string& string(int i) const { return str[i * laneStride]; }
};

template <class T>
struct KernelFrame {
    int n = 0; // lanes to compute: kBlockSize or a tail for varying calls, 1 for uniform ones
    T* out = nullptr;          // numeric result: out[k * outCompStride + i]
    int outWidth = 1;
    int outCompStride = 0;
    std::string* outStr = nullptr; // string result: outStr[i]
    const Operand<T>* args = nullptr;
    int nargs = 0;
    // Side-effecting calls only: lane i is active iff mask == null or mask[i * maskStride] != 0.
    const T* mask = nullptr;
    int maskStride = 0;
    // printf output of this block, appended in lane order; the evaluator emits blocks in order.
    std::string* messages = nullptr;
    // The built-in's own data (Builtin::data): e.g. a scene's gust rig or a turbulence cache.
    const void* user = nullptr;

    T* outComp(int k) const { return out + k * outCompStride; }
    bool active(int i) const { return mask == nullptr || mask[i * maskStride] != T(0); }
};

template <class T>
using Kernel = void (*)(const KernelFrame<T>& f);

// Calls fn with each lane stride (0 or 1) as a compile-time constant, so that a kernel written
// as `x[i * S]` compiles to a contiguous, vectorisable loop for varying operands and to a
// broadcast for uniform ones.
template <class F>
void withStrides(int s0, F&& fn) {
    if (s0) fn(std::integral_constant<int, 1>{});
    else fn(std::integral_constant<int, 0>{});
}
template <class F>
void withStrides(int s0, int s1, F&& fn) {
    withStrides(s0, [&](auto a) {
        if (s1) fn(a, std::integral_constant<int, 1>{});
        else fn(a, std::integral_constant<int, 0>{});
    });
}
template <class F>
void withStrides(int s0, int s1, int s2, F&& fn) {
    withStrides(s0, s1, [&](auto a, auto b) {
        if (s2) fn(a, b, std::integral_constant<int, 1>{});
        else fn(a, b, std::integral_constant<int, 0>{});
    });
}

// ---- Scalar functions lifted to kernels -----------------------------------------------------
// F<T>::apply(T...) -> T is a plain scalar function. The result width is the broadcast width of
// the arguments; each component is a plain loop over lanes, specialised for uniform operands so
// that the common cases compile to contiguous, vectorisable loops.

template <template <class> class F, class T>
void mapKernel1(const KernelFrame<T>& f) {
    const Operand<T>& a = f.args[0];
    for (int k = 0; k < f.outWidth; ++k) {
        T* __restrict o = f.outComp(k);
        const T* __restrict x = a.comp(k);
        if (a.uniform()) {
            const T v = F<T>::apply(x[0]);
            for (int i = 0; i < f.n; ++i) o[i] = v;
        } else {
            for (int i = 0; i < f.n; ++i) o[i] = F<T>::apply(x[i]);
        }
    }
}

template <template <class> class F, class T>
void mapKernel2(const KernelFrame<T>& f) {
    const Operand<T>& a = f.args[0];
    const Operand<T>& b = f.args[1];
    for (int k = 0; k < f.outWidth; ++k) {
        T* __restrict o = f.outComp(k);
        const T* __restrict x = a.comp(k);
        const T* __restrict y = b.comp(k);
        if (!a.uniform() && !b.uniform()) {
            for (int i = 0; i < f.n; ++i) o[i] = F<T>::apply(x[i], y[i]);
        } else if (!a.uniform()) {
            const T yv = y[0];
            for (int i = 0; i < f.n; ++i) o[i] = F<T>::apply(x[i], yv);
        } else if (!b.uniform()) {
            const T xv = x[0];
            for (int i = 0; i < f.n; ++i) o[i] = F<T>::apply(xv, y[i]);
        } else {
            const T v = F<T>::apply(x[0], y[0]);
            for (int i = 0; i < f.n; ++i) o[i] = v;
        }
    }
}

template <template <class> class F, class T>
void mapKernel3(const KernelFrame<T>& f) {
    const Operand<T>& a = f.args[0];
    const Operand<T>& b = f.args[1];
    const Operand<T>& c = f.args[2];
    withStrides(a.laneStride, b.laneStride, c.laneStride, [&](auto sa, auto sb, auto sc) {
        for (int k = 0; k < f.outWidth; ++k) {
            T* __restrict o = f.outComp(k);
            const T* __restrict x = a.comp(k);
            const T* __restrict y = b.comp(k);
            const T* __restrict z = c.comp(k);
            for (int i = 0; i < f.n; ++i) o[i] = F<T>::apply(x[i * sa], y[i * sb], z[i * sc]);
        }
    });
}

template <template <class> class F, class T>
void mapKernel5(const KernelFrame<T>& f) {
    const Operand<T>* a = f.args;
    for (int k = 0; k < f.outWidth; ++k) {
        T* __restrict o = f.outComp(k);
        for (int i = 0; i < f.n; ++i)
            o[i] = F<T>::apply(a[0].at(k, i), a[1].at(k, i), a[2].at(k, i), a[3].at(k, i), a[4].at(k, i));
    }
}

} // namespace gale::runtime
