// "Simulate" on the live page: `gale sim SCENE -o OUTDIR` run as a child process this server
// owns (stopped on request and on shutdown), with its frames reported as they appear (gale sim
// writes each frame file through a rename, so a file that exists is complete).
#pragma once

#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <sys/types.h>
#include <thread>
#include <utility>
#include <vector>

namespace gale::live {

struct SimObject {
    std::string name;
    std::string format; // obj | ply
};

class SimJob {
public:
    // `onFrame(frame)` for each frame whose every object's file exists, in order; `onExit(code,
    // log tail)` once the child has ended (code -1: stopped by us). Both run on the job's thread.
    SimJob(std::function<void(long)> onFrame, std::function<void(int, const std::string&)> onExit);
    ~SimJob();
    SimJob(const SimJob&) = delete;
    SimJob& operator=(const SimJob&) = delete;

    // Stops any running child (at once), then starts `gale sim scene -o outDir` (output and errors
    // to outDir/sim.log). False with `error` when it cannot be started.
    bool start(const std::string& galeExecutable, const std::string& scene,
               const std::string& outDir, const std::vector<SimObject>& objects, long firstFrame,
               long lastFrame, std::string& error);
    // SIGTERM to the child (SIGKILL after a second), waits for it and the thread. `now`:
    // SIGKILL at once (a run an edit replaces: its folder is thrown away, nothing to finish).
    void stop(bool now = false);
    bool running() const { return mRunning; }
    std::string outDir() const;
    const std::vector<SimObject>& objects() const { return mObjects; }
    // The newest frame reported (firstFrame - 1 before any).
    long lastFrame() const { return mLast; }

private:
    void run();

    std::function<void(long)> mOnFrame;
    std::function<void(int, const std::string&)> mOnExit;
    mutable std::mutex mMutex;
    std::thread mThread;
    pid_t mPid = -1;
    std::string mOutDir;
    std::vector<SimObject> mObjects;
    long mFirst = 1, mEnd = 1;
    std::atomic<long> mLast{0};
    std::atomic<bool> mRunning{false}, mStopping{false};
};

// The path of object `name`'s frame `frame` in `dir`: dir/name.0012.obj.
std::string simFramePath(const std::string& dir, const std::string& name, long frame,
                         const std::string& format);

} // namespace gale::live
