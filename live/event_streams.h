// Server-Sent Event streams served without a thread each: the socket of every open
// /api/events response, handed over by the HTTP server once the request is authorised, is
// written from one epoll thread as events are published (with a ping every 15 s); a client
// that closes its end, errs, or stops reading (1 MB unsent) is dropped and its socket closed.
#pragma once

#include "live/events.h"

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace gale::live {

class EventStreams {
public:
    explicit EventStreams(int pingMs = 15000, size_t maxUnsent = 1u << 20);
    ~EventStreams(); // stop()
    EventStreams(const EventStreams&) = delete;
    EventStreams& operator=(const EventStreams&) = delete;

    // Starts the epoll thread. False with `error` when epoll or eventfd are unavailable.
    bool start(std::string& error);
    // Numbers the event and queues it on every open stream.
    void publish(const std::string& type, const std::string& data);
    // The id of the newest event (0 before the first).
    uint64_t latest() const { return mHub.latest(); }
    // Takes over `fd`, a connected socket whose request has been read: writes the response
    // head (200, text/event-stream, Connection: close) and then every event newer than
    // `after`. From here on this object closes it. After stop() it is closed at once.
    void adopt(int fd, uint64_t after);
    // Open streams (adopted and not yet dropped).
    size_t count() const { return mCount; }
    // Closes every stream and ends the thread (publish() stays harmless after it).
    void stop();

private:
    struct Stream {
        std::string unsent;
        uint64_t last = 0;
        bool wantWrite = false;
    };
    void run();
    void drop(int fd);
    void flush(int fd, Stream& s);

    EventHub mHub;
    int mPingMs;
    size_t mMaxUnsent;
    int mEpoll = -1, mWake = -1;
    std::thread mThread;
    std::mutex mMutex;                              // mAdopted, mStopped
    std::vector<std::pair<int, uint64_t>> mAdopted; // handed over, not yet registered
    bool mStopped = false;
    std::map<int, Stream> mStreams; // the thread's own
    std::atomic<size_t> mCount{0};
};

} // namespace gale::live
