// The block kernels on scalar doubles, and the run-time choice of the AVX2 + FMA ones
// (bsr_kernels_avx2.cpp) on a CPU that has them.
#include "solver/linalg/bsr_kernels.h"

#include "solver/linalg/bsr_kernels_body.h"

#include <atomic>

namespace gale::solver {

#if defined(GALE_HAVE_AVX2_KERNELS)
// bsr_kernels_avx2.cpp
void bsrMultiplyRowsAvx2(const BsrPattern& m, const double* val, const double* x, double* y, std::size_t i0,
                         std::size_t i1);
void bsrMultiplyRowsAvx2(const BsrPattern& m, const float* val, const double* x, double* y, std::size_t i0,
                         std::size_t i1);
void gaussSeidelSweepAvx2(const GaussSeidelSweep& g);
void bsrUpperResidualRowsAvx2(const BsrPattern& m, const float* val, const double* x, double* t,
                              std::size_t i0, std::size_t i1);
#endif

namespace {

struct Vec3d {
    double a, b, c;
};

// The same arithmetic as the wide kernels, one lane at a time.
struct ScalarOps {
    using V = Vec3d;
    static V zero() { return {0.0, 0.0, 0.0}; }
    static V load3(const double* p) { return {p[0], p[1], p[2]}; }
    static void store3(double* p, V v) {
        p[0] = v.a;
        p[1] = v.b;
        p[2] = v.c;
    }
    static V add(V u, V v) { return {u.a + v.a, u.b + v.b, u.c + v.c}; }
    static V sub(V u, V v) { return {u.a - v.a, u.b - v.b, u.c - v.c}; }
    using B = Vec3d;
    static B broadcast(V y) { return y; }
    template <class T>
    static V block(const T* m, const B& x) {
        return {double(m[0]) * x.a + double(m[3]) * x.b + double(m[6]) * x.c,
                double(m[1]) * x.a + double(m[4]) * x.b + double(m[7]) * x.c,
                double(m[2]) * x.a + double(m[5]) * x.b + double(m[8]) * x.c};
    }
    template <class T>
    static V block(const T* m, const double* x) {
        return block(m, B{x[0], x[1], x[2]});
    }
    static V blockTimes(const double* m, V y) { return block(m, y); }
};

bool cpuHasAvx2Fma() {
#if defined(GALE_HAVE_AVX2_KERNELS)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return false;
#endif
}

std::atomic<bool>& wideSwitch() {
    static std::atomic<bool> on{cpuHasAvx2Fma()};
    return on;
}

} // namespace

bool wideKernels() { return wideSwitch().load(std::memory_order_relaxed); }
void setWideKernels(bool on) { wideSwitch().store(on && cpuHasAvx2Fma(), std::memory_order_relaxed); }

namespace {
template <class T>
void multiplyRows(const BsrPattern& m, const T* val, const double* x, double* y, std::size_t i0, std::size_t i1) {
#if defined(GALE_HAVE_AVX2_KERNELS)
    if (wideKernels()) return bsrMultiplyRowsAvx2(m, val, x, y, i0, i1);
#endif
    kernels::multiplyRows<ScalarOps>(m, val, x, y, i0, i1);
}
} // namespace

void bsrMultiplyRows(const BsrPattern& m, const double* val, const double* x, double* y, std::size_t i0,
                     std::size_t i1) {
    multiplyRows(m, val, x, y, i0, i1);
}
void bsrMultiplyRows(const BsrPattern& m, const float* val, const double* x, double* y, std::size_t i0,
                     std::size_t i1) {
    multiplyRows(m, val, x, y, i0, i1);
}

void gaussSeidelSweep(const GaussSeidelSweep& g) {
#if defined(GALE_HAVE_AVX2_KERNELS)
    if (wideKernels()) return gaussSeidelSweepAvx2(g);
#endif
    kernels::sweepAny<ScalarOps>(g);
}

void bsrUpperResidualRows(const BsrPattern& m, const float* val, const double* x, double* t,
                          std::size_t i0, std::size_t i1) {
#if defined(GALE_HAVE_AVX2_KERNELS)
    if (wideKernels()) return bsrUpperResidualRowsAvx2(m, val, x, t, i0, i1);
#endif
    kernels::upperResidualRows<ScalarOps>(m, val, x, t, i0, i1);
}

} // namespace gale::solver
