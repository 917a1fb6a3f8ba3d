// Tests for removeStaleTempFiles: temporary files of killed writers (dead or zombie pids) are
// removed, those of running processes and names the caller does not own are kept.
#include "io/atomic_file.h"
#include "io/test_support.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

using namespace gale::io;
namespace fs = std::filesystem;

namespace {

struct TempDir : test::TempDir {
    void touch(const std::string& name) const { std::ofstream(path / name) << "half"; }
    bool has(const std::string& name) const { return fs::exists(path / name); }
};

// A child that exits at once: when `reap`, its pid no longer exists; else it stays a zombie
// until `collect` is called.
pid_t exitedChild(bool reap) {
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(0);
    if (reap) {
        int status = 0;
        ::waitpid(pid, &status, 0);
    } else {
        // Wait (without collecting it) until the kernel has made it a zombie.
        for (int i = 0; i < 2000; ++i) {
            std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
            std::string text;
            std::getline(stat, text);
            const size_t paren = text.rfind(')');
            if (paren != std::string::npos && paren + 2 < text.size() && text[paren + 2] == 'Z')
                break;
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    }
    return pid;
}

} // namespace

TEST_CASE("stale temporary files of killed writers are removed", "[atomic]") {
    TempDir dir;
    const pid_t dead = exitedChild(true);
    const pid_t zombie = exitedChild(false);
    const std::string self = std::to_string(::getpid());
    const std::string parent = std::to_string(::getppid()); // runs: the test's parent
    dir.touch("cape.0003.obj.tmp." + std::to_string(dead));
    dir.touch("cape.0004.obj.tmp." + std::to_string(zombie));
    dir.touch("cape.0005.obj.tmp." + self);
    dir.touch("cape.0006.obj.tmp." + parent);
    dir.touch("notes.txt.tmp." + std::to_string(dead)); // not ours
    dir.touch("cape.0007.obj.tmp.x12");                 // not a pid
    dir.touch("cape.0008.obj");                         // a frame

    std::vector<std::string> asked;
    const std::vector<std::string> removed =
        removeStaleTempFiles(dir.path.string(), [&](const std::string& target) {
            asked.push_back(target);
            return target.rfind("cape.", 0) == 0;
        });
    int status = 0;
    ::waitpid(zombie, &status, 0);

    CHECK(removed.size() == 2);
    CHECK_FALSE(dir.has("cape.0003.obj.tmp." + std::to_string(dead)));
    CHECK_FALSE(dir.has("cape.0004.obj.tmp." + std::to_string(zombie)));
    CHECK(dir.has("cape.0005.obj.tmp." + self));
    CHECK(dir.has("cape.0006.obj.tmp." + parent));
    CHECK(dir.has("notes.txt.tmp." + std::to_string(dead)));
    CHECK(dir.has("cape.0007.obj.tmp.x12"));
    CHECK(dir.has("cape.0008.obj"));
    // The caller is asked about the target names of dead writers only.
    std::sort(asked.begin(), asked.end());
    CHECK(asked == std::vector<std::string>{"cape.0003.obj", "cape.0004.obj", "notes.txt"});
}

TEST_CASE("a missing folder has no stale files", "[atomic]") {
    CHECK(removeStaleTempFiles("/nonexistent/gale/folder", [](const std::string&) {
              return true;
          }).empty());
}
