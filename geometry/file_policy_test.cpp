// Tests of the file policy for names in expressions: relative names inside the folder resolve,
// `..` out of it, absolute paths and symbolic links leading out are refused unless the folder
// is allowed (--allow-path); `#` sequences are found with their padding; frame picking.
#include "geometry/file_policy.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace gale::geometry;
namespace fs = std::filesystem;

namespace {

struct TempTree {
    fs::path root;
    TempTree() {
        static int n = 0;
        root = fs::canonical(fs::temp_directory_path()) /
               ("gale_paths_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
        fs::create_directories(root / "shot" / "meshes");
        fs::create_directories(root / "outside");
        touch("shot/body.obj");
        touch("shot/meshes/cape.obj");
        touch("outside/secret.obj");
    }
    ~TempTree() {
        std::error_code ec;
        fs::remove_all(root, ec);
    }
    void touch(const std::string& rel) const {
        std::ofstream((root / rel).string()) << "v 0 0 0\n";
    }
    std::string str(const std::string& rel) const { return (root / rel).string(); }
};

bool ok(const FileAccess& a, const std::string& name, FileRef* out = nullptr) {
    FileRef ref;
    std::string error;
    const bool r = findFiles(a, name, ref, error);
    INFO(name << ": " << error);
    if (out) *out = ref;
    return r;
}

std::string errorOf(const FileAccess& a, const std::string& name) {
    FileRef ref;
    std::string error;
    CHECK_FALSE(findFiles(a, name, ref, error));
    return error;
}

} // namespace

TEST_CASE("names resolve inside the folder of the expression", "[geometry][paths]") {
    TempTree t;
    const FileAccess a = fileAccessFor(t.str("shot/wind.se"));
    FileRef ref;
    REQUIRE(ok(a, "body.obj", &ref));
    CHECK(ref.frames.size() == 1);
    CHECK(ref.frames[0].path == t.str("shot/body.obj"));
    CHECK_FALSE(ref.sequence);
    CHECK(ok(a, "meshes/cape.obj"));
    CHECK(ok(a, "meshes/../body.obj")); // `..` that stays inside is fine
    CHECK(ok(a, "./meshes/cape.obj"));
}

TEST_CASE("`..` out of the folder, absolute paths and symbolic links out are refused",
          "[geometry][paths]") {
    TempTree t;
    const FileAccess a = fileAccessFor(t.str("shot/wind.se"));
    std::string e = errorOf(a, "../outside/secret.obj");
    CHECK(e.find("'../outside/secret.obj' leads outside " + t.str("shot")) != std::string::npos);
    CHECK(e.find("--allow-path") != std::string::npos);
    e = errorOf(a, t.str("shot/body.obj"));
    CHECK(e.find("is an absolute path") != std::string::npos);
    CHECK(e.find("--allow-path") != std::string::npos);
    fs::create_symlink(t.root / "outside" / "secret.obj", t.root / "shot" / "link.obj");
    e = errorOf(a, "link.obj");
    CHECK(e.find("leads outside") != std::string::npos);
    CHECK(e.find("secret.obj") != std::string::npos);
    fs::create_directory_symlink(t.root / "outside", t.root / "shot" / "linkdir");
    CHECK(errorOf(a, "linkdir/secret.obj").find("leads outside") != std::string::npos);
    // A link that stays inside is fine.
    fs::create_symlink(t.root / "shot" / "body.obj", t.root / "shot" / "alias.obj");
    CHECK(ok(a, "alias.obj"));
    // Missing files and folders.
    CHECK(errorOf(a, "nothere.obj").find("cannot read 'nothere.obj'") != std::string::npos);
    CHECK(errorOf(a, "meshes").find("folder") != std::string::npos);
    CHECK(errorOf(a, "").find("empty") != std::string::npos);
}

TEST_CASE("allowed folders (--allow-path) open the way out", "[geometry][paths]") {
    TempTree t;
    const FileAccess a = fileAccessFor(t.str("shot/wind.se"), {t.str("outside")});
    CHECK(ok(a, "../outside/secret.obj"));
    CHECK(ok(a, t.str("outside/secret.obj")));
    fs::create_symlink(t.root / "outside" / "secret.obj", t.root / "shot" / "link.obj");
    CHECK(ok(a, "link.obj"));
    // Allowing one folder does not allow absolute paths elsewhere (even the expression's own).
    CHECK(errorOf(a, t.str("shot/body.obj")).find("absolute") != std::string::npos);
    // A relative --allow-path is relative to the current folder.
    const fs::path cwd = fs::current_path();
    fs::current_path(t.root);
    const FileAccess rel = fileAccessFor(t.str("shot/wind.se"), {"outside"});
    CHECK(ok(rel, "../outside/secret.obj"));
    fs::current_path(cwd);
}

TEST_CASE("the root may be wider than the folder names resolve against", "[geometry][paths]") {
    TempTree t;
    // An expression file in shot/meshes/ of a scene in shot/: names resolve in meshes/ but may
    // reach anywhere in shot/.
    FileAccess a = fileAccessFor(t.str("shot/meshes/field.se"));
    a.rootDir = t.str("shot");
    CHECK(ok(a, "cape.obj"));
    CHECK(ok(a, "../body.obj"));
    CHECK(errorOf(a, "../../outside/secret.obj").find("leads outside " + t.str("shot")) !=
          std::string::npos);
    // An expression file outside the scene's folder (a wedge variant names the original by
    // its absolute path): its own folder stays a root.
    FileAccess moved = fileAccessFor(t.str("outside/field.se"));
    moved.rootDir = t.str("shot/meshes");
    CHECK(ok(moved, "secret.obj"));
    CHECK(ok(moved, "../shot/meshes/cape.obj"));
    CHECK(errorOf(moved, "../shot/body.obj")
              .find("leads outside " + t.str("shot/meshes") + " and " + t.str("outside")) !=
          std::string::npos);
}

TEST_CASE("`#` sequences: frames found with their padding, picked by frame", "[geometry][paths]") {
    TempTree t;
    for (const char* f : {"shot/wind.0003.vdb", "shot/wind.0001.vdb", "shot/wind.0006.vdb",
                          "shot/wind.12.vdb", "shot/wind.-0002.vdb", "shot/wind.0004.vdb.bak"})
        t.touch(f);
    const FileAccess a = fileAccessFor(t.str("shot/scene.toml"));
    FileRef ref;
    REQUIRE(ok(a, "wind.#.vdb", &ref));
    CHECK(ref.sequence);
    REQUIRE(ref.frames.size() == 4); // -2, 1, 3, 6 (not the 2-digit "12", not the .bak)
    CHECK(ref.frames[0].frame == -2);
    CHECK(ref.frames[1].frame == 1);
    CHECK(ref.frames[3].frame == 6);
    CHECK(ref.frames[2].path == t.str("shot/wind.0003.vdb"));
    FileRef two;
    REQUIRE(ok(a, "wind.##.vdb", &two));
    REQUIRE(two.frames.size() == 1);
    CHECK(two.frames[0].frame == 12);

    CHECK(nearestFrame(ref, -10).frame == -2); // held before the first
    CHECK(nearestFrame(ref, 100).frame == 6);  // and after the last
    CHECK(nearestFrame(ref, 4.4).frame == 3);
    CHECK(nearestFrame(ref, 4.6).frame == 6);
    size_t i = 9, j = 9;
    double w = -1;
    bracketFrames(ref, 2.0, i, j, w);
    CHECK(ref.frames[i].frame == 1);
    CHECK(ref.frames[j].frame == 3);
    CHECK(w == Approx(0.5));
    bracketFrames(ref, 3.0, i, j, w);
    CHECK(i == j);
    CHECK(ref.frames[i].frame == 3);
    CHECK(w == 0.0);
    bracketFrames(ref, 7.0, i, j, w);
    CHECK(ref.frames[i].frame == 6);
    CHECK(i == j);

    CHECK(errorOf(a, "gust.#.vdb").find("no files of the sequence 'gust.#.vdb'") !=
          std::string::npos);
    CHECK(errorOf(a, "a.#.#.vdb").find("more than one frame number") != std::string::npos);
    // A frame that is a link out of the folder is refused.
    fs::create_symlink(t.root / "outside" / "secret.obj", t.root / "shot" / "wind.0009.vdb");
    CHECK(errorOf(a, "wind.#.vdb").find("leads outside") != std::string::npos);
}

TEST_CASE("a rewritten file gets a new cache key", "[geometry][paths]") {
    TempTree t;
    const FileAccess a = fileAccessFor(t.str("shot/wind.se"));
    FileRef before, after;
    REQUIRE(ok(a, "body.obj", &before));
    std::ofstream(t.str("shot/body.obj"), std::ios::app) << "v 1 1 1\n";
    REQUIRE(ok(a, "body.obj", &after));
    CHECK(before.frames[0].key != after.frames[0].key);
}
