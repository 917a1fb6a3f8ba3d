// The velocity-field interface every consumer uses (the solver, `gale sample`, `gale viz`):
// sample a batch of points at a time, thread-safe, with a status instead of exceptions.
#pragma once

#include "fields/keyframes.h"

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gale::fields {

using Vec3 = std::array<double, 3>;

// When (and how) a batch is sampled.
struct SampleTime {
    double time = 0.0;  // seconds ($t)
    double fps = 24.0;  // frames per second ($fps); $frame = time * fps + frameZero
    double frameZero = 0.0; // the frame at time 0 (scene.time_zero)
    int substep = 0;    // substep index within the frame (informational)
    int threads = 1;    // threads the field may use for this batch (0: all)
};

struct SampleStatus {
    bool ok = true;
    size_t nonFinite = 0;  // points whose velocity came out NaN/inf (set to zero in the output)
    std::string message;   // why not ok, or what was repaired
};

// A velocity field v(x, t) in m/s. `sample` must be safe to call from several threads at once.
class Field {
public:
    virtual ~Field() = default;
    // positions[3*i+k] -> velocities[3*i+k], for i < count. Non-finite results are replaced by
    // zero and counted in the status (never passed on silently).
    virtual SampleStatus sample(const double* positions, size_t count, const SampleTime& when,
                                double* velocities) const = 0;
    virtual std::string describe() const = 0;
};

using FieldPtr = std::shared_ptr<const Field>;

// v(x, t) given by a C++ function: analytic fields for tests and the solver's unit tests.
class FunctionField : public Field {
public:
    using Fn = std::function<Vec3(const Vec3& x, double t)>;
    FunctionField(Fn fn, std::string description) : mFn(std::move(fn)), mDescription(std::move(description)) {}
    SampleStatus sample(const double* positions, size_t count, const SampleTime& when,
                        double* velocities) const override;
    std::string describe() const override { return mDescription; }

private:
    Fn mFn;
    std::string mDescription;
};

// A constant wind.
FieldPtr uniformField(const Vec3& velocity);

// Fields of a scene are summed ([[field]] entries); each may be scaled.
class SumField : public Field {
public:
    struct Term {
        FieldPtr field;
        double scale = 1.0;
    };
    explicit SumField(std::vector<Term> terms) : mTerms(std::move(terms)) {}
    SampleStatus sample(const double* positions, size_t count, const SampleTime& when,
                        double* velocities) const override;
    std::string describe() const override;

private:
    std::vector<Term> mTerms;
};

// A field times a (possibly keyframed) scalar: `scale` of a [[field]] that is animated.
class ScaledField : public Field {
public:
    ScaledField(FieldPtr field, Param scale) : mField(std::move(field)), mScale(std::move(scale)) {}
    SampleStatus sample(const double* positions, size_t count, const SampleTime& when,
                        double* velocities) const override;
    std::string describe() const override;

private:
    FieldPtr mField;
    Param mScale;
};

// A field multiplied component by component by a mask field (a scalar mask is a field whose
// three components are equal: an expression giving FP[1] promoted to FP[3]).
class MaskedField : public Field {
public:
    MaskedField(FieldPtr field, FieldPtr mask) : mField(std::move(field)), mMask(std::move(mask)) {}
    SampleStatus sample(const double* positions, size_t count, const SampleTime& when,
                        double* velocities) const override;
    std::string describe() const override;

private:
    FieldPtr mField;
    FieldPtr mMask;
};

// Replaces non-finite components by zero; returns how many points had one.
size_t zeroNonFinite(double* velocities, size_t count);

} // namespace gale::fields
