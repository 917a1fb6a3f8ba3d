// Accuracy of the vectorised float sin/cos/exp/log against double-precision libm, in ulps of
// the float result, over dense sweeps and the special values.
#include "runtime/fastmath.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace gale::runtime;

namespace {

// Distance in float ulps between a float result and the exact (double) value.
double ulpError(float got, double exact) {
    if (std::isnan(exact)) return std::isnan(got) ? 0.0 : 1e9;
    if (std::isinf(exact)) return got == static_cast<float>(exact) ? 0.0 : 1e9;
    const float rounded = static_cast<float>(exact);
    if (std::isinf(rounded)) return std::isinf(got) ? 0.0 : 1e9;
    const double ulp = std::nextafter(std::fabs(rounded), HUGE_VALF) - std::fabs(rounded);
    const double minUlp = std::numeric_limits<float>::denorm_min();
    return std::fabs(static_cast<double>(got) - exact) / std::max(ulp, minUlp);
}

template <class ArrayFn, class Exact>
double maxUlp(ArrayFn fn, Exact exact, const std::vector<float>& xs, double absFloor = 0.0) {
    std::vector<float> out(xs.size());
    fn(xs.data(), out.data(), static_cast<int>(xs.size()));
    double worst = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
        const double e = exact(static_cast<double>(xs[i]));
        // Near a zero of sin/cos the relative ulp is meaningless: measure against an absolute
        // floor of one ulp of 1 (what range reduction in float can give).
        if (absFloor > 0 && std::fabs(e) < absFloor) {
            const double err = std::fabs(static_cast<double>(out[i]) - e) / (absFloor * 0x1p-23);
            worst = std::max(worst, err);
            continue;
        }
        worst = std::max(worst, ulpError(out[i], e));
    }
    return worst;
}

std::vector<float> sweep(float lo, float hi, size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<float> xs(n);
    for (float& x : xs) x = lo + (hi - lo) * static_cast<float>(static_cast<double>(rng() >> 11) * 0x1.0p-53);
    return xs;
}

} // namespace

TEST_CASE("fast sin and cos are within 2 ulp over the range animators use", "[fastmath]") {
    const auto xs = sweep(-200.0f, 200.0f, 400000, 1);
    const double sinErr = maxUlp(fastmath::sinArray, [](double x) { return std::sin(x); }, xs, 1.0);
    const double cosErr = maxUlp(fastmath::cosArray, [](double x) { return std::cos(x); }, xs, 1.0);
    INFO("sin " << sinErr << " ulp, cos " << cosErr << " ulp");
    CHECK(sinErr <= 2.0);
    CHECK(cosErr <= 2.0);
    // Small arguments: relative accuracy (sin x ~ x).
    const auto small = sweep(-1e-3f, 1e-3f, 100000, 2);
    CHECK(maxUlp(fastmath::sinArray, [](double x) { return std::sin(x); }, small) <= 2.0);
    // Beyond the reduction's range and special values: libm's answer.
    std::vector<float> big{1e5f, -3e7f, 1e30f, HUGE_VALF, -HUGE_VALF, std::nanf(""), 0.0f, -0.0f};
    std::vector<float> out(big.size());
    fastmath::sinArray(big.data(), out.data(), static_cast<int>(big.size()));
    for (size_t i = 0; i < big.size(); ++i) {
        const float want = std::sin(big[i]);
        if (std::isnan(want)) CHECK(std::isnan(out[i]));
        else CHECK(out[i] == want);
    }
    CHECK(std::signbit(out[7])); // sin(-0) = -0
}

TEST_CASE("fast exp is within 2 ulp, including subnormal results and overflow", "[fastmath]") {
    CHECK(maxUlp(fastmath::expArray, [](double x) { return std::exp(x); }, sweep(-87.0f, 88.0f, 400000, 3)) <= 2.0);
    CHECK(maxUlp(fastmath::expArray, [](double x) { return std::exp(x); }, sweep(-103.0f, -87.5f, 50000, 4)) <= 2.0);
    std::vector<float> xs{0.0f, 1.0f, 89.0f, 1000.0f, -104.0f, -1000.0f, HUGE_VALF, -HUGE_VALF, std::nanf("")};
    std::vector<float> out(xs.size());
    fastmath::expArray(xs.data(), out.data(), static_cast<int>(xs.size()));
    CHECK(out[0] == 1.0f);
    CHECK(out[1] == Approx(2.718281828).epsilon(2e-7));
    CHECK(std::isinf(out[2]));
    CHECK(std::isinf(out[3]));
    CHECK(out[4] == 0.0f);
    CHECK(out[5] == 0.0f);
    CHECK(std::isinf(out[6]));
    CHECK(out[7] == 0.0f);
    CHECK(std::isnan(out[8]));
}

TEST_CASE("fast log is within 2 ulp, including subnormal inputs and special values", "[fastmath]") {
    CHECK(maxUlp(fastmath::logArray, [](double x) { return std::log(x); }, sweep(1e-6f, 1e6f, 400000, 5)) <= 2.0);
    CHECK(maxUlp(fastmath::logArray, [](double x) { return std::log(x); }, sweep(0.5f, 2.0f, 400000, 6)) <= 2.0);
    std::vector<float> tiny(1000);
    for (size_t i = 0; i < tiny.size(); ++i) tiny[i] = std::numeric_limits<float>::denorm_min() * static_cast<float>(i * 7919 + 1);
    CHECK(maxUlp(fastmath::logArray, [](double x) { return std::log(x); }, tiny) <= 2.0);
    std::vector<float> xs{0.0f, -0.0f, -1.0f, HUGE_VALF, std::nanf(""), 1.0f};
    std::vector<float> out(xs.size());
    fastmath::logArray(xs.data(), out.data(), static_cast<int>(xs.size()));
    CHECK((std::isinf(out[0]) && out[0] < 0));
    CHECK((std::isinf(out[1]) && out[1] < 0));
    CHECK(std::isnan(out[2]));
    CHECK((std::isinf(out[3]) && out[3] > 0));
    CHECK(std::isnan(out[4]));
    CHECK(out[5] == 0.0f);
}
