// The Server-Sent Events hub (events.h).
#include "live/events.h"

namespace gale::live {

std::string eventText(const Event& e) {
    return "id: " + std::to_string(e.id) + "\nevent: " + e.type + "\ndata: " + e.data + "\n\n";
}

void EventHub::publish(const std::string& type, const std::string& data) {
    std::lock_guard<std::mutex> lock(mMutex);
    mEvents.push_back({mNext++, type, data});
    while (mEvents.size() > 256) mEvents.pop_front();
}

uint64_t EventHub::latest() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mNext - 1;
}

std::vector<Event> EventHub::since(uint64_t after) const {
    std::lock_guard<std::mutex> lock(mMutex);
    std::vector<Event> out;
    for (const Event& e : mEvents)
        if (e.id > after) out.push_back(e);
    return out;
}

} // namespace gale::live
