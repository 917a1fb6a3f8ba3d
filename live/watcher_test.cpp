// FileWatcher on a scratch folder: a pattern in a folder that does not exist yet is waited for
// at the nearest existing parent and watched once the folder appears; files matching it are
// reported; a folder removed and made again is picked up again.
#include "live/watcher.h"

#include <catch2/catch.hpp>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;
using gale::live::FileWatcher;

namespace {

struct Changes {
    std::mutex m;
    std::condition_variable cv;
    std::set<std::string> seen;
    void add(const std::set<std::string>& c) {
        std::lock_guard<std::mutex> lock(m);
        seen.insert(c.begin(), c.end());
        cv.notify_all();
    }
    // Waits up to `ms` until every path in `paths` has been reported (in one report or
    // several); clears what was seen.
    bool waitFor(const std::set<std::string>& paths, int ms) {
        std::unique_lock<std::mutex> lock(m);
        const bool ok = cv.wait_for(lock, std::chrono::milliseconds(ms), [&] {
            for (const std::string& p : paths)
                if (!seen.count(p)) return false;
            return true;
        });
        seen.clear();
        return ok;
    }
    bool waitFor(const std::string& path, int ms) {
        return waitFor(std::set<std::string>{path}, ms);
    }
};

void write(const fs::path& p, const std::string& text) {
    std::ofstream(p) << text;
}

} // namespace

TEST_CASE("watcher: a missing folder is picked up when it appears, and again after removal") {
    const fs::path root = fs::temp_directory_path() / ("gale_watch_" + std::to_string(::getpid()));
    fs::remove_all(root);
    fs::create_directories(root);
    Changes changes;
    FileWatcher w([&](const std::set<std::string>& c) { changes.add(c); }, 10);
    std::string error;
    REQUIRE(w.start(error));
    const fs::path body = root / "a" / "body";
    w.watch({(root / "scene.toml").string()}, {(body / "body.#.obj").string()});
    // Waiting at the nearest existing parent: root (which also holds scene.toml).
    CHECK(w.watchedFolders() == std::set<std::string>{root.string()});

    fs::create_directories(body); // two levels at once
    write(body / "body.0001.obj", "v 0 0 0\n");
    // The new folder is reported, and the file written in it, whether it was written before the
    // folder's watch was added (found by listing the folder) or after (its own event).
    CHECK(changes.waitFor({(root / "a").string(), (body / "body.0001.obj").string()}, 2000));
    CHECK(w.watchedFolders().count(body.string()) == 1);
    write(body / "body.0002.obj", "v 0 0 0\n");
    CHECK(changes.waitFor((body / "body.0002.obj").string(), 2000));
    write(body / "notes.txt", "x"); // not a frame of the sequence
    write(root / "scene.toml", "[scene]\n");
    CHECK(changes.waitFor((root / "scene.toml").string(), 2000));
    // (notes.txt was not reported along with it)
    write(body / "notes.txt", "y");
    CHECK_FALSE(changes.waitFor((body / "notes.txt").string(), 200));

    fs::remove_all(root / "a");
    CHECK(changes.waitFor(body.string(), 2000));
    CHECK(w.watchedFolders().count(body.string()) == 0);
    fs::create_directories(body);
    write(body / "body.0003.obj", "v 0 0 0\n");
    CHECK(changes.waitFor({(root / "a").string(), (body / "body.0003.obj").string()}, 2000));
    w.stop();
    fs::remove_all(root);
}

TEST_CASE("watcher: a folder moved into place is reported with the frames already in it") {
    // A cache writer that fills a temporary folder and renames it into place: no event is ever
    // made for the files inside, so the watcher finds them by listing the folder it now watches.
    const fs::path root =
        fs::temp_directory_path() / ("gale_watch_move_" + std::to_string(::getpid()));
    fs::remove_all(root);
    fs::create_directories(root / "tmp");
    write(root / "tmp" / "body.1001.obj", "v 0 0 0\n");
    write(root / "tmp" / "body.1002.obj", "v 0 0 0\n");
    write(root / "tmp" / "notes.txt", "x");
    Changes changes;
    FileWatcher w([&](const std::set<std::string>& c) { changes.add(c); }, 10);
    std::string error;
    REQUIRE(w.start(error));
    const fs::path body = root / "cache";
    w.watch({}, {(body / "body.#.obj").string()});
    CHECK(w.watchedFolders() == std::set<std::string>{root.string()});
    fs::rename(root / "tmp", body);
    CHECK(changes.waitFor(
        {body.string(), (body / "body.1001.obj").string(), (body / "body.1002.obj").string()},
        2000));
    CHECK(w.watchedFolders().count(body.string()) == 1);
    // notes.txt matches no pattern: nothing more is reported.
    CHECK_FALSE(changes.waitFor((body / "notes.txt").string(), 200));
    w.stop();
    fs::remove_all(root);
}
