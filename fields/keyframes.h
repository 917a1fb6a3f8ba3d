// Keyframed parameters: a scene value that is a number, a vector, or a curve over time
// `{ keys = [[t0, v0], [t1, v1]], interp = "linear"|"smooth"|"step" }` (t in seconds).
#pragma once

#include <string>
#include <vector>

namespace gale::fields {

enum class KeyInterp { Linear, Smooth, Step };

class Param {
public:
    Param() = default;
    explicit Param(double v) : mConstant{v} {}
    explicit Param(std::vector<double> v) : mConstant(std::move(v)) {}

    // Keys must be sorted by time (the scene loader sorts and checks them); every value has
    // the same width.
    static Param keyed(std::vector<double> times, std::vector<std::vector<double>> values, KeyInterp interp);

    bool isKeyed() const { return !mTimes.empty(); }
    int width() const;
    // Value at time t: before the first key the first value, after the last the last value;
    // linear / smooth (Hermite with zero tangents, 3s^2-2s^3) / step (hold the left key).
    std::vector<double> at(double t) const;
    // The same without allocating: writes width() values to `out`.
    void evaluate(double t, double* out) const;
    double scalarAt(double t) const; // component 0 of at(t)
    // Step keys jump: the largest change between consecutive keys whose time is in (t0, t1]
    // (the Euclidean norm of the values' difference), and that key's time in *at; 0 for keys
    // of any other interpolation and for a constant.
    double stepJump(double t0, double t1, double* at = nullptr) const;

    const std::vector<double>& times() const { return mTimes; }
    const std::vector<std::vector<double>>& values() const { return mValues; }
    KeyInterp interp() const { return mInterp; }

private:
    std::vector<double> mConstant{0.0};
    std::vector<double> mTimes;
    std::vector<std::vector<double>> mValues;
    KeyInterp mInterp = KeyInterp::Linear;
};

} // namespace gale::fields
