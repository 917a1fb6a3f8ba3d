// The velocity-field combinators: analytic fields, constant wind, sums, animated scales and
// masks. Each samples its children into scratch buffers and never shares mutable state.
#include "fields/field.h"

#include <cmath>
#include <sstream>

namespace gale::fields {

size_t zeroNonFinite(double* velocities, size_t count) {
    size_t bad = 0;
    for (size_t i = 0; i < count; ++i) {
        double* v = velocities + 3 * i;
        if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) continue;
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(v[k])) v[k] = 0.0;
        ++bad;
    }
    return bad;
}

namespace {

std::string nonFiniteMessage(size_t bad, const std::string& what) {
    return std::to_string(bad) + " point(s) of " + what +
           " gave a non-finite velocity (set to zero)";
}

// Merges a child's status into the parent's: the first failure wins the message.
void merge(SampleStatus& into, const SampleStatus& child) {
    if (!child.ok && into.ok) {
        into.ok = false;
        into.message = child.message;
    } else if (into.ok && into.message.empty()) {
        into.message = child.message;
    }
    into.nonFinite += child.nonFinite;
}

} // namespace

SampleStatus FunctionField::sample(const double* positions, size_t count, const SampleTime& when,
                                   double* velocities) const {
    for (size_t i = 0; i < count; ++i) {
        const Vec3 x{positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
        const Vec3 v = mFn(x, when.time);
        for (int k = 0; k < 3; ++k) velocities[3 * i + static_cast<size_t>(k)] = v[static_cast<size_t>(k)];
    }
    SampleStatus status;
    status.nonFinite = zeroNonFinite(velocities, count);
    if (status.nonFinite) status.message = nonFiniteMessage(status.nonFinite, mDescription);
    return status;
}

FieldPtr uniformField(const Vec3& velocity) {
    std::ostringstream d;
    d << "uniform (" << velocity[0] << ", " << velocity[1] << ", " << velocity[2] << ") m/s";
    return std::make_shared<FunctionField>([velocity](const Vec3&, double) { return velocity; },
                                           d.str());
}

SampleStatus SumField::sample(const double* positions, size_t count, const SampleTime& when,
                              double* velocities) const {
    SampleStatus status;
    for (size_t i = 0; i < 3 * count; ++i) velocities[i] = 0.0;
    if (mTerms.empty() || count == 0) return status;
    std::vector<double> scratch(3 * count);
    for (const Term& term : mTerms) {
        merge(status, term.field->sample(positions, count, when, scratch.data()));
        for (size_t i = 0; i < 3 * count; ++i) velocities[i] += term.scale * scratch[i];
    }
    // Children repaired their own non-finite values; a huge scale can still overflow.
    const size_t bad = zeroNonFinite(velocities, count);
    if (bad) {
        status.nonFinite += bad;
        if (status.message.empty()) status.message = nonFiniteMessage(bad, "the sum");
    }
    return status;
}

std::string SumField::describe() const {
    std::string out = "sum of " + std::to_string(mTerms.size()) + " field(s)";
    for (const Term& t : mTerms) {
        out += "\n  ";
        if (t.scale != 1.0) {
            std::ostringstream s;
            s << t.scale << " x ";
            out += s.str();
        }
        out += t.field->describe();
    }
    return out;
}

SampleStatus ScaledField::sample(const double* positions, size_t count, const SampleTime& when,
                                 double* velocities) const {
    SampleStatus status = mField->sample(positions, count, when, velocities);
    const double s = mScale.scalarAt(when.time);
    for (size_t i = 0; i < 3 * count; ++i) velocities[i] *= s;
    const size_t bad = zeroNonFinite(velocities, count);
    if (bad) {
        status.nonFinite += bad;
        if (status.message.empty()) status.message = nonFiniteMessage(bad, "a scaled field");
    }
    return status;
}

std::string ScaledField::describe() const {
    return (mScale.isKeyed() ? std::string("keyframed scale x ") : "scaled x ") +
           mField->describe();
}

SampleStatus MaskedField::sample(const double* positions, size_t count, const SampleTime& when,
                                 double* velocities) const {
    SampleStatus status = mField->sample(positions, count, when, velocities);
    std::vector<double> mask(3 * count);
    merge(status, mMask->sample(positions, count, when, mask.data()));
    for (size_t i = 0; i < 3 * count; ++i) velocities[i] *= mask[i];
    return status;
}

std::string MaskedField::describe() const {
    return mField->describe() + " masked by " + mMask->describe();
}

} // namespace gale::fields
