// Test harness for built-in kernels: builds operands by hand (uniform with lane stride 0,
// varying with lane stride 1 and padded component strides), runs a kernel through a
// KernelFrame and reads the results back. Used by the builtins_*_test.cpp files only.
#pragma once

#include "runtime/builtins.h"

#include <catch2/catch.hpp>

#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace gale::runtime::testing {

inline const Builtin& builtin(std::string_view name) {
    const auto& table = FunctionTable::standard();
    int32_t index = -1;
    REQUIRE(table->findFunction(name, &index) != nullptr);
    return table->at(index);
}

template <class T>
Kernel<T> kernelOf(const Builtin& b) {
    if constexpr (std::is_same_v<T, float>) return b.kernelF;
    else return b.kernelD;
}

// Relative and absolute tolerance fitting the precision.
template <class T>
Approx near(double v) {
    const double eps = std::is_same_v<T, float> ? 2e-6 : 1e-13;
    return Approx(v).epsilon(eps).margin(eps);
}

template <class T>
class KernelCall {
public:
    KernelCall(int lanes, int outWidth) : mLanes(lanes), mOutWidth(outWidth) {}

    // A constant/uniform operand: one value per component, lane stride 0.
    KernelCall& uniform(std::vector<double> comps) {
        Arg a;
        a.width = static_cast<int>(comps.size());
        a.compStride = 1;
        for (double c : comps) a.data.push_back(T(c));
        mArgs.push_back(std::move(a));
        return *this;
    }
    // A varying operand: value(lane, component), lane stride 1, components `lanes + 3` apart.
    KernelCall& varying(int width, const std::function<double(int, int)>& value) {
        Arg a;
        a.width = width;
        a.laneStride = 1;
        a.compStride = mLanes + 3;
        a.data.assign(static_cast<size_t>(width * a.compStride), T(-999));
        for (int k = 0; k < width; ++k)
            for (int i = 0; i < mLanes; ++i) a.data[static_cast<size_t>(k * a.compStride + i)] = T(value(i, k));
        mArgs.push_back(std::move(a));
        return *this;
    }
    KernelCall& string(std::string s) {
        Arg a;
        a.isString = true;
        a.strings.push_back(std::move(s));
        mArgs.push_back(std::move(a));
        return *this;
    }
    // Side-effecting calls: lane i runs iff active[i].
    KernelCall& mask(std::vector<bool> active) {
        mMask.clear();
        for (bool b : active) mMask.push_back(b ? T(1) : T(0));
        return *this;
    }

    KernelCall& run(Kernel<T> kernel) {
        REQUIRE(kernel != nullptr);
        std::vector<Operand<T>> ops;
        for (const Arg& a : mArgs) {
            Operand<T> o;
            if (a.isString) {
                o.str = a.strings.data();
            } else {
                o.data = a.data.data();
                o.width = a.width;
                o.laneStride = a.laneStride;
                o.compStride = a.compStride;
            }
            ops.push_back(o);
        }
        mOutCompStride = mLanes + 5;
        mOut.assign(static_cast<size_t>(mOutWidth * mOutCompStride), T(-12345));
        mOutStr.assign(static_cast<size_t>(mLanes), std::string("<unset>"));
        KernelFrame<T> f;
        f.n = mLanes;
        f.out = mOut.data();
        f.outWidth = mOutWidth;
        f.outCompStride = mOutCompStride;
        f.outStr = mOutStr.data();
        f.args = ops.data();
        f.nargs = static_cast<int>(ops.size());
        if (!mMask.empty()) {
            f.mask = mMask.data();
            f.maskStride = 1;
        }
        f.messages = &mMessages;
        kernel(f);
        return *this;
    }
    KernelCall& run(std::string_view name) { return run(kernelOf<T>(builtin(name))); }

    T out(int lane, int comp = 0) const { return mOut[static_cast<size_t>(comp * mOutCompStride + lane)]; }
    const std::string& str(int lane) const { return mOutStr[static_cast<size_t>(lane)]; }
    const std::string& messages() const { return mMessages; }

private:
    struct Arg {
        std::vector<T> data;
        std::vector<std::string> strings;
        bool isString = false;
        int width = 1;
        int laneStride = 0;
        int compStride = 0;
    };
    int mLanes;
    int mOutWidth;
    int mOutCompStride = 0;
    std::vector<Arg> mArgs;
    std::vector<T> mOut, mMask;
    std::vector<std::string> mOutStr;
    std::string mMessages;
};

// Checks a scalar built-in on rows {arg0, ..., argN-1, expected}: each row as a uniform call,
// all rows as the lanes of one all-varying call, and each row with only argument 0 varying
// (over 3 lanes) while the others stay uniform.
template <class T>
void checkScalarRows(std::string_view name, const std::vector<std::vector<double>>& rows) {
    const Kernel<T> k = kernelOf<T>(builtin(name));
    const int lanes = static_cast<int>(rows.size());
    const int nargs = static_cast<int>(rows.front().size()) - 1;
    for (const auto& row : rows) REQUIRE(row.size() == rows.front().size());
    for (const auto& row : rows) {
        INFO(name << " row starting " << row[0]);
        KernelCall<T> u(1, 1);
        for (int j = 0; j < nargs; ++j) u.uniform({row[static_cast<size_t>(j)]});
        u.run(k);
        CHECK(u.out(0) == near<T>(row.back()));

        KernelCall<T> mixed(3, 1);
        mixed.varying(1, [&](int, int) { return row[0]; });
        for (int j = 1; j < nargs; ++j) mixed.uniform({row[static_cast<size_t>(j)]});
        mixed.run(k);
        for (int i = 0; i < 3; ++i) CHECK(mixed.out(i) == near<T>(row.back()));
    }
    KernelCall<T> v(lanes, 1);
    for (int j = 0; j < nargs; ++j)
        v.varying(1, [&](int i, int) { return rows[static_cast<size_t>(i)][static_cast<size_t>(j)]; });
    v.run(k);
    for (int i = 0; i < lanes; ++i) {
        INFO(name << " lane " << i);
        CHECK(v.out(i) == near<T>(rows[static_cast<size_t>(i)].back()));
    }
}

// A call site for a built-in's validate hook: argument i spans [10i+1, 10i+5).
struct Site {
    lang::DiagnosticSink sink;
    lang::CallSite site;
    std::string format;
    Site(std::string_view name, std::vector<lang::Type> types, std::vector<std::vector<double>> consts) {
        site.name = name;
        site.span = {0, 100};
        site.argTypes = std::move(types);
        for (size_t i = 0; i < site.argTypes.size(); ++i) {
            site.argSpans.push_back({uint32_t(10 * i + 1), uint32_t(10 * i + 5)});
            site.constStrings.push_back(nullptr);
        }
        site.constValues = std::move(consts);
        site.constValues.resize(site.argTypes.size());
        site.sink = &sink;
    }
    // Makes argument 0 the constant string `text`.
    Site& constFormat(std::string text) {
        format = std::move(text);
        site.constStrings[0] = &format;
        return *this;
    }
    bool validate() { return builtin(site.name).info.validate(site); }
};
inline std::vector<lang::Type> scalars(size_t n) { return std::vector<lang::Type>(n, lang::Type::fp(1)); }

} // namespace gale::runtime::testing
