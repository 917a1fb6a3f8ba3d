// Server-Sent Events for the live page: a hub that numbers events and lets any number of
// streams wait for the next one, and the text of one event on the wire.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

namespace gale::live {

struct Event {
    uint64_t id = 0;
    std::string type; // field, diagnostics, frame, sim, param
    std::string data; // one line of JSON
};

// "id: N\nevent: TYPE\ndata: DATA\n\n" (DATA holds no newline: it is compact JSON).
std::string eventText(const Event& e);

class EventHub {
public:
    // Adds an event and wakes every waiting stream.
    void publish(const std::string& type, const std::string& data);
    // The id of the newest event (0 before the first).
    uint64_t latest() const;
    // Waits up to `ms` for an event newer than `after` or for close(); fills `out` with the
    // oldest such event still held (the hub keeps the last 256). False on timeout or close.
    bool next(uint64_t after, int ms, Event& out);
    // Every event newer than `after` still held, oldest first (no waiting).
    std::vector<Event> since(uint64_t after) const;
    // Wakes every stream for good: next() returns false from now on.
    void close();
    bool closed() const;

private:
    mutable std::mutex mMutex;
    std::condition_variable mChanged;
    std::deque<Event> mEvents;
    uint64_t mNext = 1;
    bool mClosed = false;
};

} // namespace gale::live
