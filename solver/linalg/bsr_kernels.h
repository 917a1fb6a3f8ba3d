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

// One block Gauss–Seidel sweep over the rows [begin, end) of A x = r (end < 0: to the last row):
//   x_i += D_i⁻¹ (r_i − Σ_j A_ij x_j)
// in row order (forward) or reverse (backward); dinv holds D_i⁻¹ column-major, 9 per row (+pad).
// Rows that share no block (one colour of a multicolour ordering) may be swept in parallel
// chunks: each reads only the other colours' x.
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
    int begin = 0, end = -1;
};
void gaussSeidelSweep(const GaussSeidelSweep& s);

// t_i = −Σ_{k after diag[i]} A_ik x_k for the block rows i in [i0, i1): after a forward sweep
// from zero this is r − A x (row i satisfies its own equation but for the later columns) — the
// same terms, subtracted in the same order, as the `t` a GaussSeidelSweep pushes, so the same
// bits; a pull over rows, for when the sweep ran in parallel chunks that may not push.
void bsrUpperResidualRows(const BsrPattern& m, const float* val, const double* x, double* t,
                          std::size_t i0, std::size_t i1);

// Whether the AVX2 + FMA kernels are in use (built, the CPU has them, and not switched off);
// tests switch them off to check the portable kernels against the same references. The
// switch is process-wide: flip it only while no solve runs.
bool wideKernels();
void setWideKernels(bool on);

} // namespace gale::solver
