// Selection built-ins: cycle, pick, choose (also as swatch), wchoose — SeExpr2's integer
// conversions, weight tables and binary searches, so the same index picks the same value. Also
// SeExpr2's hash.
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace gale::runtime {

namespace detail {

double seHash(const double* seeds, int n) {
    // The byte permutation of SeExpr2's hash.
    static const uint8_t kPerm[256] = {
        148, 201, 203,  34,  85, 225, 163, 200, 174, 137,  51,  24,  19, 252, 107, 173,
        110, 251, 149,  69, 180, 152, 141, 132,  22,  20, 147, 219,  37,  46, 154, 114,
         59,  49, 155, 161, 239,  77,  47,  10,  70, 227,  53, 235,  30, 188, 143,  73,
         88, 193, 214, 194,  18, 120, 176,  36, 212,  84, 211, 142, 167,  57, 153,  71,
        159, 151, 126, 115, 229, 124, 172, 101,  79, 183,  32,  38,  68,  11,  67, 109,
        221,   3,   4,  61, 122,  94,  72, 117,  12, 240, 199,  76, 118,   5,  48, 197,
        128,  62, 119,  89,  14,  45, 226, 195,  80,  50,  40, 192,  60,  65, 166, 106,
         90, 215, 213, 232, 250, 207, 104,  52, 182,  29, 157, 103, 242,  97, 111,  17,
          8, 175, 254, 108, 208, 224, 191, 112, 105, 187,  43,  56, 185, 243, 196, 156,
        246, 249, 184,   7, 135,   6, 158,  82, 130, 234, 206, 255, 160, 236, 171, 230,
         42,  98,  54,  74, 209, 205,  33, 177,  15, 138, 178,  44, 116,  96, 140, 253,
        233, 125,  21, 133, 136,  86, 245,  58,  23,   1,  75, 165,  92, 217,  39,   0,
        218,  91, 179,  55, 238, 170, 134,  83,  25, 189, 216, 100, 129, 150, 241, 210,
        123,  99,   2, 164,  16, 220, 121, 139, 168,  64, 190,   9,  31, 228,  95, 247,
        244,  81, 102, 145, 204, 146,  26,  87, 113, 198, 181, 127, 237, 169,  28,  93,
         27,  41, 231, 248,  78, 162,  13, 186,  63,  66, 131, 202,  35, 144, 222, 223,
    };
    constexpr double kEPi = 2.71828182845904523536 * 3.14159265358979323846;
    constexpr double kU32Max = 4294967295.0;
    uint32_t seed = 0;
    for (int i = 0; i < n; ++i) {
        // An irrational multiple's mantissa and exponent, folded into 32 bits (LCG step).
        int e = 0;
        const double frac = std::frexp(seeds[i] * kEPi, &e);
        const uint32_t s = truncToU32(frac * kU32Max) ^ static_cast<uint32_t>(e);
        seed = seed * 1664525u + s + 1013904223u;
    }
    // Mersenne twister tempering.
    seed ^= seed >> 11;
    seed ^= (seed << 7) & 0x9d2c5680u;
    seed ^= (seed << 15) & 0xefc60000u;
    seed ^= seed >> 18;
    // Byte permutation, chained from the low byte of the seed to the high byte of the result.
    const uint32_t b0 = seed & 0xffu, b1 = (seed >> 8) & 0xffu, b2 = (seed >> 16) & 0xffu, b3 = seed >> 24;
    const uint32_t r3 = kPerm[b0];
    const uint32_t r2 = kPerm[(b1 + r3) & 0xffu];
    const uint32_t r1 = kPerm[(b2 + r2) & 0xffu];
    const uint32_t r0 = kPerm[(b3 + r1) & 0xffu];
    const uint32_t r = (r3 << 24) | (r2 << 16) | (r1 << 8) | r0;
    return r * (1.0 / kU32Max);
}

} // namespace detail

namespace {

using detail::truncToInt;

// lo + (int(index) mod (hi - lo + 1)), wrapping negative indices; lo when hi < lo.
template <class T> struct Cycle {
    static T apply(T index, T loRange, T hiRange) {
        const int64_t lo = truncToInt(double(loRange)), hi = truncToInt(double(hiRange));
        const int64_t range = hi - lo + 1;
        if (range <= 0) return T(lo);
        int64_t r = int64_t(truncToInt(double(index))) % range;
        if (r < 0) r += range;
        return T(lo + r);
    }
};

// Cumulative weights of SeExpr2's pick/wchoose tables, searched the way SeExpr2 searches them.
// pick: the first `given` weights come from the call, the rest of `count` are 1.
class WeightTable {
public:
    void reset(int64_t count, int given) {
        mCount = count;
        mGiven = given;
        mPrefix.resize(static_cast<size_t>(given));
        mWeights.resize(static_cast<size_t>(given));
    }
    void setGiven(int j, double w) { mWeights[static_cast<size_t>(j)] = w; }
    // Call after the given weights are set: running sums as SeExpr2 accumulates them.
    void accumulate() {
        double total = 0;
        for (int j = 0; j < mGiven; ++j) {
            total += mWeights[static_cast<size_t>(j)];
            mPrefix[static_cast<size_t>(j)] = total;
        }
        mBase = total;
        mBaseExact = std::floor(total) == total && std::fabs(total) < 4503599627370496.0;
    }
    double weight(int64_t j) const { return j < mGiven ? mWeights[static_cast<size_t>(j)] : 1.0; }
    double cutoff(int64_t j) const {
        if (j < mGiven) return mPrefix[static_cast<size_t>(j)];
        const int64_t ones = j - mGiven + 1;
        // SeExpr2 adds the 1s one at a time; that is exact for an integral base, and for long
        // tails the one-step sum differs from it by a few ulps at most.
        if (mBaseExact || ones > 4096) return mBase + double(ones);
        double s = mBase;
        for (int64_t c = 0; c < ones; ++c) s += 1.0;
        return s;
    }
    double total() const { return cutoff(mCount - 1); }
    // Index of the interval holding `key` (in [0, total]), skipping zero-weight intervals.
    int64_t find(double key) const {
        int64_t lo = 0, hi = mCount - 1;
        while (lo < hi) {
            const int64_t m = (lo + hi) / 2;
            if (key <= cutoff(m)) hi = m;
            else lo = m + 1;
        }
        if (weight(lo) == 0) {
            if (lo > 0 && cutoff(lo) > 0) {
                while (--lo > 0 && weight(lo) == 0) {}
            } else if (lo < mCount - 1) {
                while (++lo < mCount - 1 && weight(lo) == 0) {}
            }
        }
        return lo;
    }

private:
    std::vector<double> mPrefix, mWeights;
    int64_t mCount = 0;
    int mGiven = 0;
    double mBase = 0;
    bool mBaseExact = true;
};

// pick(index, lo, hi, weights...): an integer in [lo, hi] chosen by hash(index), distributed by
// the weights (missing weights are 1).
struct PickK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        const int nWeights = f.nargs - 3;
        WeightTable table;
        for (int k = 0; k < f.outWidth; ++k) {
            T* __restrict o = f.outComp(k);
            for (int i = 0; i < f.n; ++i) {
                const double index = double(a[0].at(k, i));
                const int loRange = truncToInt(double(a[1].at(k, i)));
                const int hiRange = truncToInt(double(a[2].at(k, i)));
                const int64_t range = int64_t(hiRange) - loRange + 1;
                if (range <= 0) {
                    o[i] = T(loRange);
                    continue;
                }
                const int given = range < nWeights ? static_cast<int>(range) : nWeights;
                table.reset(range, given);
                for (int j = 0; j < given; ++j) table.setGiven(j, double(a[3 + j].at(k, i)));
                table.accumulate();
                const double total = table.total();
                if (total == 0) {
                    o[i] = T(loRange);
                    continue;
                }
                const double key = detail::seHash(&index, 1) * total;
                o[i] = T(double(loRange) + double(table.find(key)));
            }
        }
    }
};

// choose(index, c1, c2, ...): c[int(index * count)] with index clamped to [0, 1).
struct ChooseK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        const int nvals = f.nargs - 1;
        for (int k = 0; k < f.outWidth; ++k) {
            T* __restrict o = f.outComp(k);
            for (int i = 0; i < f.n; ++i) {
                const double key = double(a[0].at(k, i));
                if (key != key) {
                    o[i] = 0;
                    continue;
                }
                double x = key * nvals;
                x = x < 0 ? 0 : (x > nvals - 1 ? nvals - 1 : x);
                o[i] = a[1 + truncToInt(x)].at(k, i);
            }
        }
    }
};

// wchoose(index, c1, w1, c2, w2, ...): like choose, with interval lengths given by weights.
// As in SeExpr2, a trailing value without weight is ignored and fewer than two pairs give 0.
struct WchooseK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        const int nvals = (f.nargs - 1) / 2;
        WeightTable table;
        table.reset(nvals, nvals);
        for (int k = 0; k < f.outWidth; ++k) {
            T* __restrict o = f.outComp(k);
            for (int i = 0; i < f.n; ++i) {
                const double key = double(a[0].at(k, i));
                if (f.nargs < 5 || key != key) {
                    o[i] = 0;
                    continue;
                }
                for (int j = 0; j < nvals; ++j) table.setGiven(j, double(a[2 + 2 * j].at(k, i)));
                table.accumulate();
                const double total = table.total();
                if (total == 0) {
                    o[i] = a[1].at(k, i);
                    continue;
                }
                o[i] = a[1 + 2 * table.find(key * total)].at(k, i);
            }
        }
    }
};

bool validateWchoose(lang::CallSite& site) {
    const size_t nargs = site.argTypes.size();
    if ((nargs - 1) % 2 != 0 && site.sink) {
        site.sink->warning(site.argSpans.back(), "wchoose takes value/weight pairs; this last value has no weight and is "
                                                 "never chosen");
    }
    return true;
}

} // namespace

namespace detail {

void addSelectionBuiltins(FunctionTable& t) {
    t.add(mapBuiltin3<Cycle>("cycle", "FP[n] cycle(FP[n] index, FP[n] lo, FP[n] hi)",
                             "cycles through the integers lo..hi: lo + (int(index) mod (hi - lo + 1))"));
    t.add(kernelBuiltin<PickK>("pick", "FP[n] pick(FP[n] index, FP[n] lo, FP[n] hi, FP[n] weights...)",
                               "an integer in [lo, hi] picked by hash(index), distributed by the weights (default 1)"));
    t.add(kernelBuiltin<ChooseK>("choose", "FP[n] choose(FP[n] index, FP[n] c1, FP[n] c2, FP[n] choices...)",
                                 "one of the choices by index in [0, 1]"));
    // SeExpr2 defines swatch as choose: per component, so FP[3] choices give a colour.
    t.add(kernelBuiltin<ChooseK>(
        "swatch", "FP[n] swatch(FP[n] index, FP[n] choice0, FP[n] choice1, FP[n] choices...)",
        "one of the colours (or values) by index in [0, 1]: choose() under its colour name"));
    Builtin wchoose = kernelBuiltin<WchooseK>(
        "wchoose", "FP[n] wchoose(FP[n] index, FP[n] c1, FP[n] w1, FP[n] c2, FP[n] weightedChoices...)",
        "one of the choices by index in [0, 1], each taking a share of [0, 1] proportional to its weight");
    wchoose.info.validate = &validateWchoose;
    t.add(wchoose);
}

} // namespace detail
} // namespace gale::runtime
