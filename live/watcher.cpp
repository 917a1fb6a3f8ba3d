// inotify file watching (watcher.h): folder watches (a missing folder's nearest existing
// parent meanwhile), a settle time, a pipe to stop.
#include "live/watcher.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>

namespace gale::live {

namespace fs = std::filesystem;

namespace {

std::string absolute(const std::string& p) {
    std::error_code ec;
    const fs::path a = fs::absolute(p, ec);
    return (ec ? fs::path(p) : a).lexically_normal().string();
}

// A file name with '#' runs as a regular expression: each run one or more digits.
std::regex namePattern(const std::string& name) {
    std::string re;
    for (size_t i = 0; i < name.size(); ++i) {
        const char c = name[i];
        if (c == '#') {
            while (i + 1 < name.size() && name[i + 1] == '#') ++i;
            re += "[0-9]+";
        } else if (std::strchr(".^$|()[]{}*+?\\", c)) {
            re += '\\';
            re += c;
        } else {
            re += c;
        }
    }
    return std::regex(re);
}

// True when `dir` is `prefix` or inside it.
bool within(const std::string& dir, const std::string& prefix) {
    return dir == prefix ||
           (dir.size() > prefix.size() && dir.compare(0, prefix.size(), prefix) == 0 &&
            (prefix.back() == '/' || dir[prefix.size()] == '/'));
}

// A file counts once it is complete: closed after writing, or renamed into place (what
// editors do), or gone; a file still being written (created, modified, not closed) does not
// yet, so a reload never reads half a file. A folder counts when it is created.
constexpr uint32_t kEvents = IN_CLOSE_WRITE | IN_MOVED_TO | IN_MOVED_FROM | IN_CREATE | IN_DELETE |
                             IN_DELETE_SELF | IN_MOVE_SELF;

} // namespace

FileWatcher::FileWatcher(std::function<void(const std::set<std::string>&)> onChange, int settleMs)
    : mOnChange(std::move(onChange)), mSettleMs(settleMs) {}

FileWatcher::~FileWatcher() {
    stop();
}

bool FileWatcher::start(std::string& error) {
    mFd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (mFd < 0 || pipe2(mWake, O_CLOEXEC | O_NONBLOCK) != 0) {
        error = std::string("cannot watch files (inotify): ") + std::strerror(errno);
        return false;
    }
    mThread = std::thread([this] { run(); });
    return true;
}

bool FileWatcher::addWatch(const std::string& dir) {
    if (mDirs.count(dir)) return true;
    if (mFd < 0) return false;
    const int wd = inotify_add_watch(mFd, dir.c_str(), kEvents);
    if (wd < 0) return false;
    mDirs.insert(dir);
    mWatchDirs[wd] = dir;
    return true;
}

void FileWatcher::rescan(std::set<std::string>* appeared) {
    const std::set<std::string> wasMissing = std::move(mMissing);
    mMissing.clear();
    for (const std::string& dir : mWanted) {
        std::error_code ec;
        if (fs::is_directory(dir, ec) && addWatch(dir)) {
            if (appeared && wasMissing.count(dir)) listMatches(dir, *appeared);
            continue;
        }
        mMissing.insert(dir);
        // The nearest existing parent (the root at worst) waits for the next folder on the way.
        for (fs::path p = fs::path(dir).parent_path();; p = p.parent_path()) {
            if (fs::is_directory(p, ec) && addWatch(p.string())) break;
            if (p == p.parent_path()) break;
        }
    }
}

void FileWatcher::listMatches(const std::string& dir, std::set<std::string>& out) const {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string path = it->path().lexically_normal().string();
        const std::string name = it->path().filename().string();
        bool match = mFiles.count(path) > 0;
        for (const auto& [folder, pattern] : mPatterns)
            match = match || (folder == dir && std::regex_match(name, pattern));
        if (match) out.insert(path);
    }
}

void FileWatcher::watch(const std::set<std::string>& files, const std::set<std::string>& patterns) {
    std::lock_guard<std::mutex> lock(mMutex);
    mFiles.clear();
    mPatterns.clear();
    mWanted.clear();
    for (const std::string& f : files) {
        const std::string a = absolute(f);
        mFiles.insert(a);
        mWanted.insert(fs::path(a).parent_path().string());
    }
    for (const std::string& p : patterns) {
        const fs::path a = absolute(p);
        mPatterns.emplace_back(a.parent_path().string(), namePattern(a.filename().string()));
        mWanted.insert(a.parent_path().string());
    }
    rescan();
}

std::set<std::string> FileWatcher::watchedFolders() {
    std::lock_guard<std::mutex> lock(mMutex);
    return mDirs;
}

void FileWatcher::stop() {
    if (mThread.joinable()) {
        mStop = true;
        const char c = 'x';
        (void)!::write(mWake[1], &c, 1);
        mThread.join();
    }
    for (int* fd : {&mFd, &mWake[0], &mWake[1]})
        if (*fd >= 0) {
            ::close(*fd);
            *fd = -1;
        }
}

void FileWatcher::run() {
    alignas(inotify_event) char buf[16384];
    std::set<std::string> pending;
    using Clock = std::chrono::steady_clock;
    Clock::time_point firstPending;
    // Changes are reported once quiet for the settle time, or at the latest kMaxDelayMs after
    // the first (a generator writing frames for seconds is followed as it goes).
    constexpr int kMaxDelayMs = 200;
    while (!mStop) {
        pollfd fds[2] = {{mFd, POLLIN, 0}, {mWake[0], POLLIN, 0}};
        int wait = 1000;
        if (!pending.empty()) {
            const auto waited =
                std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - firstPending)
                    .count();
            wait = static_cast<int>(
                std::max<long long>(0, std::min<long long>(mSettleMs, kMaxDelayMs - waited)));
        }
        const int r = ::poll(fds, 2, wait);
        if (mStop) break;
        if (!pending.empty() &&
            (r == 0 || Clock::now() - firstPending >= std::chrono::milliseconds(kMaxDelayMs))) {
            std::set<std::string> changed;
            changed.swap(pending);
            mOnChange(changed);
            continue;
        }
        if (r <= 0 || !(fds[0].revents & POLLIN)) continue;
        for (;;) {
            const ssize_t n = ::read(mFd, buf, sizeof buf);
            if (n <= 0) break;
            if (pending.empty()) firstPending = Clock::now();
            std::lock_guard<std::mutex> lock(mMutex);
            bool again = false; // a folder appeared or went: watch what exists now
            for (ssize_t off = 0; off < n;) {
                const auto* ev = reinterpret_cast<const inotify_event*>(buf + off);
                off += static_cast<ssize_t>(sizeof(inotify_event) + ev->len);
                auto dir = mWatchDirs.find(ev->wd);
                if (dir == mWatchDirs.end()) continue;
                if (ev->mask & (IN_IGNORED | IN_DELETE_SELF | IN_MOVE_SELF)) {
                    // The folder itself went: its files changed, and a parent waits for it.
                    if (ev->mask & IN_IGNORED) {
                        mDirs.erase(dir->second);
                        pending.insert(dir->second);
                        mWatchDirs.erase(dir);
                        again = true;
                    } else {
                        inotify_rm_watch(mFd, ev->wd); // (IN_IGNORED follows)
                    }
                    continue;
                }
                if (ev->len == 0) continue;
                if ((ev->mask & IN_CREATE) && !(ev->mask & IN_ISDIR))
                    continue; // (its close follows)
                const std::string path =
                    (fs::path(dir->second) / ev->name).lexically_normal().string();
                if (mFiles.count(path)) pending.insert(path);
                for (const auto& [folder, name] : mPatterns)
                    if (folder == dir->second && std::regex_match(ev->name, name))
                        pending.insert(path);
                if (ev->mask & IN_ISDIR)
                    for (const std::string& m : mMissing)
                        if (within(m, path)) {
                            pending.insert(path);
                            again = true;
                        }
            }
            if (again) rescan(&pending);
        }
    }
}

} // namespace gale::live
