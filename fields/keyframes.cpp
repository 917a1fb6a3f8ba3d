// Keyframed parameters: constant values or curves over time (linear, smooth, step), evaluated
// without allocating so that built-in kernels can call them per lane.
#include "fields/keyframes.h"

#include <cmath>

#include <algorithm>

namespace gale::fields {

Param Param::keyed(std::vector<double> times, std::vector<std::vector<double>> values,
                   KeyInterp interp) {
    Param p;
    if (times.empty() || values.size() != times.size()) return p;
    p.mConstant = values.front();
    p.mTimes = std::move(times);
    p.mValues = std::move(values);
    p.mInterp = interp;
    return p;
}

int Param::width() const {
    return static_cast<int>(isKeyed() ? mValues.front().size() : mConstant.size());
}

void Param::evaluate(double t, double* out) const {
    const size_t w = static_cast<size_t>(width());
    if (!isKeyed()) {
        std::copy(mConstant.begin(), mConstant.end(), out);
        return;
    }
    // Clamp outside the keys (NaN time: the first key).
    if (!(t > mTimes.front())) {
        std::copy(mValues.front().begin(), mValues.front().end(), out);
        return;
    }
    if (t >= mTimes.back()) {
        std::copy(mValues.back().begin(), mValues.back().end(), out);
        return;
    }
    // The segment [times[i], times[i+1]) holding t.
    const size_t i = static_cast<size_t>(
        std::upper_bound(mTimes.begin(), mTimes.end(), t) - mTimes.begin() - 1);
    const std::vector<double>& a = mValues[i];
    const std::vector<double>& b = mValues[i + 1];
    const double span = mTimes[i + 1] - mTimes[i];
    double s = span > 0.0 ? (t - mTimes[i]) / span : 1.0;
    switch (mInterp) {
    case KeyInterp::Step:
        s = 0.0;
        break;
    case KeyInterp::Smooth:
        s = s * s * (3.0 - 2.0 * s);
        break;
    case KeyInterp::Linear:
        break;
    }
    for (size_t k = 0; k < w; ++k) out[k] = a[k] + (b[k] - a[k]) * s;
}

std::vector<double> Param::at(double t) const {
    std::vector<double> out(static_cast<size_t>(width()));
    evaluate(t, out.data());
    return out;
}

double Param::stepJump(double t0, double t1, double* at) const {
    double worst = 0.0;
    if (mInterp != KeyInterp::Step) return worst;
    for (size_t k = 1; k < mTimes.size(); ++k) {
        if (!(mTimes[k] > t0 && mTimes[k] <= t1)) continue;
        double d2 = 0.0;
        for (size_t c = 0; c < mValues[k].size(); ++c) {
            const double d = mValues[k][c] - mValues[k - 1][c];
            d2 += d * d;
        }
        if (std::sqrt(d2) > worst) {
            worst = std::sqrt(d2);
            if (at) *at = mTimes[k];
        }
    }
    return worst;
}

double Param::scalarAt(double t) const {
    if (!isKeyed()) return mConstant.empty() ? 0.0 : mConstant[0];
    if (width() == 1) {
        double v = 0.0;
        evaluate(t, &v);
        return v;
    }
    return at(t)[0];
}

} // namespace gale::fields
