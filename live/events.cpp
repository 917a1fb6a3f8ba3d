// The Server-Sent Events hub (events.h).
#include "live/events.h"

#include <chrono>

namespace gale::live {

std::string eventText(const Event& e) {
    return "id: " + std::to_string(e.id) + "\nevent: " + e.type + "\ndata: " + e.data + "\n\n";
}

void EventHub::publish(const std::string& type, const std::string& data) {
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mEvents.push_back({mNext++, type, data});
        while (mEvents.size() > 256) mEvents.pop_front();
    }
    mChanged.notify_all();
}

uint64_t EventHub::latest() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mNext - 1;
}

bool EventHub::next(uint64_t after, int ms, Event& out) {
    std::unique_lock<std::mutex> lock(mMutex);
    const bool ready = mChanged.wait_for(lock, std::chrono::milliseconds(ms),
                                         [&] { return mClosed || mNext - 1 > after; });
    if (!ready || mClosed) return false;
    for (const Event& e : mEvents)
        if (e.id > after) {
            out = e;
            return true;
        }
    return false;
}

std::vector<Event> EventHub::since(uint64_t after) const {
    std::lock_guard<std::mutex> lock(mMutex);
    std::vector<Event> out;
    for (const Event& e : mEvents)
        if (e.id > after) out.push_back(e);
    return out;
}

void EventHub::close() {
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mClosed = true;
    }
    mChanged.notify_all();
}

bool EventHub::closed() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mClosed;
}

} // namespace gale::live
