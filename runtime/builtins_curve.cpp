// spline (uniform Catmull-Rom) and the ramp widgets curve/ccurve. Curves follow SeExpr2's
// Curve.cpp number for number: phantom end points at +/-FLT_MAX, Catmull-Rom slopes, monotone
// clamping, float-rounded knots in linear/smooth segments. Computed in double for both kernels.
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <string>
#include <vector>

namespace gale::runtime {
namespace {

// ---- spline ----------------------------------------------------------------------------------

// spline(u, y1, ..., yn): uniform Catmull-Rom through y2..y(n-1); y1 and yn only shape the ends.
struct SplineK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        const int nsegs = f.nargs - 4;
        for (int k = 0; k < f.outWidth; ++k) {
            T* __restrict o = f.outComp(k);
            for (int i = 0; i < f.n; ++i) {
                T u = a[0].at(k, i);
                if (u != u) {
                    o[i] = u;
                    continue;
                }
                u = u < 0 ? T(0) : (u > 1 ? T(1) : u);
                if (u == 0) {
                    o[i] = a[2].at(k, i);
                    continue;
                }
                if (u == 1) {
                    o[i] = a[f.nargs - 2].at(k, i);
                    continue;
                }
                T seg;
                u = std::modf(u * T(nsegs), &seg);
                int s = static_cast<int>(seg);
                if (s >= nsegs) { // u * nsegs rounded up to nsegs
                    s = nsegs - 1;
                    u = 1;
                }
                const T p0 = a[s + 1].at(k, i), p1 = a[s + 2].at(k, i), p2 = a[s + 3].at(k, i), p3 = a[s + 4].at(k, i);
                const T u2 = u * u, u3 = u2 * u;
                o[i] = T(0.5) * (p0 * (-u3 + 2 * u2 - u) + p1 * (3 * u3 - 5 * u2 + 2) + p2 * (-3 * u3 + 4 * u2 + u) +
                                 p3 * (u3 - u2));
            }
        }
    }
};

// ---- curve, ccurve ---------------------------------------------------------------------------

enum InterpCode { kNone = 0, kLinear = 1, kSmooth = 2, kSpline = 3, kMonotone = 4 };

struct ControlPoint {
    double pos = 0;
    double val[3] = {0, 0, 0};
    double deriv[3] = {0, 0, 0};
    int interp = kNone;
};

// A piecewise cubic ramp of D-component values (D = 1 or 3), prepared as SeExpr2 prepares it.
template <int D>
class Ramp {
public:
    // Starts over with SeExpr2's two phantom points (their values are set in prepare()).
    void reset() {
        mPoints.clear();
        ControlPoint lo, hi;
        lo.pos = -FLT_MAX;
        hi.pos = FLT_MAX;
        mPoints.push_back(lo);
        mPoints.push_back(hi);
    }

    void add(double pos, const double* val, double interp) {
        ControlPoint p;
        p.pos = pos;
        for (int c = 0; c < D; ++c) p.val[c] = val[c];
        p.interp = detail::truncToInt(interp);
        mPoints.push_back(p);
    }

    // Sorts by position, gives the phantom ends the end values and zero slope, then computes
    // Catmull-Rom slopes and clamps them on monotone segments.
    void prepare() {
        std::sort(mPoints.begin(), mPoints.end(),
                  [](const ControlPoint& a, const ControlPoint& b) { return a.pos < b.pos; });
        ControlPoint& first = mPoints.front();
        ControlPoint& last = mPoints.back();
        const size_t size = mPoints.size();
        if (size > 2) {
            copyVal(first, mPoints[1]);
            copyVal(last, mPoints[size - 2]);
        } else {
            first.pos = last.pos = 0;
        }
        first.interp = last.interp = kNone;
        for (int c = 0; c < 3; ++c) first.deriv[c] = last.deriv[c] = 0;

        for (size_t i = 1; i + 1 < size; ++i) {
            const ControlPoint& prev = mPoints[i - 1];
            const ControlPoint& next = mPoints[i + 1];
            divide(mPoints[i].deriv, next.val, prev.val, next.pos - prev.pos);
        }
        for (size_t i = 0; i + 1 < size; ++i) {
            if (mPoints[i].interp != kMonotone) continue;
            ControlPoint& p = mPoints[i];
            ControlPoint& q = mPoints[i + 1];
            const double h = q.pos - p.pos;
            if (h == 0) {
                for (int c = 0; c < D; ++c) p.deriv[c] = q.deriv[c] = 0;
                continue;
            }
            double delta[3];
            divide(delta, q.val, p.val, h);
            for (int c = 0; c < D; ++c) {
                if (delta[c] == 0) {
                    p.deriv[c] = q.deriv[c] = 0;
                } else {
                    p.deriv[c] = clampSlope(p.deriv[c] / delta[c]) * delta[c];
                    q.deriv[c] = clampSlope(q.deriv[c] / delta[c]) * delta[c];
                }
            }
        }
    }

    // The value at `param`: the segment's LEFT point chooses the interpolation; outside the
    // points the phantom segments hold the end values.
    void eval(double param, double* out) const {
        const int count = static_cast<int>(mPoints.size());
        const ControlPoint* begin = mPoints.data();
        int index = static_cast<int>(std::upper_bound(begin, begin + count, param,
                                                      [](double x, const ControlPoint& p) { return x < p.pos; }) -
                                     begin);
        index = std::max(1, std::min(index, count - 1));
        const ControlPoint& p = mPoints[static_cast<size_t>(index - 1)];
        const ControlPoint& q = mPoints[static_cast<size_t>(index)];
        // SeExpr2 rounds the knots to float in linear and smooth segments (so t1 - t0 is a
        // float subtraction).
        const float t0 = static_cast<float>(p.pos), t1 = static_cast<float>(q.pos);
        const float span = t1 - t0;
        switch (p.interp) {
        case kNone:
            for (int c = 0; c < D; ++c) out[c] = p.val[c];
            return;
        case kLinear: {
            const double u = (param - t0) / span;
            for (int c = 0; c < D; ++c) out[c] = p.val[c] + u * (q.val[c] - p.val[c]);
            return;
        }
        case kSmooth: {
            const double u = (param - t0) / span;
            for (int c = 0; c < D; ++c)
                out[c] = p.val[c] * (u - 1) * (u - 1) * (2 * u + 1) + q.val[c] * u * u * (3 - 2 * u);
            return;
        }
        case kSpline:
        case kMonotone: {
            // Cubic Hermite with the prepared slopes, in SeExpr2's factored form.
            const double x = param - p.pos, h = q.pos - p.pos;
            const double h3 = h * h * h;
            for (int c = 0; c < D; ++c) {
                const double delta = q.val[c] - p.val[c];
                const double d1 = p.deriv[c], d2 = q.deriv[c];
                const double num = x * (delta * (3 * h - 2 * x) * x + h * (-h + x) * (-(d1 * h) + (d1 + d2) * x));
                out[c] = (D == 1 ? num / h3 : num * (1 / h3)) + p.val[c];
            }
            return;
        }
        default: // an interpolation code outside 0..4 (only possible when not constant)
            for (int c = 0; c < D; ++c) out[c] = 0;
            return;
        }
    }

private:
    static void copyVal(ControlPoint& dst, const ControlPoint& src) {
        for (int c = 0; c < 3; ++c) dst.val[c] = src.val[c];
    }
    // out = (a - b) / d; SeExpr2's vector type divides by multiplying with the reciprocal.
    static void divide(double* out, const double* a, const double* b, double d) {
        if (D == 1) {
            out[0] = (a[0] - b[0]) / d;
        } else {
            const double r = 1 / d;
            for (int c = 0; c < D; ++c) out[c] = (a[c] - b[c]) * r;
        }
    }
    static double clampSlope(double s) { return s < 0 ? 0.0 : (s > 3 ? 3.0 : s); }

    std::vector<ControlPoint> mPoints;
};

// curve(param, pos0, val0, interp0, ...) (D = 1) and ccurve (D = 3). The points are sorted once
// per call when they are constant or uniform, else once per lane.
template <int D>
struct CurveK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const Operand<T>* a = f.args;
        const int npoints = (f.nargs - 1) / 3;
        bool uniformPoints = true;
        for (int j = 1; j < f.nargs; ++j) uniformPoints = uniformPoints && a[j].uniform();
        Ramp<D> ramp;
        auto build = [&](int lane) {
            ramp.reset();
            for (int p = 0; p < npoints; ++p) {
                const Operand<T>& val = a[2 + 3 * p];
                double v[3];
                for (int c = 0; c < D; ++c) v[c] = double(val.at(c, lane));
                ramp.add(double(a[1 + 3 * p].at(0, lane)), v, double(a[3 + 3 * p].at(0, lane)));
            }
            ramp.prepare();
        };
        if (uniformPoints) build(0);
        for (int i = 0; i < f.n; ++i) {
            if (!uniformPoints) build(i);
            double out[D];
            ramp.eval(double(a[0].at(0, i)), out);
            for (int c = 0; c < D; ++c) f.outComp(c)[i] = T(out[c]);
        }
    }
};

// (n - 1) % 3 == 0, value widths, and constant interpolation codes in 0..4. As in SeExpr2, a
// vector position or interpolation code gives its first component (curve's FP[1] parameters are
// reduced by the compiler already, ccurve's reach here as ANY).
bool validateCurveArgs(lang::CallSite& site, int valueWidth) {
    const size_t nargs = site.argTypes.size();
    const std::string name(site.name);
    if ((nargs - 1) % 3 != 0) {
        site.sink->error(site.span, name + " takes the parameter then triples (position, value, interpolation); got " +
                                        std::to_string(nargs - 1) + " arguments after the parameter");
        return false;
    }
    bool ok = true;
    for (size_t j = 1; j < nargs; ++j) {
        const lang::Type& t = site.argTypes[j];
        if (t.isError()) {
            ok = false;
            continue;
        }
        const bool isValue = (j - 1) % 3 == 1;
        const int allowed = isValue ? valueWidth : 1;
        if (!t.isFloat() || (isValue && t.width != 1 && t.width != allowed)) {
            const char* what = isValue ? "value" : ((j - 1) % 3 == 0 ? "position" : "interpolation code");
            site.sink->error(
                site.argSpans[j],
                name + ": a control point's " + what + " must be " +
                    (!isValue ? "a number" : (allowed == 1 ? "FP[1]" : "FP[1] or FP[3]")) +
                    ", got " + lang::typeName(t));
            ok = false;
            continue;
        }
        if ((j - 1) % 3 == 2 && j < site.constValues.size() && !site.constValues[j].empty()) {
            const double code = site.constValues[j][0];
            const int c = detail::truncToInt(code);
            if (c < 0 || c > 4) {
                site.sink->error(site.argSpans[j], name + ": interpolation code must be 0 (none), 1 (linear), 2 (smooth), "
                                                          "3 (spline) or 4 (monotone)");
                ok = false;
            }
        }
    }
    return ok;
}

bool validateCurve(lang::CallSite& site) { return validateCurveArgs(site, 1); }
bool validateCcurve(lang::CallSite& site) { return validateCurveArgs(site, 3); }

} // namespace

void addCurveBuiltins(FunctionTable& t) {
    t.add(kernelBuiltin<SplineK>("spline", "FP[n] spline(FP[n] u, FP[n] y1, FP[n] y2, FP[n] y3, FP[n] y4, FP[n] more...)",
                                 "uniform Catmull-Rom through y2..y(n-1) for u in [0, 1]; y1, yn shape the ends"));
    Builtin curve =
        kernelBuiltin<CurveK<1>>("curve", "FP[1] curve(FP[1] param, FP[1] posValInterp...)",
                                 "ramp through control points (pos, val, interp); interp 0 none, 1 "
                                 "linear, 2 smooth, 3 spline, 4 monotone; "
                                 "a vector argument gives its first component (SeExpr2)");
    curve.info.validate = &validateCurve;
    curve.info.firstComponent = true;
    t.add(curve);
    Builtin ccurve =
        kernelBuiltin<CurveK<3>>("ccurve", "FP[3] ccurve(FP[1] param, ANY posValInterp...)",
                                 "curve() with FP[3] values (a scalar value is broadcast): triples "
                                 "(pos, FP[3] val, interp); a vector param, "
                                 "pos or interp gives its first component (SeExpr2)");
    ccurve.info.validate = &validateCcurve;
    ccurve.info.firstComponent = true;
    t.add(ccurve);
}

} // namespace gale::runtime
