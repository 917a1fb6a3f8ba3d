// Watching a set of files for edits with inotify: the folders holding them are watched (editors
// often write a new file and rename it over the old one), and a change to any watched name is
// reported once the folder has been quiet for a short settle time. A folder that does not exist
// yet is waited for at its nearest existing parent: when it appears (or any folder on the way
// to it), it is watched from then on and reported as a change, together with the files in it
// that match (written before its watch could be added), so a scene that named a missing folder
// reloads once the folder and its files are there.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

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
    // Replaces the watched files (paths as given; their folders are watched). `patterns` are
    // paths that need not exist, a run of '#' in the file name standing for a frame number
    // (`body/body.#.obj`); any file matching one is watched, and their folders as files' are.
    void watch(const std::set<std::string>& files, const std::set<std::string>& patterns = {});
    void stop();

    // The folders with a watch now (tests).
    std::set<std::string> watchedFolders();

private:
    void run();
    // Adds a watch on each wanted folder that exists, else on its nearest existing parent.
    // Files already in a folder that was missing and is now watched, matching a watched name or
    // pattern, go into `appeared` (when given). Called with mMutex held.
    void rescan(std::set<std::string>* appeared = nullptr);
    bool addWatch(const std::string& dir);
    // The files in `dir` that match a watched name or pattern (called with mMutex held).
    void listMatches(const std::string& dir, std::set<std::string>& out) const;

    std::function<void(const std::set<std::string>&)> mOnChange;
    int mSettleMs;
    int mFd = -1;
    int mWake[2] = {-1, -1}; // a pipe that stop() writes to end run()'s poll
    std::thread mThread;
    std::mutex mMutex;
    std::set<std::string> mFiles;                              // absolute, lexically normal
    std::vector<std::pair<std::string, std::regex>> mPatterns; // folder, file name pattern
    std::set<std::string> mWanted;                             // folders of files and patterns
    std::set<std::string> mMissing;                            // wanted folders not there yet
    std::set<std::string> mDirs;                               // folders with a watch
    std::map<int, std::string> mWatchDirs;                     // watch descriptor -> folder
    std::atomic<bool> mStop{false};
};

} // namespace gale::live
