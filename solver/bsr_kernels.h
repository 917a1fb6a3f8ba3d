// The inner loops of the 3×3-block sparse solvers — block-row products and block Gauss–Seidel
// sweeps — written once (bsr_kernels_body.h) and compiled twice: scalar for any x86-64, and
// 4-wide for AVX2 + FMA, picked at run time (so the portable build uses AVX2 where it exists).
#pragma once

#include <cstddef>

namespace gale::solver {

// The pattern of a block-CSR matrix: block row i holds slots start[i] .. start[i+1], column
// cols[k] of slot k, sorted; diag[i] is the slot of (i, i). Values are 9 per slot, column-major
// (val[9k + 3c + r] = A(r, c)), and every value array carries kBsrPad extra entries at its
// end: a block is read as three 4-wide columns, each one value longer than the column.
struct BsrPattern {
    const int* start = nullptr;
    const int* cols = nullptr;
    const int* diag = nullptr;
    int n = 0;
};
constexpr std::size_t kBsrPad = 1;

// y_i = Σ_k A_ik x_k for the block rows i in [i0, i1); each row summed in column order.
void bsrMultiplyRows(const BsrPattern& m, const double* val, const double* x, double* y, std::size_t i0,
                     std::size_t i1);
void bsrMultiplyRows(const BsrPattern& m, const float* val, const double* x, double* y, std::size_t i0,
                     std::size_t i1);

// One block Gauss–Seidel sweep over all rows of A x = r:
//   x_i += D_i⁻¹ (r_i − Σ_j A_ij x_j)
// in row order (forward) or reverse (backward); dinv holds D_i⁻¹ column-major, 9 per row (+pad).
// fromZero (forward only): x is zero on entry, so row i reads only the columns before i.
// With fromZero, `t` (if not null) receives r − A x after the sweep without a second pass:
// row i then satisfies its equation, and its blocks below the diagonal, read through `mirror`
// (mirror[k]: the slot of the transposed block), subtract A_ji x_i from the earlier rows j.
struct GaussSeidelSweep {
    BsrPattern pattern;
    const float* val = nullptr;
    const int* mirror = nullptr;
    const double* dinv = nullptr;
    const double* r = nullptr;
    double* x = nullptr;
    double* t = nullptr;
    bool forward = true;
    bool fromZero = false;
};
void gaussSeidelSweep(const GaussSeidelSweep& s);

// Whether the AVX2 + FMA kernels are in use (built, the CPU has them, and not switched off);
// tests switch them off to check the portable kernels against the same references. The
// switch is process-wide: flip it only while no solve runs.
bool wideKernels();
void setWideKernels(bool on);

} // namespace gale::solver
