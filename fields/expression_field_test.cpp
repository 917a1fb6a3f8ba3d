// Tests for expression fields: the parameter idiom (declarations, ranges, blanking), overrides
// and keyframes, sampling (threads, precision, non-finite repair), and the presets against
// their closed forms (ripple phase speed and wavelength, volume-axis components, wind falloff).
#include "fields/expression_field.h"
#include "fields/presets.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

using namespace gale::fields;
using gale::lang::SourceFile;

namespace {

std::shared_ptr<ExpressionField> compileText(const std::string& text,
                                             const ExpressionFieldOptions& options = {},
                                             std::string* errors = nullptr) {
    SourceFile source("test.se", text);
    gale::lang::DiagnosticSink sink;
    auto field = ExpressionField::compile(source, options, sink);
    if (errors) *errors = gale::lang::renderDiagnostics(source, sink);
    else if (!field) FAIL(gale::lang::renderDiagnostics(source, sink));
    return field;
}

std::shared_ptr<ExpressionField> compilePreset(const std::string& name,
                                               std::map<std::string, Param> params,
                                               gale::runtime::Precision precision =
                                                   gale::runtime::Precision::Double) {
    const Preset* p = findPreset(name);
    REQUIRE(p != nullptr);
    ExpressionFieldOptions options;
    options.params = std::move(params);
    options.precision = precision;
    SourceFile source(name + ".se", std::string(p->text));
    gale::lang::DiagnosticSink sink;
    auto field = ExpressionField::compile(source, options, sink);
    if (!field) FAIL(gale::lang::renderDiagnostics(source, sink));
    return field;
}

Vec3 sampleAt(const Field& f, const Vec3& p, double t = 0.0) {
    double v[3] = {0, 0, 0};
    SampleTime when;
    when.time = t;
    SampleStatus s = f.sample(p.data(), 1, when, v);
    REQUIRE(s.ok);
    return {v[0], v[1], v[2]};
}

void requireNear(const Vec3& got, const Vec3& want, double tol = 1e-9) {
    INFO("got (" << got[0] << ", " << got[1] << ", " << got[2] << "), want (" << want[0] << ", "
                 << want[1] << ", " << want[2] << ")");
    for (int k = 0; k < 3; ++k) REQUIRE(std::fabs(got[k] - want[k]) <= tol);
}

Param vec(double x, double y, double z) { return Param(std::vector<double>{x, y, z}); }

} // namespace

TEST_CASE("findParameters reads the slider idiom", "[params]") {
    SourceFile src("p.se", "# header\n"
                           "$speed = 5; # 0, 40  mean speed, m/s\n"
                           "$dir = [1, -0.5, 0];   # [-1, 1]\n"
                           "$neg = -2.5;\n"
                           "$plain = 3; # just a note\n"
                           "x = 1;\n"
                           "if (x) { $inner = 4; }\n"
                           "def f(a) { $q = 2; a }\n"
                           "$expr = 2 * 3;\n"
                           "$t = 7;\n"
                           "$speed = 9;\n"
                           "$speed * $dir\n");
    std::vector<ParameterDecl> ps = findParameters(src);
    REQUIRE(ps.size() == 4);
    CHECK(ps[0].name == "speed");
    CHECK(ps[0].defaultValue == std::vector<double>{5});
    CHECK(ps[0].hasRange);
    CHECK(ps[0].min == 0);
    CHECK(ps[0].max == 40);
    CHECK(ps[0].doc == "mean speed, m/s");
    CHECK(ps[0].line == 2);
    CHECK(ps[1].name == "dir");
    CHECK(ps[1].defaultValue == std::vector<double>{1, -0.5, 0});
    CHECK(ps[1].hasRange);
    CHECK(ps[1].min == -1);
    CHECK(ps[1].max == 1);
    CHECK(ps[2].name == "neg");
    CHECK(ps[2].defaultValue == std::vector<double>{-2.5});
    CHECK_FALSE(ps[2].hasRange);
    CHECK(ps[3].name == "plain");
    CHECK_FALSE(ps[3].hasRange);
    CHECK(ps[3].doc == "just a note");
}

TEST_CASE("withoutParameters blanks declarations and keeps every column", "[params]") {
    SourceFile src("p.se", "$a = 2; # 0, 4\n$b = [1, 2, 3];\n$a * $b\n");
    std::vector<ParameterDecl> ps = findParameters(src);
    SourceFile blank = withoutParameters(src, ps);
    CHECK(blank.text() == std::string(7, ' ') + " # 0, 4\n" + std::string(15, ' ') + "\n$a * $b\n");
    CHECK(blank.text().size() == src.text().size());
}

TEST_CASE("parameters take their defaults, overrides and keyframes", "[params]") {
    const std::string text = "$speed = 5; # 0, 40\n$dir = [1, 0, 0];\n$speed * $dir\n";
    requireNear(sampleAt(*compileText(text), {3, 4, 5}), {5, 0, 0});

    ExpressionFieldOptions o;
    o.params["speed"] = Param(8.0);
    o.params["dir"] = vec(0, 0, 1);
    requireNear(sampleAt(*compileText(text, o), {0, 0, 0}), {0, 0, 8});

    // A scalar override of a vector parameter broadcasts.
    ExpressionFieldOptions b;
    b.params["dir"] = Param(2.0);
    requireNear(sampleAt(*compileText(text, b), {0, 0, 0}), {10, 10, 10});

    // Keyframed: evaluated at the sample time (linear 2 -> 10 over [1, 3]).
    ExpressionFieldOptions k;
    k.params["speed"] = Param::keyed({1.0, 3.0}, {{2.0}, {10.0}}, KeyInterp::Linear);
    auto f = compileText(text, k);
    requireNear(sampleAt(*f, {0, 0, 0}, 0.0), {2, 0, 0});
    requireNear(sampleAt(*f, {0, 0, 0}, 2.5), {8, 0, 0});
    requireNear(sampleAt(*f, {0, 0, 0}, 9.0), {10, 0, 0});
}

TEST_CASE("unknown or misshapen overrides are errors with the declared names", "[params]") {
    const std::string text = "$speed = 5;\n$gain = 1;\n$speed * $gain\n";
    ExpressionFieldOptions o;
    o.params["sped"] = Param(1.0);
    std::string errors;
    CHECK(compileText(text, o, &errors) == nullptr);
    CHECK(errors.find("'sped' is not a parameter of test.se") != std::string::npos);
    CHECK(errors.find("did you mean 'speed'?") != std::string::npos);
    CHECK(errors.find("its parameters: speed, gain") != std::string::npos);

    ExpressionFieldOptions w;
    w.params["speed"] = Param(std::vector<double>{1, 2});
    CHECK(compileText(text, w, &errors) == nullptr);
    CHECK(errors.find("test.se:1:1: error: parameter 'speed' is FP[1] but its override has 2") !=
          std::string::npos);
}

TEST_CASE("errors in an expression keep their line and column after blanking", "[params]") {
    std::string errors;
    CHECK(compileText("$speed = 5; # 0, 9\nv = $speed * nosuch;\nv\n", {}, &errors) == nullptr);
    CHECK(errors.find("test.se:2:14: error:") == 0);
    CHECK(errors.find("    v = $speed * nosuch;") != std::string::npos);
}

TEST_CASE("sampling a batch: threads, precision and non-finite repair", "[sample]") {
    auto f = compileText("[$P[0] * 2, $P[1] + $t, $id]");
    std::vector<double> pos;
    const size_t n = 1000;
    for (size_t i = 0; i < n; ++i) {
        pos.push_back(0.25 * static_cast<double>(i));
        pos.push_back(-1.0);
        pos.push_back(0.0);
    }
    std::vector<double> one(3 * n), many(3 * n);
    SampleTime when;
    when.time = 0.5;
    REQUIRE(f->sample(pos.data(), n, when, one.data()).ok);
    when.threads = 0;
    REQUIRE(f->sample(pos.data(), n, when, many.data()).ok);
    CHECK(one == many);
    CHECK(one[3 * 7] == 3.5);
    CHECK(one[3 * 7 + 1] == -0.5);
    CHECK(one[3 * 7 + 2] == 7.0);

    auto nan = compileText("$P[0] > 1 ? [0, 0, 0] / 0 : [1, 2, 3]");
    SampleStatus s = nan->sample(pos.data(), n, when, many.data());
    CHECK(s.ok);
    CHECK(s.nonFinite == n - 5); // x = 0, 0.25, ..., 1 are finite
    CHECK(many[3 * 999] == 0.0);
    CHECK(many[0] == 1.0);
    CHECK(!s.message.empty());
}

TEST_CASE("float and double precision agree to float accuracy", "[sample]") {
    const std::string text = "[sin($P[0]), cos($P[1]) * 3, $P[2] / 7]";
    ExpressionFieldOptions o;
    o.precision = gale::runtime::Precision::Double;
    auto d = compileText(text, o);
    auto f = compileText(text);
    const Vec3 p{0.3, 1.7, 2.0};
    Vec3 vd = sampleAt(*d, p), vf = sampleAt(*f, p);
    requireNear(vd, {std::sin(0.3), 3 * std::cos(1.7), 2.0 / 7}, 1e-12);
    requireNear(vf, vd, 1e-6);
}

TEST_CASE("embedded presets are the files in fields/presets", "[presets]") {
    REQUIRE(presets().size() >= 3);
    for (const char* name : {"wind", "ripple", "volume_axis"}) {
        const Preset* p = findPreset(name);
        REQUIRE(p != nullptr);
        std::ifstream in(std::string(GALE_SOURCE_DIR) + "/fields/presets/" + name + ".se");
        std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        CHECK(text == p->text);
        // Every parameter is documented with a range or a note.
        for (const ParameterDecl& d : findParameters(SourceFile(name, text)))
            CHECK((d.hasRange || !d.doc.empty()));
    }
    CHECK(findPreset("nosuch") == nullptr);
    CHECK(presetNames().find("ripple") != std::string::npos);
}

TEST_CASE("wind preset: direction and speed, and the falloff at its edge", "[presets]") {
    auto f = compilePreset("wind", {{"speed", Param(6.0)}, {"direction", vec(0, 0, 2)}});
    requireNear(sampleAt(*f, {1, 2, 3}), {0, 0, 6}, 1e-12);

    // Falloff: 1 inside radius - width, 1/2 half-way, 0 at and beyond the radius.
    auto g = compilePreset("wind", {{"speed", Param(4.0)},
                                    {"falloffRadius", Param(10.0)},
                                    {"falloffWidth", Param(4.0)},
                                    {"falloffCenter", vec(1, 0, 0)}});
    requireNear(sampleAt(*g, {1, 5.9, 0}), {4, 0, 0}, 1e-12);
    requireNear(sampleAt(*g, {1, 0, 8}), {2, 0, 0}, 1e-12);     // d = 8: smoothstep(1/2) = 1/2
    requireNear(sampleAt(*g, {1, 7, 0}), {4 * (1 - 0.15625), 0, 0}, 1e-12); // s = 1/4
    requireNear(sampleAt(*g, {11, 0, 0}), {0, 0, 0}, 1e-12);
    requireNear(sampleAt(*g, {30, 0, 0}), {0, 0, 0}, 1e-12);
}

TEST_CASE("wind preset: spread turns the direction, turbulence has the asked rms", "[presets]") {
    // Spread keeps the speed (only the direction turns) and moves the direction off-axis.
    auto f = compilePreset("wind", {{"speed", Param(5.0)}, {"spread", Param(30.0)}});
    double offAxis = 0.0;
    for (int i = 0; i < 50; ++i) {
        Vec3 v = sampleAt(*f, {i * 3.1, 0.7 * i, -2.0 * i});
        CHECK(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) == Approx(5.0).epsilon(1e-9));
        offAxis += std::fabs(v[1]) + std::fabs(v[2]);
    }
    CHECK(offAxis > 1.0);

    // Turbulence: rms of each component about turbulence * speed (here 0.2 * 5 = 1 m/s).
    auto g = compilePreset("wind", {{"speed", Param(5.0)}, {"turbulence", Param(0.2)},
                                    {"turbulenceScale", Param(1.0)}});
    const int n = 4096;
    std::vector<double> pos, vel(3 * n);
    for (int i = 0; i < n; ++i) {
        pos.push_back(0.37 * (i % 16));
        pos.push_back(0.41 * ((i / 16) % 16));
        pos.push_back(0.43 * (i / 256));
    }
    SampleTime when;
    REQUIRE(g->sample(pos.data(), n, when, vel.data()).ok);
    double sum2 = 0.0;
    for (int i = 0; i < n; ++i) sum2 += vel[3 * i + 1] * vel[3 * i + 1] + vel[3 * i + 2] * vel[3 * i + 2];
    const double rms = std::sqrt(sum2 / (2.0 * n));
    CHECK(rms > 0.6);
    CHECK(rms < 1.4);
}

TEST_CASE("ripple preset: phase speed, wavelength, amplitude and decay", "[presets]") {
    const double lambda = 4.0, c = 2.0, amp = 3.0;
    auto f = compilePreset("ripple", {{"wavelength", Param(lambda)},
                                      {"speed", Param(c)},
                                      {"amplitude", Param(amp)}});
    // A crest at phase 1/4 (s = lambda / 4), a trough at 3/4, zero at 0 and 1/2.
    requireNear(sampleAt(*f, {1, 5, -2}), {amp, 0, 0}, 1e-12);
    requireNear(sampleAt(*f, {3, 0, 0}), {-amp, 0, 0}, 1e-12);
    requireNear(sampleAt(*f, {2, 0, 0}), {0, 0, 0}, 1e-12);
    // The pattern repeats every wavelength ...
    for (double x : {0.3, 1.1, 2.6}) {
        const Vec3 v0 = sampleAt(*f, {x, 0, 0}, 0.4);
        requireNear(sampleAt(*f, {x + lambda, 0, 0}, 0.4), v0, 1e-9);
        requireNear(sampleAt(*f, {x + 3 * lambda, 0, 0}, 0.4), v0, 1e-9);
        // ... and travels at the phase speed c: v(x + c dt, t + dt) = v(x, t).
        requireNear(sampleAt(*f, {x + c * 0.7, 0, 0}, 0.4 + 0.7), v0, 1e-9);
        requireNear(sampleAt(*f, {x + c * 2.25, 0, 0}, 0.4 + 2.25), v0, 1e-9);
    }
    // The crest at x = 1 is at x = 1 + c t later.
    requireNear(sampleAt(*f, {1 + c * 1.5, 0, 0}, 1.5), {amp, 0, 0}, 1e-9);

    // Decay: exp(-decay s) at distance s from the source plane; an axis turns the motion.
    auto g = compilePreset("ripple", {{"wavelength", Param(lambda)}, {"amplitude", Param(amp)},
                                      {"decay", Param(0.1)}, {"axis", vec(0, 2, 0)},
                                      {"direction", vec(0, 0, 1)}});
    requireNear(sampleAt(*g, {0, 0, 9}), {0, amp * std::exp(-0.9), 0}, 1e-12); // phase 9/4 % 1

    // Radial: circles around the centre, measured across `up`.
    auto r = compilePreset("ripple", {{"wavelength", Param(lambda)}, {"amplitude", Param(amp)},
                                      {"radial", Param(1.0)}, {"center", vec(1, 0, 1)}});
    requireNear(sampleAt(*r, {1, 7, 2}), {0, 0, amp}, 1e-12);   // s = 1 along +z
    requireNear(sampleAt(*r, {1 - 0.6, 0, 1 + 0.8}), {-0.6 * amp, 0, 0.8 * amp}, 1e-9);
}

TEST_CASE("volume_axis preset: components along, around and away", "[presets]") {
    const double m = 5.0;
    auto component = [&](const char* name) {
        std::map<std::string, Param> p{{"magnitude", Param(m)}, {"radius", Param(10.0)},
                                       {"awayFromAxis", Param(0.0)}};
        p[name] = Param(1.0);
        return compilePreset("volume_axis", p);
    };
    requireNear(sampleAt(*component("awayFromCenter"), {3, 4, 0}), {3, 4, 0}, 1e-12);
    requireNear(sampleAt(*component("awayFromAxis"), {3, 7, 4}), {3, 0, 4}, 1e-12);
    requireNear(sampleAt(*component("alongAxis"), {3, 7, 4}), {0, 5, 0}, 1e-12);
    // Around +y by the right-hand rule: +x goes to -z, +z to +x.
    requireNear(sampleAt(*component("aroundAxis"), {2, 1, 0}), {0, 0, -5}, 1e-12);
    requireNear(sampleAt(*component("aroundAxis"), {0, -3, 4}), {5, 0, 0}, 1e-12);
    requireNear(sampleAt(*component("directionalSpeed"), {1, 1, 1}), {5, 0, 0}, 1e-12);
    // Outside the sphere: nothing.
    requireNear(sampleAt(*component("alongAxis"), {0, 10.5, 0}), {0, 0, 0}, 1e-12);

    // A tilted axis and an offset centre: along the axis is along the (normalised) axis.
    auto t = compilePreset("volume_axis", {{"magnitude", Param(2.0)}, {"awayFromAxis", Param(0.0)},
                                           {"alongAxis", Param(1.0)}, {"axis", vec(1, 1, 0)},
                                           {"center", vec(5, 5, 5)}});
    const double h = std::sqrt(2.0);
    requireNear(sampleAt(*t, {6, 5, 5}), {h, h, 0}, 1e-12);
}

TEST_CASE("volume_axis preset: shapes and the attenuation ramp at the edge", "[presets]") {
    auto along = [&](double shape, std::map<std::string, Param> extra = {}) {
        std::map<std::string, Param> p{{"magnitude", Param(1.0)}, {"awayFromAxis", Param(0.0)},
                                       {"alongAxis", Param(1.0)}, {"shape", Param(shape)},
                                       {"radius", Param(2.0)}, {"height", Param(3.0)}};
        for (auto& [k, v] : extra) p[k] = v;
        return compilePreset("volume_axis", p);
    };
    auto inside = [&](const Field& f, const Vec3& p) { return sampleAt(f, p)[1]; };
    auto cube = along(1), sphere = along(2), cylinder = along(3), cone = along(4), torus = along(5);
    auto everywhere = along(0);
    CHECK(inside(*everywhere, {100, -50, 3}) == 1.0);
    // Cube: half-size 2 across the axis, 3 along it.
    CHECK(inside(*cube, {1.9, 2.9, -1.9}) == 1.0);
    CHECK(inside(*cube, {2.1, 0, 0}) == 0.0);
    CHECK(inside(*cube, {0, 3.1, 0}) == 0.0);
    // Sphere radius 2.
    CHECK(inside(*sphere, {1.2, 1.5, 0}) == 1.0);
    CHECK(inside(*sphere, {1.5, 1.5, 0}) == 0.0);
    // Cylinder radius 2, half-length 3.
    CHECK(inside(*cylinder, {1.2, 2.9, 1.5}) == 1.0);
    CHECK(inside(*cylinder, {1.5, 0, 1.5}) == 0.0);
    CHECK(inside(*cylinder, {0, -3.2, 0}) == 0.0);
    // Cone: apex at the centre, radius 2 at height 3 (radius 1 at height 1.5).
    CHECK(inside(*cone, {0.9, 1.5, 0}) == 1.0);
    CHECK(inside(*cone, {1.1, 1.5, 0}) == 0.0);
    CHECK(inside(*cone, {0, -0.5, 0}) == 0.0);
    // Torus: ring radius 2, tube radius 1; along the "axis" is along the ring.
    Vec3 v = sampleAt(*torus, {2.5, 0.3, 0});
    requireNear(v, {0, 0, -1}, 1e-12); // the ring's tangent at +x: cross(y, x) = -z
    CHECK(sampleAt(*torus, {0.5, 0, 0})[2] == 0.0);

    // Attenuation 1: the default ramp (1 at the centre, smooth to 0 at the surface).
    auto a = along(2, {{"attenuation", Param(1.0)}});
    CHECK(inside(*a, {0, 0, 0}) == Approx(1.0).margin(1e-12));
    CHECK(inside(*a, {0, 0.5, 0}) == Approx(1 - 0.15625).margin(1e-12)); // u = 1/4
    CHECK(inside(*a, {0, 1.0, 0}) == Approx(0.5).margin(1e-12));         // u = 1/2
    CHECK(inside(*a, {0, 2.0, 0}) == Approx(0.0).margin(1e-12));         // on the surface
    // Half attenuation mixes halfway toward the ramp.
    auto half = along(2, {{"attenuation", Param(0.5)}});
    CHECK(inside(*half, {0, 1.0, 0}) == Approx(0.75).margin(1e-12));
}

TEST_CASE("presets evaluate in float to float accuracy", "[presets]") {
    auto f = compilePreset("ripple", {}, gale::runtime::Precision::Float);
    auto d = compilePreset("ripple", {}, gale::runtime::Precision::Double);
    for (double x : {0.1, 1.0, 2.7, 5.5}) requireNear(sampleAt(*f, {x, 0, 0}, 0.3), sampleAt(*d, {x, 0, 0}, 0.3), 1e-5);
}
