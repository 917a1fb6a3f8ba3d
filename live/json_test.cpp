// Tests of the live page's JSON: the state of a scene on disk (files, parameters at the literal
// holding their effective value, ramps, diagnostics at file:line:col) and the field view's
// sizes and rounding.
#include "live/json.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace gale;
namespace fs = std::filesystem;

namespace {

struct TempDir {
    fs::path path;
    TempDir() {
        char tmpl[] = "/tmp/gale_live_json_XXXXXX";
        path = mkdtemp(tmpl);
    }
    ~TempDir() { fs::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream((path / name).string()) << text;
        return (path / name).string();
    }
};

} // namespace

TEST_CASE("the state of a scene: files, params, ramps", "[live][json]") {
    TempDir dir;
    const std::string se =
        dir.write("w.se", "$gain = 2; # 0, 4\n$tilt = 0.5; # -1, 1\n"
                          "[1, 0, 0] * $gain * curve($P[0], 0,0,1, 1,1,1) + [0, $tilt, 0]\n");
    const std::string toml = dir.write("scene.toml", "[scene]\nfps = 30\nframes = [1, 10]\n\n"
                                                     "[[field]]\nname = \"main\"\nexpr = \"w.se\"\n"
                                                     "params = { tilt = 0.25 }\n");
    live::Project p(toml);
    REQUIRE(p.load());
    const nlohmann::json s = live::stateJson(p, 0.5);
    CHECK(s["ok"] == true);
    CHECK(s["fps"] == 30.0);
    CHECK(s["frames"] == nlohmann::json::array({1, 10}));
    CHECK(s["time"] == 0.5);
    CHECK(s["files"] == nlohmann::json::array({toml, se}));
    REQUIRE(s["params"].size() == 2);
    const nlohmann::json& gain = s["params"][0];
    CHECK(gain["name"] == "gain");
    CHECK(gain["value"] == 2.0);
    CHECK(gain["min"] == 0.0);
    CHECK(gain["max"] == 4.0);
    CHECK(gain["file"] == se);
    CHECK(gain["line"] == 1);
    CHECK(gain["integer"] == true);
    // tilt's effective value is the scene's override, on line 8 of the scene.
    const nlohmann::json& tilt = s["params"][1];
    CHECK(tilt["value"] == 0.25);
    CHECK(tilt["file"] == toml);
    CHECK(tilt["line"] == 8);
    CHECK(tilt["editable"] == true);
    REQUIRE(s["ramps"].size() == 1);
    CHECK(s["ramps"][0]["points"].size() == 2);
    CHECK(s["diagnostics"].empty());

    // Setting tilt rewrites the scene's literal; the expression file is untouched.
    std::string error;
    const std::string seBefore = [&] {
        std::ifstream in(se);
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    REQUIRE(p.setParam("tilt", "", {-0.75}, error));
    std::ifstream in(toml);
    const std::string after((std::istreambuf_iterator<char>(in)), {});
    CHECK(after.find("params = { tilt = -0.75 }\n") != std::string::npos);
    std::ifstream in2(se);
    CHECK(std::string(std::istreambuf_iterator<char>(in2), {}) == seBefore);
    REQUIRE(p.load());
    CHECK(live::stateJson(p, 0)["params"][1]["value"] == -0.75);
}

TEST_CASE("diagnostics carry file, line, column and gale check's message", "[live][json]") {
    TempDir dir;
    const std::string se = dir.write("bad.se", "$a = 1;\nx = 2 +;\n[x, 0, 0]\n");
    live::Project p(se);
    CHECK_FALSE(p.load());
    const nlohmann::json s = live::stateJson(p, 0);
    CHECK(s["ok"] == false);
    REQUIRE(!s["diagnostics"].empty());
    const nlohmann::json& d = s["diagnostics"][0];
    CHECK(d["file"] == se);
    CHECK(d["line"] == 2);
    CHECK(d["col"] == 8);
    CHECK(d["severity"] == "error");
    // The rendering starts with file:line:col: error: message, as gale check prints it.
    const std::string head = se + ":2:8: error: " + d["message"].get<std::string>();
    CHECK(d["text"].get<std::string>().rfind(head, 0) == 0);
    CHECK(s["params"].size() == 1); // parameters need only tokens
}

TEST_CASE("a field view's JSON: sizes and values", "[live][json]") {
    const fields::FieldPtr wind = fields::uniformField({3.0, 0.0, 4.0});
    live::FieldRequest r;
    r.res = 16;
    r.arrows = 4;
    r.rake.count = 8;
    r.rake.a = {-0.9, -0.5, 0};
    r.rake.b = {-0.9, 0.5, 0};
    viz::Box3 box;
    box.lo = {-1, -1, -1};
    box.hi = {1, 1, 1};
    live::FieldFrame f;
    std::string error;
    REQUIRE(live::computeFieldFrame(*wind, 24, box, r, f, error));
    const nlohmann::json j = live::fieldJson(f, {});
    CHECK(j["slice"]["nu"] == 16);
    CHECK(j["slice"]["nv"] == 16);
    REQUIRE(j["slice"]["speed"].size() == 256);
    for (const auto& s : j["slice"]["speed"]) CHECK(s.get<double>() == 5.0);
    CHECK(j["slice"]["max"] == 5.0);
    CHECK(j["slice"]["top"] == 5.0); // niceCeil(5)
    CHECK(j["slice"]["colormap"].size() == 33);
    CHECK(j["arrows"]["positions"].size() == 3 * 64);
    CHECK(j["arrows"]["velocities"][0] == 3.0);
    CHECK(j["arrows"]["velocities"][2] == 4.0);
    REQUIRE(j["streamlines"].size() == 8);
    // Rounded to 1e-4: every coordinate is a multiple of it.
    for (const auto& c : j["streamlines"][0]["points"]) {
        const double v = c.get<double>() * 1e4;
        CHECK(std::fabs(v - std::round(v)) < 1e-6);
    }
    CHECK_FALSE(j["overlays"]["windicator"]["present"].get<bool>());

    r.res = 4;
    CHECK_FALSE(live::computeFieldFrame(*wind, 24, box, r, f, error));
    CHECK(error.find("res") != std::string::npos);
}

TEST_CASE("bytes that are not UTF-8 in a source line do not break the JSON", "[live][json]") {
    TempDir dir;
    // A Latin-1 comment (0xE9) on the line of a syntax error: the diagnostic's text holds it.
    const std::string se = dir.write("latin.se", "x = 2 +; # caf\xe9\n[x, 0, 0]\n");
    live::Project p(se);
    CHECK_FALSE(p.load());
    std::string text;
    REQUIRE_NOTHROW(text = live::jsonText(live::stateJson(p, 0)));
    CHECK(text.find("caf\xef\xbf\xbd") != std::string::npos); // U+FFFD in its place
    const nlohmann::json back = nlohmann::json::parse(text);
    CHECK(back["diagnostics"][0]["line"] == 1);
}
