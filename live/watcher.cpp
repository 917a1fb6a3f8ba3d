// inotify file watching (watcher.h): folder watches, a settle time, a pipe to stop.
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

void FileWatcher::watch(const std::set<std::string>& files) {
    std::lock_guard<std::mutex> lock(mMutex);
    mFiles.clear();
    for (const std::string& f : files) {
        const std::string a = absolute(f);
        mFiles.insert(a);
        const std::string dir = fs::path(a).parent_path().string();
        if (mFd >= 0 && mDirs.insert(dir).second) {
            const int wd = inotify_add_watch(
                mFd, dir.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_MODIFY);
            if (wd >= 0) mWatchDirs[wd] = dir;
        }
    }
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
    while (!mStop) {
        pollfd fds[2] = {{mFd, POLLIN, 0}, {mWake[0], POLLIN, 0}};
        // While changes are pending, wait only the settle time for more.
        const int r = ::poll(fds, 2, pending.empty() ? 1000 : mSettleMs);
        if (mStop) break;
        if (r == 0 && !pending.empty()) {
            std::set<std::string> changed;
            changed.swap(pending);
            mOnChange(changed);
            continue;
        }
        if (r <= 0 || !(fds[0].revents & POLLIN)) continue;
        for (;;) {
            const ssize_t n = ::read(mFd, buf, sizeof buf);
            if (n <= 0) break;
            for (ssize_t off = 0; off < n;) {
                const auto* ev = reinterpret_cast<const inotify_event*>(buf + off);
                off += static_cast<ssize_t>(sizeof(inotify_event) + ev->len);
                if (ev->len == 0) continue;
                std::lock_guard<std::mutex> lock(mMutex);
                auto dir = mWatchDirs.find(ev->wd);
                if (dir == mWatchDirs.end()) continue;
                const std::string path =
                    (fs::path(dir->second) / ev->name).lexically_normal().string();
                if (mFiles.count(path)) pending.insert(path);
            }
        }
    }
}

} // namespace gale::live
