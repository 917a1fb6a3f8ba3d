// sprintf and printf kernels (C conversions, %v, %%, masks, varying arguments) and the format
// checks of their validate hooks.
#include "runtime/builtins.h"
#include "runtime/builtins_testing.h"

#include <catch2/catch.hpp>

#include <string>

using namespace gale;
using namespace gale::runtime;
using namespace gale::runtime::testing;

TEMPLATE_TEST_CASE("sprintf: C conversions, %v and %%", "[builtins]", float, double) {
    using T = TestType;
    KernelCall<T> a(1, 1);
    a.string("%d apples, %.2f pears: %s %v 100%%").uniform({3.7}).uniform({2.5}).string("x").uniform({1, 2, 3});
    a.run("sprintf");
    CHECK(a.str(0) == "3 apples, 2.50 pears: x [1,2,3] 100%");

    KernelCall<T> b(1, 1);
    b.string("%05.1f|%x|%X|%o|%e|%g|%c|%i|%u|%-4d|%+d|%ld");
    for (double v : {3.14159, 255.0, 255.0, 8.0, 12345.678, 0.0001, 65.0, -7.9, 42.0, 7.0, 5.0, 6.0}) b.uniform({v});
    b.run("sprintf");
    CHECK(b.str(0) == "003.1|ff|FF|10|1.234568e+04|0.0001|A|-7|42|7   |+5|6");

    // %v: a scalar shows as FP[3]; flags and precision apply to each component (as %g).
    KernelCall<T> c(1, 1);
    c.string("%v %.3v %v").uniform({2}).uniform({1, 0.5, 0.25}).uniform({0.5, 1.5});
    c.run("sprintf");
    CHECK(c.str(0) == "[2,2,2] [1,0.5,0.25] [0.5,1.5]");

    KernelCall<T> d(1, 1);
    d.string("no conversions").run("sprintf");
    CHECK(d.str(0) == "no conversions");
}

TEMPLATE_TEST_CASE("sprintf: varying arguments give one string per lane", "[builtins]", float, double) {
    using T = TestType;
    KernelCall<T> v(4, 1);
    v.string("lane %d: %g").varying(1, [](int i, int) { return double(i); }).varying(1, [](int i, int) {
        return 0.5 * i;
    });
    v.run("sprintf");
    CHECK(v.str(0) == "lane 0: 0");
    CHECK(v.str(1) == "lane 1: 0.5");
    CHECK(v.str(3) == "lane 3: 1.5");
}

TEMPLATE_TEST_CASE("sprintf: mismatches of a non-constant format are printed, not fatal", "[builtins]", float,
                   double) {
    KernelCall<TestType> m(1, 1);
    m.string("%d and %d, %s").uniform({1}).uniform({2}).uniform({2.5});
    m.run("sprintf");
    CHECK(m.str(0) == "1 and 2, 2.5");
    KernelCall<TestType> missing(1, 1);
    missing.string("%d %5.1f").uniform({1});
    missing.run("sprintf");
    CHECK(missing.str(0) == "1 %5.1f");
    KernelCall<TestType> bad(1, 1);
    bad.string("50% off").run("sprintf");
    CHECK(bad.str(0) == "50% off");
}

TEMPLATE_TEST_CASE("printf: active lanes only, one line each, result 0", "[builtins]", float, double) {
    using T = TestType;
    KernelCall<T> p(3, 1);
    p.string("a=%f b=%.3f %v 5%%").varying(1, [](int i, int) { return 0.5 + i * 0.875; }).uniform({0.5});
    p.uniform({1, 2, 3});
    p.mask({true, false, true});
    p.run("printf");
    // A bare %f prints like SeExpr2's printf (stream format, i.e. %g); %.3f is C's.
    CHECK(p.messages() == "a=0.5 b=0.500 [1,2,3] 5%\na=2.25 b=0.500 [1,2,3] 5%\n");
    for (int i = 0; i < 3; ++i) CHECK(p.out(i) == T(0));

    KernelCall<T> all(2, 1);
    all.string("hi").run("printf");
    CHECK(all.messages() == "hi\nhi\n");
    KernelCall<T> nl(2, 1);
    nl.string("line %d\n").varying(1, [](int i, int) { return double(i); }).run("printf");
    CHECK(nl.messages() == "line 0\nline 1\n");
}

TEST_CASE("sprintf/printf validate the format against the arguments", "[builtins]") {
    const lang::Type num = lang::Type::fp(1), vec = lang::Type::fp(3), str = lang::Type::string();
    {
        Site s("sprintf", {str, num, str, vec}, {});
        s.constFormat("%d %s %v");
        CHECK(s.validate());
        CHECK(!s.sink.hasErrors());
    }
    {
        Site s("sprintf", {str, str}, {});
        s.constFormat("%d");
        CHECK(!s.validate());
        CHECK(s.sink.diagnostics()[0].span.begin == s.site.argSpans[1].begin);
    }
    {
        Site s("sprintf", {str, num}, {});
        s.constFormat("%d %d");
        CHECK(!s.validate());
    }
    {
        Site s("sprintf", {str, num, num}, {});
        s.constFormat("%d");
        CHECK(!s.validate());
        CHECK(s.sink.diagnostics()[0].span.begin == s.site.argSpans[2].begin);
    }
    {
        Site s("sprintf", {str, vec}, {});
        s.constFormat("%f");
        CHECK(!s.validate()); // use %v for vectors
    }
    {
        Site s("printf", {str, vec}, {});
        s.constFormat("%f");
        CHECK(s.validate()); // SeExpr2's printf prints component 0
    }
    {
        Site s("sprintf", {str, num}, {});
        s.constFormat("%q");
        CHECK(!s.validate());
        CHECK(s.sink.diagnostics()[0].span.begin == s.site.argSpans[0].begin);
    }
    {
        Site s("printf", {str}, {});
        s.constFormat("100%");
        CHECK(!s.validate());
    }
    {
        Site s("sprintf", {str, num, str}, {}); // format not constant: checked at run time
        CHECK(s.validate());
    }
}
