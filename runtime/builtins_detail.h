// Helpers shared by the built-in sources (builtins_*.cpp) and their tests: the registration
// functions of the split-out families and the exact integer/hash conventions of SeExpr2.
// Not part of the runtime's public interface.
#pragma once

#include "runtime/builtins.h"

#include <cstdint>

namespace gale::runtime::detail {

// Registered by addMathBuiltins (builtins_vector.cpp, builtins_select.cpp, builtins_color.cpp).
void addVectorBuiltins(FunctionTable& t);
void addSelectionBuiltins(FunctionTable& t);
void addColorBuiltins(FunctionTable& t);

// SeExpr2's remap(x, source, range, falloff, interp) in double (builtins_math.cpp); midhsi
// shapes its map with it.
double remapValue(double x, double source, double range, double falloff, double interp);

// C's float-to-int truncation as SeExpr2 performs it on x86-64 (`int(x)`), without undefined
// behaviour: NaN and values outside int's range give INT_MIN, like cvttsd2si.
inline int truncToInt(double v) {
    if (!(v > -2147483649.0 && v < 2147483648.0)) return INT32_MIN;
    return static_cast<int>(v);
}

// SeExpr2's `(uint32_t)double` on x86-64: truncation through a 64-bit integer, so negative
// values wrap modulo 2^32 (NaN and huge values give 0, the low bits of INT64_MIN).
inline uint32_t truncToU32(double v) {
    if (!(v > -9223372036854775808.0 && v < 9223372036854775808.0)) return 0u;
    return static_cast<uint32_t>(static_cast<uint64_t>(static_cast<int64_t>(v)));
}

// SeExpr2's hash(seed1, seed2, ...) in [0, 1]: a linear congruential mix of the seeds, Mersenne
// twister tempering and a byte permutation. pick() hashes its index with it.
double seHash(const double* seeds, int n);

} // namespace gale::runtime::detail
