// Server-Sent Events for the live page: a hub that numbers events and keeps the last 256 for
// streams to catch up from (event_streams.h sends them), and the text of one event on the wire.
#pragma once

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
    // Adds an event (the oldest beyond 256 are let go).
    void publish(const std::string& type, const std::string& data);
    // The id of the newest event (0 before the first).
    uint64_t latest() const;
    // Every event newer than `after` still held, oldest first (no waiting).
    std::vector<Event> since(uint64_t after) const;

private:
    mutable std::mutex mMutex;
    std::deque<Event> mEvents;
    uint64_t mNext = 1;
};

} // namespace gale::live
