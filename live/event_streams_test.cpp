// EventStreams over socket pairs: the response head and the events reach every stream, a
// stream resumes after the id it had, and a peer that closes is dropped.
#include "live/event_streams.h"

#include <catch2/catch.hpp>

#include <chrono>
#include <poll.h>
#include <string>
#include <sys/socket.h>
#include <thread>
#include <unistd.h>

using gale::live::EventStreams;

namespace {

// Reads what `fd` gets until `want` appears or `ms` pass.
std::string readUntil(int fd, const std::string& want, int ms) {
    std::string got;
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (got.find(want) == std::string::npos && std::chrono::steady_clock::now() < end) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 20) > 0) {
            char buf[4096];
            const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
            if (n <= 0) break;
            got.append(buf, static_cast<size_t>(n));
        }
    }
    return got;
}

bool countBecomes(const EventStreams& s, size_t n, int ms) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (s.count() != n && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    return s.count() == n;
}

} // namespace

TEST_CASE("event streams: every stream gets the head and each event; closed peers are dropped") {
    EventStreams streams;
    std::string error;
    REQUIRE(streams.start(error));
    streams.publish("field", "{\"n\":1}"); // before any stream: only a resuming one sees it
    int a[2], b[2];
    REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, a) == 0);
    REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, b) == 0);
    streams.adopt(a[0], streams.latest()); // from now on
    streams.adopt(b[0], 0);                // resumes from the start: gets event 1 too
    CHECK(countBecomes(streams, 2, 1000));
    const std::string headA = readUntil(a[1], ": gale live\n\n", 1000);
    CHECK(headA.rfind("HTTP/1.1 200 OK\r\n", 0) == 0);
    CHECK(headA.find("Content-Type: text/event-stream\r\n") != std::string::npos);
    CHECK(readUntil(b[1], "id: 1\nevent: field\ndata: {\"n\":1}\n\n", 1000).find("id: 1\n") !=
          std::string::npos);
    streams.publish("frame", "{\"frame\":3}");
    const std::string want = "id: 2\nevent: frame\ndata: {\"frame\":3}\n\n";
    const std::string gotA = readUntil(a[1], want, 1000);
    CHECK(gotA.find(want) != std::string::npos);
    CHECK(gotA.find("id: 1\n") == std::string::npos);
    CHECK(readUntil(b[1], want, 1000).find(want) != std::string::npos);
    ::close(a[1]); // a client that goes away
    CHECK(countBecomes(streams, 1, 1000));
    streams.publish("frame", "{\"frame\":4}");
    CHECK(readUntil(b[1], "id: 3\n", 1000).find("id: 3\n") != std::string::npos);
    streams.stop();
    CHECK(streams.count() == 0);
    char c;
    CHECK(::recv(b[1], &c, 1, 0) == 0); // closed by stop()
    ::close(b[1]);
    int late[2];
    REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, late) == 0);
    streams.adopt(late[0], 0); // after stop: closed at once
    CHECK(::recv(late[1], &c, 1, 0) == 0);
    ::close(late[1]);
}

TEST_CASE(
    "event streams: a peer that stops reading is dropped once its unsent bytes pass the bound") {
    EventStreams streams(15000, 64 * 1024);
    std::string error;
    REQUIRE(streams.start(error));
    int s[2];
    REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, s) == 0);
    int small = 4096;
    setsockopt(s[0], SOL_SOCKET, SO_SNDBUF, &small, sizeof small);
    streams.adopt(s[0], 0);
    REQUIRE(countBecomes(streams, 1, 1000));
    const std::string big(8000, 'x');
    for (int i = 0; i < 200 && streams.count() == 1; ++i) streams.publish("frame", big);
    CHECK(countBecomes(streams, 0, 2000));
    ::close(s[1]);
}
