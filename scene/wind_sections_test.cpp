// Tests for scene loading: every key of [scene], [windicator], [[gust]] and [[field]], keyframed
// values, --set overrides by dotted path, and bad input reported at file:line:col (all of it,
// with "did you mean"); then the scene's summed field built and sampled.
#include "fields/expression_field.h"
#include "fields/scene.h"
#include "scene/load.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace gale::fields;
using namespace gale::scene;

namespace {

// A scratch folder per test, removed afterwards.
using gale::io::test::TempDir;

struct Loaded {
    Scene scene;
    std::vector<SceneError> errors;
    bool ok = false;
    std::string rendered() const {
        std::string out;
        for (const SceneError& e : errors) out += e.render() + "\n";
        return out;
    }
    // "line:col: message" of error i (file name left out).
    std::string at(size_t i) const {
        REQUIRE(i < errors.size());
        return std::to_string(errors[i].line) + ":" + std::to_string(errors[i].col) + ": " +
               errors[i].message;
    }
};

Loaded load(const TempDir& dir, const std::string& text, std::vector<std::string> sets = {}) {
    Loaded l;
    SceneLoadOptions options;
    options.sets = std::move(sets);
    l.ok = loadScene(dir.write("scene.toml", text), l.scene, l.errors, options);
    return l;
}

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

Vec3 sampleAt(const Field& f, const Vec3& p, double t) {
    double v[3];
    SampleTime when;
    when.time = t;
    REQUIRE(f.sample(p.data(), 1, when, v).ok);
    return {v[0], v[1], v[2]};
}

} // namespace

TEST_CASE("a full scene loads every key", "[scene]") {
    TempDir dir;
    dir.write("wind/breeze.se", "$swirl = 0.1; # 0, 1\n[1, 0, 0] * (1 + $swirl)\n");
    Loaded l = load(dir, R"TOML(
[scene]
fps = 30
frames = [10, 20]
substeps = 6
gravity = [0, -3.5, 0]
air_density = 1.1

[windicator]
direction = [0, 0, 2]
speed = { keys = [[0, 2.0], [1.0, 8.0]], interp = "smooth" }

[[gust]]
name = "first"
start = 0.5
attack = 0.1
hold = 0.2
decay = 0.4
strength = 6.0
travel_speed = 4.0

[[gust]]
strength = { keys = [[2, 1], [0, 3]] }

[[field]]
name = "main"
expr = "wind/breeze.se"
params = { swirl = 0.3 }
scale = 2

[[field]]
name = "ripples"
preset = "ripple"
params = { wavelength = 2, center = [1, 2, 3] }
scale = { keys = [[0, 0], [1, 1]], interp = "step" }
mask = "smoothstep($P[1], 0, 2)"

[[field]]
source = '''
[0, 1, 0]
'''

[[cloth]]
name = "cape"

[solver]
max_halvings = 4
)TOML");
    INFO(l.rendered());
    REQUIRE(l.ok);
    const Scene& s = l.scene;
    CHECK(s.settings.fps == 30);
    CHECK(s.settings.frameStart == 10);
    CHECK(s.settings.frameEnd == 20);
    CHECK(s.settings.substeps == 6);
    CHECK(s.settings.gravity == std::vector<double>{0, -3.5, 0});
    CHECK(s.settings.airDensity == 1.1);
    REQUIRE(s.windicator);
    CHECK(s.windicator->direction.at(0) == std::vector<double>{0, 0, 2});
    CHECK(s.windicator->speed.isKeyed());
    CHECK(s.windicator->speed.interp() == KeyInterp::Smooth);
    CHECK(s.windicator->speed.scalarAt(0.5) == Approx(5.0));
    REQUIRE(s.gusts.size() == 2);
    CHECK(s.gusts[0].name == "first");
    CHECK(s.gusts[0].start == 0.5);
    CHECK(s.gusts[0].attack == 0.1);
    CHECK(s.gusts[0].hold == 0.2);
    CHECK(s.gusts[0].decay == 0.4);
    CHECK(s.gusts[0].strength.scalarAt(0) == 6.0);
    CHECK(s.gusts[0].travelSpeed == 4.0);
    // Keys are sorted by time.
    CHECK(s.gusts[1].strength.times() == std::vector<double>{0, 2});
    CHECK(s.gusts[1].strength.scalarAt(1) == 2.0);
    REQUIRE(s.fields.size() == 3);
    CHECK(s.fields[0].name == "main");
    CHECK(s.fields[0].exprPath == (dir.path / "wind/breeze.se").string());
    CHECK(s.fields[0].params.at("swirl").scalarAt(0) == 0.3);
    CHECK(s.fields[0].scale.scalarAt(0) == 2);
    CHECK(s.fields[1].preset == "ripple");
    CHECK(s.fields[1].params.at("center").at(0) == std::vector<double>{1, 2, 3});
    CHECK(s.fields[1].scale.interp() == KeyInterp::Step);
    CHECK(s.fields[1].mask == "smoothstep($P[1], 0, 2)");
    CHECK(s.fields[1].maskLine == 36);
    CHECK(s.fields[1].maskCol == 9);
    CHECK(s.fields[2].name == "field2");
    CHECK(s.fields[2].source == "[0, 1, 0]\n");
    CHECK(s.fields[2].sourceLine == 40);
    CHECK(s.fields[2].sourceCol == 1);

    // The summed field: 2 * 1.3 x + (step-scaled, masked ripple) + y.
    std::string report;
    FieldPtr f = buildSceneField(s, gale::runtime::Precision::Double, report);
    INFO(report);
    REQUIRE(f);
    Vec3 v = sampleAt(*f, {0, -1, 0}, 0.5); // ripple scale 0 before t = 1, mask 0 at y < 0
    CHECK(v[0] == Approx(2.6));
    CHECK(v[1] == Approx(1.0));
    CHECK(v[2] == Approx(0.0).margin(1e-12));
}

TEST_CASE("bad scenes: every error at its file:line:col", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, R"TOML([scene]
fps = -2
frames = [5, 1]
substepz = 3

[windicator]
direction = [0, 0]
speed = "fast"

[[gust]]
atack = 0.1
travel_speed = 0
strength = { keys = [[0, 1], [0, 2]] }

[[field]]
name = "a"
preset = "rippel"

[[field]]
name = "a"
source = "1"
scale = { keys = [[0, [1, 2]]] , interp = "cubic" }

[wind]
speed = 3
)TOML");
    CHECK_FALSE(l.ok);
    INFO(l.rendered());
    // In file order.
    REQUIRE(l.errors.size() == 13);
    CHECK(l.at(0) == "2:7: scene.fps must be positive");
    CHECK(l.at(1) == "3:10: scene.frames: the last frame (1) comes before the first (5)");
    CHECK(l.at(2) == "4:1: unknown key 'substepz' in [scene]");
    CHECK(l.errors[2].notes[0] == "did you mean 'substeps'?");
    CHECK(l.errors[2].sourceLine == "substepz = 3");
    CHECK(l.at(3) == "7:13: windicator.direction must be a vector of 3 numbers, not 2 numbers");
    CHECK(has(l.at(4), "8:9: windicator.speed must be a number or a keyframed curve"));
    CHECK(l.at(5) == "11:1: unknown key 'atack' in [[gust]]");
    CHECK(l.errors[5].notes[0] == "did you mean 'attack'?");
    CHECK(l.at(6) == "12:16: gust 0: travel_speed must be positive (m/s)");
    CHECK(l.at(7) == "13:30: gust 0: strength: two keys at time 0 (each key needs its own time)");
    CHECK(l.at(8) == "17:10: unknown preset 'rippel'");
    CHECK(l.errors[8].notes[0] == "did you mean 'ripple'?");
    CHECK(l.at(9) == "20:8: two fields are named 'a'");
    CHECK(has(l.at(10), "22:23: field 'a': scale: a key's value must be a number"));
    CHECK(has(l.at(11), "22:43: unknown interpolation 'cubic'"));
    CHECK(l.at(12) == "24:2: unknown scene section or key 'wind'");
    CHECK(has(l.rendered(), "scene.toml:4:1: error: unknown key 'substepz' in [scene]\n"
                            "    substepz = 3\n    ^\nnote: did you mean 'substeps'?\n"));
}

TEST_CASE("scene error rendering: line, caret and notes", "[scene]") {
    SceneError e;
    e.file = "s.toml";
    e.line = 3;
    e.col = 5;
    e.sourceLine = "\tab = 1";
    e.message = "bad";
    e.notes = {"did you mean 'ac'?"};
    CHECK(e.render() == "s.toml:3:5: error: bad\n    \tab = 1\n    \t   ^\nnote: did you mean 'ac'?");
    SceneError s;
    s.file = "--set x=1";
    s.message = "unknown";
    CHECK(s.render() == "--set x=1: error: unknown");
}

TEST_CASE("field parameters are checked against the expression's declarations", "[scene]") {
    TempDir dir;
    dir.write("w.se", "$speed = 5; # 0, 40\n$dir = [1, 0, 0];\n$dir * $speed\n");
    Loaded l = load(dir, R"TOML([[field]]
expr = "w.se"
params = { sped = 3, dir = [1, 2], speed = 2 }

[[field]]
expr = "missing.se"

[[field]]
preset = "wind"
params = { turbulance = 0.3 }
)TOML");
    CHECK_FALSE(l.ok);
    INFO(l.rendered());
    REQUIRE(l.errors.size() == 4);
    CHECK(l.at(0) == "3:12: 'sped' is not a parameter of " + (dir.path / "w.se").string());
    CHECK(l.errors[0].notes[0] == "did you mean 'speed'?");
    CHECK(l.errors[0].notes[1] == "its parameters: speed, dir");
    CHECK(has(l.at(1), "3:28: parameter 'dir' of "));
    CHECK(has(l.at(1), "is a vector of 3 numbers, not 2 numbers"));
    CHECK(has(l.at(2), "6:8: field 'field1': cannot read '"));
    CHECK(l.errors[2].io);
    CHECK(l.at(3) == "10:12: 'turbulance' is not a parameter of the wind preset");
    CHECK(l.errors[3].notes[0] == "did you mean 'turbulence'?");
}

TEST_CASE("scene: --set overrides keys by dotted path", "[scene]") {
    TempDir dir;
    const std::string text = R"TOML([scene]
fps = 24

[[gust]]
name = "big"
strength = 4

[[field]]
name = "main"
preset = "wind"
params = { spread = 3 }
)TOML";
    Loaded l = load(dir, text,
                    {"scene.fps=30", "windicator.direction=0,0,1", "windicator.speed=12",
                     "gust.big.start=1.5", "gust.0.travel_speed=2",
                     "field.main.params.spread={ keys = [[0, 1], [2, 5]] }",
                     "field.0.params.turbulence=0.1", "field.main.scale=0.5", "cloth.cape.drag=0.8",
                     "solver.max_halvings=4"});
    INFO(l.rendered());
    REQUIRE(l.ok);
    CHECK(l.scene.settings.fps == 30);
    REQUIRE(l.scene.windicator);
    CHECK(l.scene.windicator->direction.at(0) == std::vector<double>{0, 0, 1});
    CHECK(l.scene.windicator->speed.scalarAt(0) == 12);
    CHECK(l.scene.gusts[0].start == 1.5);
    CHECK(l.scene.gusts[0].travelSpeed == 2);
    CHECK(l.scene.fields[0].params.at("spread").scalarAt(1) == 3);
    CHECK(l.scene.fields[0].params.at("turbulence").scalarAt(0) == 0.1);
    CHECK(l.scene.fields[0].scale.scalarAt(0) == 0.5);

    Loaded bad = load(dir, text,
                      {"field.mian.params.speed=1", "windicator.sped=3", "scene.fps=fast", "nosuch",
                       "wnd.speed=2", "field.main.params.sped=1"});
    CHECK_FALSE(bad.ok);
    INFO(bad.rendered());
    REQUIRE(bad.errors.size() == 6);
    CHECK(bad.errors[0].render() ==
          "--set field.mian.params.speed=1: error: the scene has no [[field]] named 'mian'\n"
          "note: did you mean 'main'?\n"
          "note: it has 1 [[field]] entry (main); name one, or give its index from 0");
    CHECK(has(bad.errors[1].render(), "--set nosuch: error: expected KEY=VALUE"));
    CHECK(has(bad.errors[2].render(), "--set wnd.speed=2: error: unknown scene section 'wnd'"));
    CHECK(has(bad.errors[3].render(), "--set scene.fps=fast: error: scene.fps must be a number, not a string"));
    CHECK(has(bad.errors[4].render(), "--set windicator.sped=3: error: unknown key 'sped' in [windicator]"));
    CHECK(has(bad.errors[5].render(), "--set field.main.params.sped=1: error: 'sped' is not a parameter of the wind preset"));
}

TEST_CASE("a TOML syntax error and an unreadable scene", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, "[scene]\nfps = = 3\n");
    CHECK_FALSE(l.ok);
    REQUIRE(l.errors.size() == 1);
    CHECK(l.errors[0].line == 2);
    CHECK(l.errors[0].col > 0);
    CHECK_FALSE(l.errors[0].io);

    Scene s;
    std::vector<SceneError> errors;
    CHECK_FALSE(loadScene((dir.path / "nope.toml").string(), s, errors));
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].io);
    CHECK(has(errors[0].render(), "nope.toml: error: cannot read the scene: No such file"));
}

TEST_CASE("inline sources report errors at their place in the scene", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, "[[field]]\nname = \"x\"\nsource = '''\nv = [1, 0, 0];\nv * nosuch\n'''\n"
                         "mask = \"$P[0] + oops\"\n");
    INFO(l.rendered());
    REQUIRE(l.ok);
    std::string report;
    CHECK_FALSE(buildSceneField(l.scene, gale::runtime::Precision::Float, report));
    CHECK(has(report, "scene.toml:5:5: error: unknown variable 'nosuch'"));
    CHECK(has(report, "    v * nosuch\n"));
    CHECK(has(report, "scene.toml:7:17: error: unknown variable 'oops'"));
    INFO(report);
}

TEST_CASE("the wind preset follows the windicator and refuses its replaced parameters", "[scene]") {
    TempDir dir;
    Loaded l = load(dir, R"TOML([windicator]
direction = { keys = [[0, [1, 0, 0]], [1, [0, 0, 1]]], interp = "step" }
speed = { keys = [[0, 2], [2, 6]] }

[[field]]
preset = "wind"
)TOML");
    INFO(l.rendered());
    REQUIRE(l.ok);
    std::string report;
    FieldPtr f = buildSceneField(l.scene, gale::runtime::Precision::Double, report);
    INFO(report);
    REQUIRE(f);
    // The field keeps no pointer into the scene: build it from a copy that is then destroyed.
    {
        auto copy = std::make_unique<Scene>(l.scene);
        f = buildSceneField(*copy, gale::runtime::Precision::Double, report);
        copy->windicator->speed = Param(1e9);
        copy.reset();
    }
    REQUIRE(f);
    Vec3 a = sampleAt(*f, {0, 0, 0}, 0.5), b = sampleAt(*f, {0, 0, 0}, 1.5);
    CHECK(a[0] == Approx(3.0));
    CHECK(a[2] == Approx(0.0).margin(1e-12));
    CHECK(b[0] == Approx(0.0).margin(1e-12));
    CHECK(b[2] == Approx(5.0));

    Loaded r = load(dir, "[windicator]\nspeed = 3\n[[field]]\npreset = \"wind\"\nparams = { speed = 8 }\n");
    CHECK_FALSE(r.ok);
    REQUIRE(r.errors.size() == 1);
    CHECK(has(r.at(0), "5:12: with a [windicator], the wind preset's 'speed' comes from it"));
}
