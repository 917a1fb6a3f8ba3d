// The scene document: --set applied as the loader applies it (a written variant loads to the
// same scene as the original loaded with the same overrides), file keys made absolute so the
// written scene runs from another folder, literals located byte-exactly, named files found.
#include "scene/document.h"

#include "io/test_support.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

using namespace gale::scene;
using gale::io::test::TempDir;
namespace fs = std::filesystem;

namespace {

const char* kScene = R"([scene]
fps = 24
frames = [1, 4]

[[field]]
name = "breeze"
expr = "wind.se"
params = { speed = 3.5, gust = [1, 0, 0] }

[[cloth]]
name = "cape"
mesh = "meshes/cape.obj"
rest_mesh = "meshes/cape.obj"
drag = 1.0
lift = { expr = "lift.se" }
attach = { mesh = "meshes/body.obj", box = [-1, 0.9, -1, 1, 1.1, 1] }

[[collider]]
name = "ground"
type = "plane"
point = [0, -1, 0]
normal = [0, 1, 0]
)";

// A 2×2-quad sheet at y ∈ [0, 1] and a body triangle pair under its top row.
const char* kCape = "v -0.5 1 0\nv 0 1 0\nv 0.5 1 0\nv -0.5 0.5 0\nv 0 0.5 0\nv 0.5 0.5 0\n"
                    "f 1 2 5 4\nf 2 3 6 5\n";
const char* kBody = "v -1 1 -0.01\nv 1 1 -0.01\nv 0 1.05 -0.2\nf 1 2 3\n";

struct Fixture {
    TempDir dir;
    std::string scene;
    Fixture() {
        dir.write("wind.se", "$speed = 2; # 0, 10\n$gust = [1, 0, 0];\n$gust * $speed\n");
        dir.write("lift.se", "0.5\n");
        dir.write("meshes/cape.obj", kCape);
        dir.write("meshes/body.obj", kBody);
        scene = dir.write("scene.toml", kScene);
    }
};

std::string rendered(const std::vector<SceneError>& errors) {
    std::string s;
    for (const SceneError& e : errors) s += e.render() + "\n";
    return s;
}

} // namespace

TEST_CASE("scene document: a written variant loads like the original with the same --set",
          "[scene][document]") {
    Fixture f;
    const std::vector<std::string> sets = {"cloth.cape.drag=0.8", "field.breeze.params.speed=7",
                                           "scene.frames=[2, 3]", "collider.0.friction=0.1"};
    SceneDocument doc;
    std::vector<SceneError> errors;
    REQUIRE(doc.read(f.scene, errors));
    REQUIRE(doc.applySets(sets, errors));
    doc.absolutisePaths();
    // The variant lives in another folder: every file it names must still be found.
    const std::string variant = f.dir.write("variants/v000/scene.toml", doc.write("variant v000"));

    SimScene original, written;
    const bool loadedOriginal = loadSimScene(f.scene, original, errors, sets);
    const bool loadedWritten = loadedOriginal && loadSimScene(variant, written, errors);
    INFO(rendered(errors));
    REQUIRE(loadedOriginal);
    REQUIRE(loadedWritten);
    REQUIRE(errors.empty());
    REQUIRE(written.cloths.size() == 1);
    CHECK(written.cloths[0].drag.value.scalarAt(0.0) ==
          original.cloths[0].drag.value.scalarAt(0.0));
    CHECK(written.cloths[0].drag.value.scalarAt(0.0) == 0.8);
    CHECK(written.cloths[0].meshPath == original.cloths[0].meshPath);
    CHECK(written.cloths[0].restMeshPath == original.cloths[0].restMeshPath);
    CHECK(written.cloths[0].attachMesh == original.cloths[0].attachMesh);
    CHECK(written.cloths[0].lift.exprPath == original.cloths[0].lift.exprPath);
    CHECK(written.wind.fields[0].exprPath == original.wind.fields[0].exprPath);
    CHECK(written.wind.fields[0].params.at("speed").scalarAt(0.0) == 7.0);
    CHECK(written.wind.settings.frameStart == 2);
    CHECK(written.wind.settings.frameEnd == 3);
    CHECK(written.colliders[0].friction == original.colliders[0].friction);
    // The header is comment lines; the file itself was not changed by the document.
    CHECK(doc.write("a\nb").rfind("# a\n# b\n", 0) == 0);
    CHECK(doc.text() == kScene);
}

TEST_CASE("scene document: an override that cannot be applied is an error naming it",
          "[scene][document]") {
    Fixture f;
    SceneDocument doc;
    std::vector<SceneError> errors;
    REQUIRE(doc.read(f.scene, errors));
    CHECK_FALSE(doc.applySets({"cloth.cap.drag=0.8"}, errors));
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].message.find("no [[cloth]] named 'cap'") != std::string::npos);
    CHECK(rendered(errors).find("did you mean 'cape'") != std::string::npos);
    errors.clear();
    CHECK_FALSE(doc.applySets({"wind.speed=3"}, errors));
    CHECK(rendered(errors).find("unknown scene section 'wind'") != std::string::npos);
    errors.clear();
    CHECK_FALSE(doc.read(f.dir.file("missing.toml"), errors));
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].io);
    errors.clear();
    CHECK_FALSE(doc.parse(f.dir.file("bad.toml"), "[scene\nfps = 24\n", errors));
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].line == 1);
}

TEST_CASE("scene document: parameter literals and named files", "[scene][document]") {
    Fixture f;
    SceneDocument doc;
    std::vector<SceneError> errors;
    REQUIRE(doc.read(f.scene, errors));
    const std::string text = doc.text();
    const auto speed = doc.fieldParamLiteral(0, "speed");
    REQUIRE(speed);
    CHECK(text.substr(speed->begin, speed->end - speed->begin) == "3.5");
    // Line and column of the literal, counted in the text independently.
    const size_t lineStart = text.rfind('\n', speed->begin) + 1;
    CHECK(speed->col == static_cast<int>(speed->begin - lineStart) + 1);
    CHECK(speed->line ==
          1 + static_cast<int>(std::count(text.begin(), text.begin() + speed->begin, '\n')));
    const auto gust = doc.fieldParamLiteral(0, "gust");
    REQUIRE(gust);
    CHECK(text.substr(gust->begin, gust->end - gust->begin) == "[1, 0, 0]");
    CHECK_FALSE(doc.fieldParamLiteral(0, "nothing"));
    CHECK_FALSE(doc.fieldParamLiteral(3, "speed"));
    CHECK(doc.colliderMesh(0).empty());
    CHECK(doc.colliderMesh(5).empty());

    // Each existing file once per mention; names that are not files ("breeze", "plane") are not.
    std::vector<std::string> files = doc.namedFiles();
    for (std::string& p : files) p = fs::path(p).lexically_normal().string();
    std::sort(files.begin(), files.end());
    const std::string d = f.dir.path.string() + "/";
    CHECK(files == std::vector<std::string>{d + "lift.se", d + "meshes/body.obj",
                                            d + "meshes/cape.obj", d + "meshes/cape.obj",
                                            d + "wind.se"});
    // The other strings, as paths beside the scene: none of them an existing file.
    for (const std::string& p : doc.otherPaths()) {
        CHECK(p.rfind(d, 0) == 0);
        CHECK(std::find(files.begin(), files.end(), p) == files.end());
    }
    const std::vector<std::string> other = doc.otherPaths();
    CHECK(std::find(other.begin(), other.end(), d + "breeze") != other.end());
}

TEST_CASE("scene document: one key for both spellings of a --set", "[scene][document]") {
    Fixture f;
    SceneDocument doc;
    std::vector<SceneError> errors;
    REQUIRE(doc.read(f.scene, errors));
    // By name and by index: the same entry, whatever the value.
    CHECK(doc.canonicalSetKey("cloth.cape.drag=0.8") == doc.canonicalSetKey("cloth.0.drag=1"));
    CHECK(doc.canonicalSetKey("field.breeze.params.speed=7") == "field.0.params.speed");
    CHECK(doc.canonicalSetKey(" collider.ground.friction = 0.1") == "collider.0.friction");
    // Different entries, keys or sections stay apart; what the scene does not name is kept.
    CHECK(doc.canonicalSetKey("cloth.cape.drag=1") != doc.canonicalSetKey("cloth.cape.lift=1"));
    CHECK(doc.canonicalSetKey("cloth.nobody.drag=1") == "cloth.nobody.drag");
    CHECK(doc.canonicalSetKey("cloth.1.drag=1") == "cloth.1.drag");
    CHECK(doc.canonicalSetKey("scene.fps=30") == "scene.fps");
    CHECK(doc.canonicalSetKey("windicator.speed=3") == "windicator.speed");
}
