// The epoll-driven Server-Sent Event streams (event_streams.h).
#include "live/event_streams.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

namespace gale::live {

namespace {

constexpr const char* kHead = "HTTP/1.1 200 OK\r\n"
                              "Content-Type: text/event-stream\r\n"
                              "Cache-Control: no-store\r\n"
                              "Connection: close\r\n"
                              "\r\n"
                              "retry: 1000\n: gale live\n\n";

void wakeUp(int fd) {
    const uint64_t one = 1;
    (void)!::write(fd, &one, sizeof one);
}

} // namespace

EventStreams::EventStreams(int pingMs, size_t maxUnsent) : mPingMs(pingMs), mMaxUnsent(maxUnsent) {}

EventStreams::~EventStreams() {
    stop();
    // (Closed only here: publish() may still write to mWake from another thread after stop.)
    for (int* fd : {&mEpoll, &mWake})
        if (*fd >= 0) {
            ::close(*fd);
            *fd = -1;
        }
}

bool EventStreams::start(std::string& error) {
    mEpoll = epoll_create1(EPOLL_CLOEXEC);
    mWake = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (mEpoll < 0 || mWake < 0) {
        error = std::string("cannot serve event streams (epoll): ") + std::strerror(errno);
        return false;
    }
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = mWake;
    if (epoll_ctl(mEpoll, EPOLL_CTL_ADD, mWake, &ev) != 0) {
        error = std::string("cannot serve event streams (epoll): ") + std::strerror(errno);
        return false;
    }
    mThread = std::thread([this] { run(); });
    return true;
}

void EventStreams::publish(const std::string& type, const std::string& data) {
    mHub.publish(type, data);
    if (mWake >= 0) wakeUp(mWake);
}

void EventStreams::adopt(int fd, uint64_t after) {
    {
        std::lock_guard<std::mutex> lock(mMutex);
        if (!mStopped && mThread.joinable()) {
            mAdopted.emplace_back(fd, after);
            ++mCount;
            wakeUp(mWake);
            return;
        }
    }
    ::shutdown(fd, SHUT_RDWR);
    ::close(fd);
}

void EventStreams::stop() {
    {
        std::lock_guard<std::mutex> lock(mMutex);
        if (mStopped) return;
        mStopped = true;
    }
    if (mThread.joinable()) {
        wakeUp(mWake);
        mThread.join();
    }
    for (auto& [fd, after] : mAdopted) { // (handed over after the thread's last look)
        ::shutdown(fd, SHUT_RDWR);
        ::close(fd);
    }
    mAdopted.clear();
    mCount = 0;
}

void EventStreams::drop(int fd) {
    epoll_ctl(mEpoll, EPOLL_CTL_DEL, fd, nullptr);
    ::shutdown(fd, SHUT_RDWR);
    ::close(fd);
    mStreams.erase(fd);
    --mCount;
}

// Writes what the socket takes now; waits for EPOLLOUT while some is left. Drops a stream
// that errs or has more than mMaxUnsent waiting (a client that stopped reading).
void EventStreams::flush(int fd, Stream& s) {
    while (!s.unsent.empty()) {
        const ssize_t n = ::send(fd, s.unsent.data(), s.unsent.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n > 0) {
            s.unsent.erase(0, static_cast<size_t>(n));
            continue;
        }
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
        drop(fd);
        return;
    }
    if (s.unsent.size() > mMaxUnsent) {
        drop(fd);
        return;
    }
    const bool want = !s.unsent.empty();
    if (want != s.wantWrite) {
        s.wantWrite = want;
        epoll_event ev{};
        ev.events = EPOLLIN | EPOLLRDHUP | (want ? EPOLLOUT : 0u);
        ev.data.fd = fd;
        epoll_ctl(mEpoll, EPOLL_CTL_MOD, fd, &ev);
    }
}

void EventStreams::run() {
    using Clock = std::chrono::steady_clock;
    auto nextPing = Clock::now() + std::chrono::milliseconds(mPingMs);
    epoll_event events[64];
    for (;;) {
        const auto wait =
            std::chrono::duration_cast<std::chrono::milliseconds>(nextPing - Clock::now()).count();
        const int n =
            epoll_wait(mEpoll, events, 64, static_cast<int>(std::max<long long>(0, wait)));
        {
            std::lock_guard<std::mutex> lock(mMutex);
            if (mStopped) break;
            for (auto& [fd, after] : mAdopted) {
                const int flags = fcntl(fd, F_GETFL);
                fcntl(fd, F_SETFL, flags | O_NONBLOCK);
                Stream s;
                s.unsent = kHead;
                s.last = after;
                epoll_event ev{};
                ev.events = EPOLLIN | EPOLLRDHUP;
                ev.data.fd = fd;
                if (epoll_ctl(mEpoll, EPOLL_CTL_ADD, fd, &ev) != 0) {
                    ::close(fd);
                    --mCount;
                    continue;
                }
                mStreams[fd] = std::move(s);
            }
            mAdopted.clear();
        }
        for (int i = 0; i < n; ++i) {
            const int fd = events[i].data.fd;
            if (fd == mWake) {
                uint64_t v;
                (void)!::read(mWake, &v, sizeof v);
                continue;
            }
            auto it = mStreams.find(fd);
            if (it == mStreams.end()) continue;
            if (events[i].events & (EPOLLERR | EPOLLHUP | EPOLLRDHUP)) {
                drop(fd);
                continue;
            }
            if (events[i].events & EPOLLIN) { // a client sends nothing more; EOF is its leaving
                char buf[512];
                ssize_t r;
                while ((r = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT)) > 0) {
                }
                if (r == 0 ||
                    (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
                    drop(fd);
                    continue;
                }
            }
            if (events[i].events & EPOLLOUT) flush(fd, it->second);
        }
        // New events (and the backlog of new streams), then a ping when due.
        const bool ping = Clock::now() >= nextPing;
        if (ping) nextPing = Clock::now() + std::chrono::milliseconds(mPingMs);
        const uint64_t latest = mHub.latest();
        std::vector<Event> fresh;
        uint64_t oldestWanted = latest;
        for (auto& [fd, s] : mStreams) oldestWanted = std::min(oldestWanted, s.last);
        if (oldestWanted < latest) fresh = mHub.since(oldestWanted);
        std::vector<int> fds;
        for (auto& [fd, s] : mStreams) fds.push_back(fd);
        for (int fd : fds) {
            Stream& s = mStreams[fd];
            for (const Event& e : fresh)
                if (e.id > s.last) s.unsent += eventText(e);
            s.last = std::max(s.last, latest);
            if (ping) s.unsent += ": ping\n\n";
            if (!s.unsent.empty()) flush(fd, s);
        }
    }
    for (auto& [fd, s] : mStreams) {
        ::shutdown(fd, SHUT_RDWR);
        ::close(fd);
    }
    mStreams.clear();
}

} // namespace gale::live
