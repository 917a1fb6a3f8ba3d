// The background `gale sim` of the live page (sim_job.h): posix_spawn, frame polling, stop.
#include "live/sim_job.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace gale::live {

namespace fs = std::filesystem;

std::string simFramePath(const std::string& dir, const std::string& name, long frame,
                         const std::string& format) {
    char buf[32];
    std::snprintf(buf, sizeof buf, ".%04ld.", frame);
    return (fs::path(dir) / (name + buf + format)).string();
}

SimJob::SimJob(std::function<void(long)> onFrame,
               std::function<void(int, const std::string&)> onExit)
    : mOnFrame(std::move(onFrame)), mOnExit(std::move(onExit)) {}

SimJob::~SimJob() {
    stop();
}

std::string SimJob::outDir() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mOutDir;
}

bool SimJob::start(const std::string& gale, const std::string& scene, const std::string& outDir,
                   const std::vector<SimObject>& objects, long firstFrame, long lastFrame,
                   std::string& error) {
    stop(true);
    std::error_code ec;
    fs::create_directories(outDir, ec);
    if (ec) {
        error = outDir + ": cannot create: " + ec.message();
        return false;
    }
    const std::string log = (fs::path(outDir) / "sim.log").string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    std::vector<std::string> args = {gale, "sim", scene, "-o", outDir, "--threads", "1"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    // The child starts with no signals blocked and default handlers (the server may block
    // SIGINT/SIGTERM to wait for them on one thread).
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &all);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, gale.c_str(), &actions, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    if (rc != 0) {
        error = "cannot run " + gale + ": " + std::strerror(rc);
        return false;
    }
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mPid = pid;
        mOutDir = outDir;
        mObjects = objects;
        mFirst = firstFrame;
        mEnd = lastFrame;
        mLast = firstFrame - 1;
    }
    mStopping = false;
    mRunning = true;
    mThread = std::thread([this] { run(); });
    return true;
}

void SimJob::run() {
    int status = 0;
    bool exited = false;
    auto poll = [&] {
        for (long f = mLast + 1; f <= mEnd; ++f) {
            bool all = !mObjects.empty();
            for (const SimObject& o : mObjects) {
                std::error_code ec;
                all = all && fs::exists(simFramePath(mOutDir, o.name, f, o.format), ec);
            }
            if (!all) break;
            mLast = f;
            mOnFrame(f);
        }
    };
    while (!exited) {
        const pid_t r = ::waitpid(mPid, &status, WNOHANG);
        exited = r == mPid || (r < 0 && errno != EINTR);
        if (!mStopping) poll();
        if (!exited)
            std::this_thread::sleep_for(
                std::chrono::milliseconds(10)); // (frames seen within 10 ms)
    }
    if (!mStopping) poll();
    std::string tail;
    {
        std::ifstream in(fs::path(mOutDir) / "sim.log");
        std::ostringstream s;
        s << in.rdbuf();
        tail = s.str();
        if (tail.size() > 4000) tail = tail.substr(tail.size() - 4000);
    }
    const int code = mStopping           ? -1
                     : WIFEXITED(status) ? WEXITSTATUS(status)
                                         : 128 + WTERMSIG(status);
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mPid = -1;
    }
    mRunning = false;
    mOnExit(code, tail);
}

void SimJob::stop(bool now) {
    pid_t pid;
    {
        std::lock_guard<std::mutex> lock(mMutex);
        pid = mPid;
    }
    if (pid > 0) {
        mStopping = true;
        ::kill(pid, now ? SIGKILL : SIGTERM);
        for (int i = 0; i < 100 && mRunning; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        std::lock_guard<std::mutex> lock(mMutex);
        if (mPid > 0) ::kill(mPid, SIGKILL);
    }
    if (mThread.joinable()) mThread.join();
}

} // namespace gale::live
