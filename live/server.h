// The `gale live` server: the page and its JSON API over HTTP with Server-Sent Events
// (cpp-httplib), bound to 127.0.0.1 (or --host), every request checked for the token and the
// Host header. It owns the project (reloaded when a watched file changes), the file watcher
// and the background simulation. docs/live.md lists the endpoints.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace gale::live {

struct ServerOptions {
    std::string input; // SCENE.toml or FILE.se
    std::string host = "127.0.0.1";
    int port = 0;                        // 0: a free port
    std::vector<std::string> allowPaths; // --allow-path
    std::string galeExecutable;          // for "simulate" (`gale sim`); "" disables it
    std::string token;                   // "" for a random one
    std::string webDir;                  // the page's files ("" for the built-in path)
    std::string modulesDir;              // node_modules holding three ("" for the built-in path)
    std::string simDir;                  // where simulations go ("" for a new folder under /tmp)
};

class Server {
public:
    explicit Server(ServerOptions options);
    ~Server(); // stops everything it started
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

    // Loads the input (errors become diagnostics on the page, not a failure), binds and starts
    // serving on a thread. False with `error` when the port cannot be bound or the input is
    // missing.
    bool start(std::string& error);
    // Blocks until stop() (from another thread or a signal handler's thread).
    void wait();
    void stop();

    int port() const;
    const std::string& token() const;
    // http://HOST:PORT/?token=TOKEN
    std::string url() const;

    class Impl;

private:
    std::unique_ptr<Impl> mImpl;
};

// A random token: 32 hex digits from std::random_device.
std::string randomToken();

// True when `host` (a Host header) names this server: 127.0.0.1, localhost or [::1] (or
// `boundHost` when it is not a loopback name) with `port`.
bool hostAllowed(const std::string& host, const std::string& boundHost, int port);

} // namespace gale::live
