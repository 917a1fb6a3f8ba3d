// The block kernels (bsr_kernels_body.h) on AVX2 + FMA registers; this file alone is compiled
// with -mavx2 -mfma, and bsr_kernels.cpp calls it only on a CPU that has both. Everything here
// has internal linkage, so no AVX2 copy of a shared inline function can reach other callers.
#include "solver/linalg/bsr_kernels_body.h"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>

namespace gale::solver {

namespace {

// A 3-vector in the low lanes of a 256-bit register; the fourth lane carries a neighbouring
// value of the block being read and is never stored.
struct WideOps {
    using V = __m256d;
    static V zero() { return _mm256_setzero_pd(); }
    static V load3(const double* p) {
        return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_load_sd(p + 2), 1);
    }
    static void store3(double* p, V v) {
        _mm_storeu_pd(p, _mm256_castpd256_pd128(v));
        _mm_store_sd(p + 2, _mm256_extractf128_pd(v, 1));
    }
    static V add(V a, V b) { return _mm256_add_pd(a, b); }
    static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
    static V column(const double* p) { return _mm256_loadu_pd(p); }
    static V column(const float* p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }
    // x₀, x₁, x₂ each in all lanes.
    struct B {
        V x0, x1, x2;
    };
    static B broadcast(V y) {
        return {_mm256_permute4x64_pd(y, 0x00), _mm256_permute4x64_pd(y, 0x55), _mm256_permute4x64_pd(y, 0xAA)};
    }
    // A x = a₀ x₀ + a₁ x₁ + a₂ x₂ for the column-major block at b.
    template <class T>
    static V block(const T* b, const B& x) {
        const V s = _mm256_mul_pd(column(b), x.x0);
        return _mm256_fmadd_pd(column(b + 6), x.x2, _mm256_fmadd_pd(column(b + 3), x.x1, s));
    }
    template <class T>
    static V block(const T* b, const double* x) {
        return block(b, B{_mm256_broadcast_sd(x), _mm256_broadcast_sd(x + 1), _mm256_broadcast_sd(x + 2)});
    }
    static V blockTimes(const double* b, V y) { return block(b, broadcast(y)); }
};

} // namespace

void bsrMultiplyRowsAvx2(const BsrPattern& m, const double* val, const double* x, double* y, std::size_t i0,
                         std::size_t i1) {
    kernels::multiplyRows<WideOps>(m, val, x, y, i0, i1);
}
void bsrMultiplyRowsAvx2(const BsrPattern& m, const float* val, const double* x, double* y, std::size_t i0,
                         std::size_t i1) {
    kernels::multiplyRows<WideOps>(m, val, x, y, i0, i1);
}
void gaussSeidelSweepAvx2(const GaussSeidelSweep& g) { kernels::sweepAny<WideOps>(g); }
void bsrUpperResidualRowsAvx2(const BsrPattern& m, const float* val, const double* x, double* t,
                              std::size_t i0, std::size_t i1) {
    kernels::upperResidualRows<WideOps>(m, val, x, t, i0, i1);
}

} // namespace gale::solver
#endif
