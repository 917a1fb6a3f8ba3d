// The windicator and gust rigs: the wind direction over time, gust envelopes, and the gust(P)
// built-in whose kernel reads the scene's gusts through Builtin::data.
#include "fields/rigs.h"

#include "fields/expression_field.h"

#include <cmath>

namespace gale::fields {

Vec3 windDirectionAt(const Windicator& w, double t) {
    double d[3] = {0.0, 0.0, 0.0};
    if (w.direction.width() == 3)
        w.direction.evaluate(t, d);
    else
        d[0] = d[1] = d[2] = w.direction.scalarAt(t);
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0) || !std::isfinite(len)) return {0.0, 0.0, 0.0};
    return {d[0] / len, d[1] / len, d[2] / len};
}

namespace {

double smooth01(double s) { return s * s * (3.0 - 2.0 * s); }

} // namespace

double gustEnvelope(const Gust& g, double tau) {
    if (!(tau >= 0.0)) return 0.0; // before the front (or NaN)
    if (tau < g.attack) return smooth01(tau / g.attack);
    tau -= g.attack;
    if (tau < g.hold) return 1.0;
    tau -= g.hold;
    if (tau < g.decay) return 1.0 - smooth01(tau / g.decay);
    return 0.0;
}

double gustSpeedAt(const GustRig& rig, const Vec3& dir, const Vec3& p, double t) {
    const double along = p[0] * dir[0] + p[1] * dir[1] + p[2] * dir[2];
    double sum = 0.0;
    for (const Gust& g : rig.gusts) {
        const double delay = along / g.travelSpeed;
        const double env = gustEnvelope(g, t - g.start - delay);
        if (env == 0.0) continue;
        sum += env * g.strength.scalarAt(t - delay);
    }
    return sum;
}

namespace {

// gust(P) with the implicit $t appended by the compiler: args[0] = P (FP[3]), args[1] = $t.
struct GustKernel {
    template <class T>
    static void run(const runtime::KernelFrame<T>& f) {
        T* out = f.outComp(0);
        const GustRig* rig = static_cast<const GustRig*>(f.user);
        if (!rig || rig->gusts.empty()) {
            for (int i = 0; i < f.n; ++i) out[i] = T(0);
            return;
        }
        const runtime::Operand<T>& P = f.args[0];
        const bool haveTime = f.nargs > 1;
        const bool uniformTime = !haveTime || f.args[1].uniform();
        auto timeAt = [&](int i) { return haveTime ? static_cast<double>(f.args[1].at(0, i)) : 0.0; };
        Vec3 dir = windDirectionAt(rig->windicator, timeAt(0));
        for (int i = 0; i < f.n; ++i) {
            const double t = timeAt(i);
            if (!uniformTime) dir = windDirectionAt(rig->windicator, t);
            const Vec3 p{static_cast<double>(P.at(0, i)), static_cast<double>(P.at(1, i)),
                         static_cast<double>(P.at(2, i))};
            out[i] = static_cast<T>(gustSpeedAt(*rig, dir, p, t));
        }
    }
};

} // namespace

runtime::Builtin gustBuiltin(std::shared_ptr<const GustRig> rig) {
    runtime::Builtin b = runtime::kernelBuiltin<GustKernel>(
        "gust", "FP[1] gust(FP[3] P)",
        "Speed (m/s) of the scene's [[gust]] events at P and time $t: each front sweeps along "
        "the windicator direction at its travel_speed (0 without gusts)");
    b.info.implicitArgs = {{"t", 0.0}};
    b.data = std::move(rig);
    return b;
}

void addGustBuiltins(runtime::FunctionTable& t) { t.add(gustBuiltin(nullptr)); }

std::shared_ptr<const runtime::FunctionTable> sceneFunctions(const Scene& scene) {
    auto rig = std::make_shared<GustRig>();
    rig->windicator = scene.windicator.value_or(Windicator{});
    rig->gusts = scene.gusts;
    auto table = std::make_shared<runtime::FunctionTable>(*fieldFunctions());
    table->add(gustBuiltin(std::move(rig)));
    return table;
}

} // namespace gale::fields
