// The loops of the block kernels (bsr_kernels.h), written once over a small "Ops" type that
// supplies a 3-vector V, a 3-vector B broadcast for products, and their arithmetic; bsr_kernels.cpp instantiates them with scalar
// doubles, bsr_kernels_avx2.cpp with AVX2 + FMA registers. Private to those two files.
#pragma once

#include "solver/linalg/bsr_kernels.h"

#include <cstddef>

namespace gale::solver::kernels {

// y_i = Σ_k A_ik x_k for the rows [i0, i1).
template <class Ops, class T>
inline void multiplyRows(const BsrPattern& m, const T* val, const double* x, double* y, std::size_t i0,
                         std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) {
        typename Ops::V s = Ops::zero();
        for (int k = m.start[i]; k < m.start[i + 1]; ++k)
            s = Ops::add(s, Ops::block(val + 9 * static_cast<std::size_t>(k), x + 3 * static_cast<std::size_t>(m.cols[k])));
        Ops::store3(y + 3 * i, s);
    }
}

// x_i += D_i⁻¹ (r_i − Σ_j A_ij x_j) over the rows in order or reverse (see GaussSeidelSweep).
template <class Ops, bool Forward, bool FromZero, bool Residual>
inline void sweep(const GaussSeidelSweep& g) {
    const int* start = g.pattern.start;
    const int* cols = g.pattern.cols;
    const int* diag = g.pattern.diag;
    const int n = g.pattern.n;
    const float* val = g.val;
    const int* mirror = g.mirror;
    const double* dinv = g.dinv;
    const double* r = g.r;
    double* x = g.x;
    double* t = g.t; // (locals: the stores below might alias `g` for all the compiler knows)
    const int begin = g.begin, end = g.end < 0 ? n : g.end;
    for (int s = 0; s < end - begin; ++s) {
        const int i = Forward ? begin + s : end - 1 - s;
        typename Ops::V y = Ops::load3(r + 3 * static_cast<std::size_t>(i));
        const int last = FromZero ? diag[i] : start[i + 1];
        for (int k = start[i]; k < last; ++k)
            y = Ops::sub(y, Ops::block(val + 9 * static_cast<std::size_t>(k), x + 3 * static_cast<std::size_t>(cols[k])));
        double* xi = x + 3 * static_cast<std::size_t>(i);
        const typename Ops::V xNew = Ops::blockTimes(dinv + 9 * static_cast<std::size_t>(i), y);
        Ops::store3(xi, FromZero ? xNew : Ops::add(Ops::load3(xi), xNew));
        if (!Residual) continue;
        // t_j −= A_ji x_i for the earlier rows j; row i itself is satisfied (t_i = 0) until the
        // later rows subtract their part.
        Ops::store3(t + 3 * static_cast<std::size_t>(i), Ops::zero());
        const typename Ops::B xb = Ops::broadcast(xNew);
        for (int k = start[i]; k < last; ++k) {
            double* tj = t + 3 * static_cast<std::size_t>(cols[k]);
            Ops::store3(tj, Ops::sub(Ops::load3(tj), Ops::block(val + 9 * static_cast<std::size_t>(mirror[k]), xb)));
        }
    }
}

// t_i = −Σ_{k > diag[i]} A_ik x_k for the rows [i0, i1) (see bsrUpperResidualRows).
template <class Ops>
inline void upperResidualRows(const BsrPattern& m, const float* val, const double* x, double* t,
                              std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) {
        typename Ops::V s = Ops::zero();
        for (int k = m.diag[i] + 1; k < m.start[i + 1]; ++k)
            s = Ops::sub(s, Ops::block(val + 9 * static_cast<std::size_t>(k),
                                       x + 3 * static_cast<std::size_t>(m.cols[k])));
        Ops::store3(t + 3 * i, s);
    }
}

template <class Ops>
inline void sweepAny(const GaussSeidelSweep& g) {
    if (!g.forward) sweep<Ops, false, false, false>(g);
    else if (!g.fromZero) sweep<Ops, true, false, false>(g);
    else if (g.t) sweep<Ops, true, true, true>(g);
    else sweep<Ops, true, true, false>(g);
}

} // namespace gale::solver::kernels
