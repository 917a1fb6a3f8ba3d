// FP[3] vector built-ins: length dot cross norm angle ortho rotate up dist, with SeExpr2's
// formulas and evaluation order (its Vec divides by multiplying with the reciprocal).
#include "runtime/builtins.h"
#include "runtime/builtins_detail.h"

#include <cmath>
#include <string>

namespace gale::runtime {
namespace {

template <class T>
struct V3 {
    T x, y, z;
};

// Reads lane i of an FP[3] operand (a width-1 operand broadcasts to all three components).
template <class T>
struct V3Reader {
    const T* c0;
    const T* c1;
    const T* c2;
    int stride;
    explicit V3Reader(const Operand<T>& o) : c0(o.comp(0)), c1(o.comp(1)), c2(o.comp(2)), stride(o.laneStride) {}
    V3<T> operator[](int i) const {
        const int j = i * stride;
        return {c0[j], c1[j], c2[j]};
    }
};

// The same with the lane stride known at compile time (see withStrides): the hot kernels use
// it so that their loops vectorise.
template <class T, int S>
struct V3ReaderS {
    const T* __restrict c0;
    const T* __restrict c1;
    const T* __restrict c2;
    explicit V3ReaderS(const Operand<T>& o) : c0(o.comp(0)), c1(o.comp(1)), c2(o.comp(2)) {}
    V3<T> operator[](int i) const { return {c0[i * S], c1[i * S], c2[i * S]}; }
};

template <class T>
struct V3Writer {
    T* c0;
    T* c1;
    T* c2;
    explicit V3Writer(const KernelFrame<T>& f) : c0(f.outComp(0)), c1(f.outComp(1)), c2(f.outComp(2)) {}
    void set(int i, const V3<T>& v) const {
        c0[i] = v.x;
        c1[i] = v.y;
        c2[i] = v.z;
    }
};

template <class T> T dot(const V3<T>& a, const V3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> T length(const V3<T>& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }
template <class T> V3<T> cross(const V3<T>& a, const V3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T> V3<T> scaled(const V3<T>& v, T s) { return {v.x * s, v.y * s, v.z * s}; }
// Unit vector; the zero vector stays zero.
template <class T> V3<T> norm(const V3<T>& v) {
    const T len = length(v);
    if (len == 0) return {0, 0, 0};
    return scaled(v, T(1) / len);
}
// Angle between a and b in radians (0 if either is zero). The cosine is clamped to [-1, 1]:
// SeExpr2 gives NaN for angle(v, v) when rounding pushes it past 1 (documented fix).
template <class T> T angle(const V3<T>& a, const V3<T>& b) {
    const T len = length(a) * length(b);
    if (len == 0) return 0;
    T c = dot(a, b) / len;
    c = c < T(-1) ? T(-1) : (c > T(1) ? T(1) : c);
    return std::acos(c);
}
// Rodrigues' rotation of p about the unit axis a by `angle` radians (right-handed), in
// SeExpr2's form c p + (1 - c)(p.a) a - s (p x a).
template <class T> V3<T> rotateBy(const V3<T>& p, const V3<T>& a, T angle) {
    const T c = std::cos(angle), s = std::sin(angle);
    const T t = (1 - c) * dot(p, a);
    const V3<T> pa = cross(p, a);
    return {p.x * c + a.x * t - pa.x * s, p.y * c + a.y * t - pa.y * s, p.z * c + a.z * t - pa.z * s};
}

struct LengthK {
    template <class T> static void run(const KernelFrame<T>& f) {
        withStrides(f.args[0].laneStride, [&](auto s) {
            const V3ReaderS<T, decltype(s)::value> v(f.args[0]);
            T* __restrict o = f.outComp(0);
            for (int i = 0; i < f.n; ++i) o[i] = length(v[i]);
        });
    }
};

struct DotK {
    template <class T> static void run(const KernelFrame<T>& f) {
        withStrides(f.args[0].laneStride, f.args[1].laneStride, [&](auto sa, auto sb) {
            const V3ReaderS<T, decltype(sa)::value> a(f.args[0]);
            const V3ReaderS<T, decltype(sb)::value> b(f.args[1]);
            T* __restrict o = f.outComp(0);
            for (int i = 0; i < f.n; ++i) o[i] = dot(a[i], b[i]);
        });
    }
};

struct CrossK {
    template <class T> static void run(const KernelFrame<T>& f) {
        withStrides(f.args[0].laneStride, f.args[1].laneStride, [&](auto sa, auto sb) {
            constexpr int A = decltype(sa)::value, B = decltype(sb)::value;
            const T* __restrict ax = f.args[0].comp(0);
            const T* __restrict ay = f.args[0].comp(1);
            const T* __restrict az = f.args[0].comp(2);
            const T* __restrict bx = f.args[1].comp(0);
            const T* __restrict by = f.args[1].comp(1);
            const T* __restrict bz = f.args[1].comp(2);
            T* __restrict o0 = f.outComp(0);
            T* __restrict o1 = f.outComp(1);
            T* __restrict o2 = f.outComp(2);
            for (int i = 0; i < f.n; ++i) {
                const V3<T> c = cross(V3<T>{ax[i * A], ay[i * A], az[i * A]}, V3<T>{bx[i * B], by[i * B], bz[i * B]});
                o0[i] = c.x;
                o1[i] = c.y;
                o2[i] = c.z;
            }
        });
    }
};

struct NormK {
    template <class T> static void run(const KernelFrame<T>& f) {
        withStrides(f.args[0].laneStride, [&](auto s) {
            const V3ReaderS<T, decltype(s)::value> v(f.args[0]);
            T* __restrict o0 = f.outComp(0);
            T* __restrict o1 = f.outComp(1);
            T* __restrict o2 = f.outComp(2);
            for (int i = 0; i < f.n; ++i) {
                const V3<T> u = norm(v[i]);
                o0[i] = u.x;
                o1[i] = u.y;
                o2[i] = u.z;
            }
        });
    }
};

struct AngleK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const V3Reader<T> a(f.args[0]), b(f.args[1]);
        T* __restrict o = f.outComp(0);
        for (int i = 0; i < f.n; ++i) o[i] = angle(a[i], b[i]);
    }
};

struct OrthoK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const V3Reader<T> a(f.args[0]), b(f.args[1]);
        const V3Writer<T> o(f);
        for (int i = 0; i < f.n; ++i) o.set(i, norm(cross(a[i], b[i])));
    }
};

// rotate(v, axis, angle): SeExpr2 rounds the angle to float before taking cos/sin; so do we,
// which keeps results identical to SeExpr2's (e.g. rotating by PI/2 leaves ~4e-8, not 6e-17).
struct RotateK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const V3Reader<T> v(f.args[0]), axis(f.args[1]);
        const Operand<T>& ang = f.args[2];
        const V3Writer<T> o(f);
        for (int i = 0; i < f.n; ++i) {
            const V3<T> p = v[i];
            const V3<T> a = axis[i];
            const T len = length(a);
            if (len == 0) {
                o.set(i, p);
                continue;
            }
            const T angle = T(static_cast<float>(ang.at(0, i)));
            o.set(i, rotateBy(p, scaled(a, T(1) / len), angle));
        }
    }
};

// up(v, upvec): rotates v so that the y axis points along upvec.
struct UpK {
    template <class T> static void run(const KernelFrame<T>& f) {
        const V3Reader<T> v(f.args[0]), up(f.args[1]);
        const V3Writer<T> o(f);
        const V3<T> yAxis{0, 1, 0};
        for (int i = 0; i < f.n; ++i) {
            const V3<T> u = up[i];
            o.set(i, rotateBy(v[i], norm(cross(u, yAxis)), angle(u, yAxis)));
        }
    }
};

// dist(a, b) between two points (FP[3]; a scalar is promoted), or SeExpr2's
// dist(ax, ay, az, bx, by, bz), applied per component when given vectors.
struct DistK {
    template <class T> static void run(const KernelFrame<T>& f) {
        if (f.nargs == 2) {
            const V3Reader<T> a(f.args[0]), b(f.args[1]);
            T* __restrict o = f.outComp(0);
            for (int i = 0; i < f.n; ++i) {
                const V3<T> p = a[i], q = b[i];
                const T x = p.x - q.x, y = p.y - q.y, z = p.z - q.z;
                o[i] = std::sqrt(x * x + y * y + z * z);
            }
            return;
        }
        const Operand<T>* g = f.args;
        for (int k = 0; k < f.outWidth; ++k) {
            T* __restrict o = f.outComp(k);
            for (int i = 0; i < f.n; ++i) {
                const T x = g[0].at(k, i) - g[3].at(k, i);
                const T y = g[1].at(k, i) - g[4].at(k, i);
                const T z = g[2].at(k, i) - g[5].at(k, i);
                o[i] = std::sqrt(x * x + y * y + z * z);
            }
        }
    }
};

bool validateDist(lang::CallSite& site) {
    const size_t nargs = site.argTypes.size();
    if (nargs != 2 && nargs != 6) {
        site.sink->error(site.span, "dist takes two points, dist(a, b), or six coordinates, dist(ax, ay, az, bx, by, bz); got " +
                                        std::to_string(nargs) + " arguments");
        return false;
    }
    bool ok = true;
    int width = 1;
    for (size_t i = 0; i < nargs; ++i) {
        const lang::Type& t = site.argTypes[i];
        if (t.isError()) {
            ok = false;
            continue;
        }
        if (!t.isFloat()) {
            site.sink->error(site.argSpans[i], "dist expects numbers, got " + lang::typeName(t));
            ok = false;
            continue;
        }
        if (nargs == 2) {
            if (t.width != 1 && t.width != 3) {
                site.sink->error(site.argSpans[i], "dist(a, b) expects points of FP[3] (or FP[1]), got " + lang::typeName(t));
                ok = false;
            }
        } else if (t.width != 1) {
            if (width != 1 && t.width != width) {
                site.sink->error(site.argSpans[i], "dist arguments of different widths: FP[" + std::to_string(width) +
                                                       "] and " + lang::typeName(t));
                ok = false;
            }
            width = t.width;
        }
    }
    if (ok) site.resultType = lang::Type::fp(width);
    return ok;
}

} // namespace

namespace detail {

void addVectorBuiltins(FunctionTable& t) {
    t.add(kernelBuiltin<LengthK>("length", "FP[1] length(FP[3] v)", "length of the vector v"));
    t.add(kernelBuiltin<DotK>("dot", "FP[1] dot(FP[3] a, FP[3] b)", "dot product"));
    t.add(kernelBuiltin<CrossK>("cross", "FP[3] cross(FP[3] a, FP[3] b)", "cross product"));
    t.add(kernelBuiltin<NormK>("norm", "FP[3] norm(FP[3] v)", "v scaled to unit length (the zero vector stays zero)"));
    t.add(kernelBuiltin<AngleK>("angle", "FP[1] angle(FP[3] a, FP[3] b)", "angle between a and b, in radians"));
    t.add(kernelBuiltin<OrthoK>("ortho", "FP[3] ortho(FP[3] a, FP[3] b)", "unit vector orthogonal to a and b: norm(cross(a, b))"));
    Builtin rotate =
        kernelBuiltin<RotateK>("rotate", "FP[3] rotate(FP[3] v, FP[3] axis, FP[1] angle)",
                               "v rotated about axis by angle (radians, right-handed)");
    rotate.info.firstComponent = true; // SeExpr2 reads angle[0] of a vector angle
    t.add(rotate);
    t.add(kernelBuiltin<UpK>("up", "FP[3] up(FP[3] v, FP[3] upvec)", "v rotated so that the y axis points along upvec"));
    Builtin dist = kernelBuiltin<DistK>("dist", "FP[1] dist(ANY a, ANY b, ANY coords...)",
                                        "distance between points a and b; also dist(ax, ay, az, bx, by, bz)");
    dist.info.validate = &validateDist;
    t.add(dist);
}

} // namespace detail
} // namespace gale::runtime
