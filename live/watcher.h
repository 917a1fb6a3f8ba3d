// Watching a set of files for edits with inotify: the folders holding them are watched (editors
// often write a new file and rename it over the old one), and a change to any watched name is
// reported once the folder has been quiet for a short settle time.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace gale::live {

class FileWatcher {
public:
    // `onChange` runs on the watcher's thread with the changed files' paths.
    explicit FileWatcher(std::function<void(const std::set<std::string>&)> onChange,
                         int settleMs = 30);
    ~FileWatcher();
    FileWatcher(const FileWatcher&) = delete;
    FileWatcher& operator=(const FileWatcher&) = delete;

    // Starts the thread. False with `error` when inotify is unavailable.
    bool start(std::string& error);
    // Replaces the watched files (paths as given; their folders are watched).
    void watch(const std::set<std::string>& files);
    void stop();

private:
    void run();

    std::function<void(const std::set<std::string>&)> mOnChange;
    int mSettleMs;
    int mFd = -1;
    int mWake[2] = {-1, -1}; // a pipe that stop() writes to end run()'s poll
    std::thread mThread;
    std::mutex mMutex;
    std::set<std::string> mFiles;          // canonical-ish (lexically normal, absolute) paths
    std::set<std::string> mDirs;           // folders with a watch
    std::map<int, std::string> mWatchDirs; // watch descriptor -> folder
    std::atomic<bool> mStop{false};
};

} // namespace gale::live
