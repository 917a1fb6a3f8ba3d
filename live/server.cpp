// The `gale live` HTTP server (server.h): routes, token and Host checks, SSE streams, the
// reload on file changes and the background simulation. Every handler answers a bad request
// with a 4xx JSON {"error": ...}; nothing outside the page's assets and the scene's files is
// read, and only the scene's files (by literal edits) and the simulation folder are written.
#include "live/server.h"

#include "live/event_streams.h"
#include "live/json.h"
#include "live/project.h"
#include "live/sim_job.h"
#include "live/watcher.h"
#include "viz/overlays.h"
#include "viz/strain.h"

#include <httplib.h>

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>

#ifndef GALE_LIVE_WEB_DIR
#define GALE_LIVE_WEB_DIR "live/web"
#endif
#ifndef GALE_LIVE_NODE_MODULES
#define GALE_LIVE_NODE_MODULES "live/web/node_modules"
#endif

namespace gale::live {

namespace fs = std::filesystem;
using nlohmann::json;

std::string randomToken() {
    std::random_device rd;
    static const char* hex = "0123456789abcdef";
    std::string t;
    for (int i = 0; i < 8; ++i) {
        const uint32_t v = rd();
        for (int k = 0; k < 4; ++k) t += hex[(v >> (8 * k + 4 * (i & 1))) & 15];
    }
    return t;
}

bool hostAllowed(const std::string& host, const std::string& boundHost, int port) {
    const std::string p = ":" + std::to_string(port);
    for (const std::string& name :
         {std::string("127.0.0.1"), std::string("localhost"), std::string("[::1]")})
        if (host == name + p) return true;
    return !boundHost.empty() && boundHost != "0.0.0.0" && host == boundHost + p;
}

namespace {

// cpp-httplib compresses `application/json`, `application/javascript` and `text/*` replies with
// brotli at its highest quality when the browser accepts it, which takes seconds for a
// megabyte; on loopback it only costs time, so the JSON and the scripts are sent with a charset
// parameter, which that check does not match (text/html and text/css are small).
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kScript = "application/javascript; charset=utf-8";

bool sameToken(const std::string& a, const std::string& b) {
    if (a.size() != b.size() || a.empty()) return false;
    unsigned char d = 0;
    for (size_t i = 0; i < a.size(); ++i) d |= static_cast<unsigned char>(a[i] ^ b[i]);
    return d == 0;
}

bool readFile(const std::string& path, std::string& out, size_t limit) {
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec || size > limit) return false;
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    std::ostringstream s;
    s << in.rdbuf();
    out = s.str();
    return true;
}

void fail(httplib::Response& res, int status, const std::string& message) {
    res.status = status;
    res.set_content(errorJson(message), kJson);
}

// A finite number query parameter; `def` when absent. False on a malformed value.
bool numberParam(const httplib::Request& req, const char* name, double def, double& out) {
    out = def;
    if (!req.has_param(name)) return true;
    const std::string s = req.get_param_value(name);
    char* end = nullptr;
    out = std::strtod(s.c_str(), &end);
    return !s.empty() && end == s.c_str() + s.size() && std::isfinite(out);
}

bool intParam(const httplib::Request& req, const char* name, int def, int lo, int hi, int& out) {
    double v = 0;
    if (!numberParam(req, name, def, v) || v != std::floor(v) || v < lo || v > hi) return false;
    out = static_cast<int>(v);
    return true;
}

// A connection's socket as httplib's Stream, with a read buffer kept over its keep-alive
// requests. Once an event stream has taken the socket over (take()), writes are swallowed:
// httplib's reply to that request never reaches the wire, EventStreams writes instead.
class SocketStream final : public httplib::Stream {
public:
    SocketStream(int fd, int readMs, int writeMs) : mFd(fd), mReadMs(readMs), mWriteMs(writeMs) {}
    bool is_readable() const override { return mPos < mLen || ready(POLLIN, mReadMs); }
    bool is_writable() const override { return mTaken || ready(POLLOUT, mWriteMs); }
    ssize_t read(char* ptr, size_t size) override {
        if (mPos == mLen) {
            if (!ready(POLLIN, mReadMs)) return -1;
            ssize_t n;
            do n = ::recv(mFd, mBuf, sizeof mBuf, 0);
            while (n < 0 && errno == EINTR);
            if (n <= 0) return n;
            mPos = 0;
            mLen = static_cast<size_t>(n);
        }
        const size_t k = std::min(size, mLen - mPos);
        std::memcpy(ptr, mBuf + mPos, k);
        mPos += k;
        return static_cast<ssize_t>(k);
    }
    ssize_t write(const char* ptr, size_t size) override {
        if (mTaken) return static_cast<ssize_t>(size);
        if (!ready(POLLOUT, mWriteMs)) return -1;
        ssize_t n;
        do n = ::send(mFd, ptr, size, MSG_NOSIGNAL);
        while (n < 0 && errno == EINTR);
        return n;
    }
    void get_remote_ip_and_port(std::string& ip, int& port) const override {
        address(::getpeername, ip, port);
    }
    void get_local_ip_and_port(std::string& ip, int& port) const override {
        address(::getsockname, ip, port);
    }
    socket_t socket() const override { return mFd; }
    bool buffered() const { return mPos < mLen; }
    void take() { mTaken = true; }
    bool taken() const { return mTaken; }

private:
    bool ready(short what, int ms) const {
        pollfd p{mFd, what, 0};
        int r;
        do r = ::poll(&p, 1, ms);
        while (r < 0 && errno == EINTR);
        return r > 0 && (p.revents & (what | POLLHUP | POLLERR));
    }
    template <typename Get>
    void address(Get get, std::string& ip, int& port) const {
        sockaddr_storage a{};
        socklen_t len = sizeof a;
        ip.clear();
        port = 0;
        if (get(mFd, reinterpret_cast<sockaddr*>(&a), &len) != 0) return;
        char text[INET6_ADDRSTRLEN] = "";
        if (a.ss_family == AF_INET) {
            const auto* v4 = reinterpret_cast<const sockaddr_in*>(&a);
            inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text);
            port = ntohs(v4->sin_port);
        } else if (a.ss_family == AF_INET6) {
            const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&a);
            inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof text);
            port = ntohs(v6->sin6_port);
        }
        ip = text;
    }

    int mFd;
    int mReadMs, mWriteMs;
    char mBuf[4096];
    size_t mPos = 0, mLen = 0;
    bool mTaken = false;
};

// The connection being served on this worker thread (the /api/events handler takes it over).
thread_local SocketStream* tConnection = nullptr;

// cpp-httplib's server with its per-connection loop replaced (the same keep-alive rules) so
// that an /api/events request can hand its socket to EventStreams and free the worker: with
// cpp-httplib's own loop every open stream held one of the pool's threads.
class HttpServer final : public httplib::Server {
private:
    bool process_and_close_socket(socket_t sock) override {
        SocketStream strm(sock,
                          static_cast<int>(read_timeout_sec_ * 1000 + read_timeout_usec_ / 1000),
                          static_cast<int>(write_timeout_sec_ * 1000 + write_timeout_usec_ / 1000));
        tConnection = &strm;
        bool ok = false;
        for (size_t left = keep_alive_max_count_; left > 0; --left) {
            if (!strm.buffered() && !keepAlive(sock)) break;
            bool closed = false;
            ok = process_request(strm, left == 1, closed, nullptr);
            if (!ok || closed || strm.taken()) break;
        }
        tConnection = nullptr;
        if (!strm.taken()) {
            ::shutdown(sock, SHUT_RDWR);
            ::close(sock);
        }
        return ok;
    }
    // Waits up to the keep-alive timeout for the next request, giving up when the server stops.
    bool keepAlive(int sock) const {
        const auto end =
            std::chrono::steady_clock::now() + std::chrono::seconds(keep_alive_timeout_sec_);
        while (svr_sock_ != INVALID_SOCKET) {
            pollfd p{sock, POLLIN, 0};
            const int r = ::poll(&p, 1, 100);
            if (r > 0) return true;
            if (r < 0 && errno != EINTR) return false;
            if (std::chrono::steady_clock::now() >= end) return false;
        }
        return false;
    }
};

} // namespace

class Server::Impl {
public:
    explicit Impl(ServerOptions o)
        : mOpt(std::move(o)), mProject(mOpt.input, mOpt.allowPaths),
          mWatcher([this](const std::set<std::string>& files) { onFilesChanged(files); }, 15),
          mSim(
              [this](long f) {
                  publish("frame", json{{"frame", f}, {"run", mRunId.load()}});
              },
              [this](int code, const std::string& log) {
                  publish("sim", json{{"running", false},
                                      {"exit", code},
                                      {"log", log},
                                      {"run", mRunId.load()},
                                      {"on", mSimulateOn.load()}});
              }) {
        if (mOpt.token.empty()) mOpt.token = randomToken();
        if (mOpt.webDir.empty()) mOpt.webDir = GALE_LIVE_WEB_DIR;
        if (mOpt.modulesDir.empty()) mOpt.modulesDir = GALE_LIVE_NODE_MODULES;
    }

    bool start(std::string& error) {
        std::error_code ec;
        if (!fs::is_regular_file(mOpt.input, ec)) {
            error = mOpt.input + ": no such file";
            return false;
        }
        {
            std::lock_guard<std::mutex> lock(mMutex);
            mProject.load();
        }
        if (!mWatcher.start(error) || !mEvents.start(error)) return false;
        watchProjectFiles();
        routes();
        // SO_REUSEADDR only: cpp-httplib's default adds SO_REUSEPORT, with which a second
        // server on the same port would silently share its connections.
        mHttp.set_socket_options([](int sock) {
            int yes = 1;
            setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
        });
        mHttp.set_payload_max_length(64 * 1024);
        mHttp.set_keep_alive_timeout(5);
        mHttp.new_task_queue = [] { return new httplib::ThreadPool(16); };
        if (mOpt.port == 0) {
            mPort = mHttp.bind_to_any_port(mOpt.host);
            if (mPort <= 0) {
                error = "cannot listen on " + mOpt.host + ": no free port";
                return false;
            }
        } else if (!mHttp.bind_to_port(mOpt.host, mOpt.port)) {
            error = "cannot listen on " + mOpt.host + ":" + std::to_string(mOpt.port) +
                    " (in use? try --port 0 for a free one)";
            return false;
        } else {
            mPort = mOpt.port;
        }
        mThread = std::thread([this] { mHttp.listen_after_bind(); });
        return true;
    }

    void stop() {
        std::lock_guard<std::mutex> stopping(mStopMutex);
        if (mStopped) return;
        mStopped = true;
        mSimulateOn = false;
        mEvents.stop();
        {
            std::lock_guard<std::mutex> simLock(mSimMutex);
            mShuttingDown = true; // (a reload on the watcher's thread starts no new run now)
            mSim.stop();
            if (!mTempDir.empty()) { // the simulations' folder this server made under /tmp
                std::error_code ec;
                fs::remove_all(mTempDir, ec);
            }
        }
        mWatcher.stop();
        mHttp.stop();
        if (mThread.joinable()) mThread.join();
        {
            std::lock_guard<std::mutex> lock(mWaitMutex);
            mDone = true;
        }
        mWaitCv.notify_all();
    }

    void wait() {
        std::unique_lock<std::mutex> lock(mWaitMutex);
        mWaitCv.wait(lock, [&] { return mDone; });
    }

    int port() const { return mPort; }

    void publish(const std::string& type, const json& data) {
        mEvents.publish(type, jsonText(data));
    }
    static void reply(httplib::Response& res, const json& data) {
        res.set_content(jsonText(data), kJson);
    }
    const std::string& token() const { return mOpt.token; }
    std::string url() const {
        return "http://" + (mOpt.host == "0.0.0.0" ? std::string("127.0.0.1") : mOpt.host) + ":" +
               std::to_string(mPort) + "/?token=" + mOpt.token;
    }

private:
    void watchProjectFiles() {
        std::set<std::string> files, patterns;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            files.insert(mProject.files().begin(), mProject.files().end());
            patterns.insert(mProject.patterns().begin(), mProject.patterns().end());
        }
        mWatcher.watch(files, patterns);
    }

    // A reload after edits: the new files are watched; `field` when it compiled, else
    // `diagnostics`.
    void onFilesChanged(const std::set<std::string>& changed) {
        try {
            reloadAndNotify(changed);
        } catch (const std::exception& e) { // (out of memory): the page hears of it
            publish("diagnostics", json{{"error", e.what()}});
        }
    }

    void reloadAndNotify(const std::set<std::string>& changed) {
        const auto t0 = std::chrono::steady_clock::now();
        json event;
        bool ok;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            ok = mProject.load();
            json diags = stateJson(mProject, mTime)["diagnostics"];
            event = {{"changed", std::vector<std::string>(changed.begin(), changed.end())},
                     {"diagnostics", diags},
                     {"reloadMs", std::chrono::duration<double, std::milli>(
                                      std::chrono::steady_clock::now() - t0)
                                      .count()}};
        }
        watchProjectFiles();
        publish(ok ? "field" : "diagnostics", event);
        // Live re-simulation: while Simulate is on, an edit that compiles restarts the run from
        // the first frame with the new scene (the old child killed by its pid).
        if (ok && mSimulateOn) {
            std::string error;
            if (!startSimulation(true, error))
                publish("sim", json{{"running", false}, {"exit", 1}, {"log", error}});
        }
    }

    // Starts (or, `restart`, replaces) the background `gale sim` in a new folder. False with
    // `error` (and the HTTP status in `status`) when it cannot.
    bool startSimulation(bool restart, std::string& error, int* status = nullptr) {
        std::lock_guard<std::mutex> simLock(mSimMutex);
        auto refuse = [&](int code, const std::string& message) {
            if (status) *status = code;
            error = message;
            return false;
        };
        if (mShuttingDown) return refuse(503, "the server is stopping");
        if (restart && !mSimulateOn) return true; // (stopped since the edit was seen)
        if (mOpt.galeExecutable.empty())
            return refuse(409, "simulation is not available in this server");
        std::vector<SimObject> objects;
        long first, last;
        bool scene;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            objects = mProject.simObjects();
            first = mProject.frameStart();
            last = mProject.frameEnd();
            scene = mProject.isScene();
        }
        if (!scene || objects.empty())
            return refuse(
                409, "nothing to simulate: give gale live a SCENE.toml with [[cloth]] or [[hair]]");
        std::string dir = mOpt.simDir;
        if (dir.empty()) {
            if (mTempDir.empty()) {
                char tmpl[] = "/tmp/gale-live-XXXXXX";
                if (!mkdtemp(tmpl)) return refuse(500, "cannot create a folder for the simulation");
                mTempDir = tmpl;
            }
            dir = mTempDir + "/sim" + std::to_string(mRuns + 1);
        }
        const std::string oldDir = mSim.outDir();
        const std::vector<SimObject> oldObjects = mSim.objects();
        const int oldRun = mRunId;
        const bool oldStepped = mSim.lastFrame() > first; // (wrote a frame after its first)
        mSim.stop(true); // (its exit event carries the old run's id)
        ++mRuns;
        mRunId = mRuns;
        if (!mSim.start(mOpt.galeExecutable, mOpt.input, dir, objects, first, last, error))
            return refuse(500, error);
        // The run an edit replaced is kept to compare with (/api/frame?run=), the one it had
        // replaced thrown away; a run replaced before it stepped (a slider still moving) is
        // thrown away instead, and the one before it kept.
        if (restart && !oldDir.empty() && oldDir != dir) {
            const bool keep = oldStepped || mPrevDir.empty();
            const std::string drop = keep ? mPrevDir : oldDir;
            if (mOpt.simDir.empty() && !drop.empty() && drop != dir) {
                std::error_code ec;
                fs::remove_all(drop, ec);
            }
            if (keep) {
                mPrevDir = oldDir;
                mPrevRun = oldRun;
                mPrevObjects = oldObjects;
            }
        }
        publish("sim", json{{"running", true},
                            {"dir", dir},
                            {"frames", {first, last}},
                            {"run", mRunId.load()},
                            {"restart", restart},
                            {"previous", mPrevRun},
                            {"on", true}});
        return true;
    }

    bool authorised(const httplib::Request& req, httplib::Response& res) {
        if (!hostAllowed(req.get_header_value("Host"), mOpt.host, mPort)) {
            fail(res, 403,
                 "the Host header must name this server (127.0.0.1:" + std::to_string(mPort) + ")");
            return false;
        }
        const std::string token = req.has_param("token") ? req.get_param_value("token")
                                                         : req.get_header_value("X-Gale-Token");
        if (!sameToken(token, mOpt.token)) {
            fail(res, 403,
                 "missing or wrong token: open the URL gale live printed (it has ?token=...)");
            return false;
        }
        return true;
    }

    void asset(httplib::Response& res, const std::string& path, const char* mime,
               bool substitute = false) {
        std::string body;
        if (!readFile(path, body, 8u << 20)) {
            fail(res, 404, path + ": missing (was the page's npm set-up run? see docs/live.md)");
            return;
        }
        if (substitute)
            for (size_t p; (p = body.find("{{TOKEN}}")) != std::string::npos;)
                body.replace(p, 9, mOpt.token);
        res.set_header("Cache-Control", "no-store");
        res.set_content(body, mime);
    }

    void routes() {
        mHttp.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
            return authorised(req, res) ? httplib::Server::HandlerResponse::Unhandled
                                        : httplib::Server::HandlerResponse::Handled;
        });
        mHttp.set_error_handler([](const httplib::Request&, httplib::Response& res) {
            if (res.body.empty())
                res.set_content(errorJson(res.status == 404 ? "no such endpoint"
                                                            : "bad request (HTTP " +
                                                                  std::to_string(res.status) + ")"),
                                kJson);
        });
        mHttp.set_exception_handler(
            [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
                std::string what = "internal error";
                try {
                    if (ep) std::rethrow_exception(ep);
                } catch (const std::exception& e) {
                    what = e.what();
                } catch (...) {
                }
                fail(res, 500, what);
            });
        const std::string web = mOpt.webDir, mods = mOpt.modulesDir;
        mHttp.Get("/", [=](const httplib::Request&, httplib::Response& res) {
            asset(res, web + "/index.html", "text/html; charset=utf-8", true);
        });
        // Only these files are served from disk besides the scene's own.
        const std::map<std::string, std::pair<std::string, const char*>> assets = {
            {"app.js", {web + "/app.js", kScript}},
            {"panels.js", {web + "/panels.js", kScript}},
            {"view.js", {web + "/view.js", kScript}},
            {"style.css", {web + "/style.css", "text/css"}},
            {"three.module.js", {mods + "/three/build/three.module.js", kScript}},
            {"three.core.js", {mods + "/three/build/three.core.js", kScript}},
            {"OrbitControls.js", {mods + "/three/examples/jsm/controls/OrbitControls.js", kScript}},
        };
        mHttp.Get(R"(/assets/([A-Za-z0-9_.-]+))",
                  [this, assets](const httplib::Request& req, httplib::Response& res) {
                      auto a = assets.find(req.matches[1]);
                      if (a == assets.end()) return fail(res, 404, "no such asset");
                      asset(res, a->second.first, a->second.second);
                  });
        mHttp.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
            json state;
            {
                std::lock_guard<std::mutex> lock(mMutex);
                state = stateJson(mProject, mTime);
            }
            state["eventStreams"] = mEvents.count();
            reply(res, state);
        });
        mHttp.Get("/api/scene", [this](const httplib::Request&, httplib::Response& res) {
            std::lock_guard<std::mutex> lock(mMutex);
            reply(res, sceneJson(mProject));
        });
        mHttp.Get("/api/colliders", [this](const httplib::Request& req, httplib::Response& res) {
            double t = 0;
            if (!numberParam(req, "t", 0.0, t)) return fail(res, 400, "t: a time in seconds");
            std::lock_guard<std::mutex> lock(mMutex);
            reply(res, collidersJson(mProject, t));
        });
        mHttp.Get("/api/file", [this](const httplib::Request& req, httplib::Response& res) {
            const std::string path =
                fs::path(req.get_param_value("path")).lexically_normal().string();
            bool known;
            {
                std::lock_guard<std::mutex> lock(mMutex);
                const auto& files = mProject.files();
                known = std::find(files.begin(), files.end(), path) != files.end();
            }
            std::string text;
            if (!known)
                return fail(res, 403,
                            "not one of the scene's files: " + req.get_param_value("path"));
            if (!readFile(path, text, 4u << 20)) return fail(res, 404, path + ": cannot read");
            reply(res, json{{"path", path}, {"text", text}});
        });
        mHttp.Get("/api/field",
                  [this](const httplib::Request& req, httplib::Response& res) { field(req, res); });
        mHttp.Get("/api/run",
                  [this](const httplib::Request&, httplib::Response& res) { run(res); });
        mHttp.Get("/api/frame",
                  [this](const httplib::Request& req, httplib::Response& res) { frame(req, res); });
        mHttp.Post("/api/param", [this](const httplib::Request& req, httplib::Response& res) {
            setParam(req, res);
        });
        mHttp.Post("/api/ramp", [this](const httplib::Request& req, httplib::Response& res) {
            setRamp(req, res);
        });
        mHttp.Post("/api/simulate", [this](const httplib::Request& req, httplib::Response& res) {
            simulate(req, res);
        });
        // The socket is handed to EventStreams (no worker is held while the stream is open);
        // Last-Event-ID (an EventSource reconnecting) resumes after the last event it had.
        mHttp.Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) {
            SocketStream* conn = tConnection;
            if (!conn) return fail(res, 500, "no connection to stream events on");
            uint64_t after = mEvents.latest();
            const std::string last = req.get_header_value("Last-Event-ID");
            if (!last.empty()) {
                char* end = nullptr;
                const unsigned long long id = std::strtoull(last.c_str(), &end, 10);
                if (end == last.c_str() + last.size() && id < after) after = id;
            }
            conn->take();
            mEvents.adopt(conn->socket(), after);
        });
    }

    void field(const httplib::Request& req, httplib::Response& res) {
        FieldRequest r;
        int lines = 256;
        double a[3], b[3];
        fields::FieldPtr fieldPtr;
        double fps;
        viz::Box3 box;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            fieldPtr = mProject.field();
            fps = mProject.fps();
            box = mProject.box();
        }
        // The rake defaults to a vertical line across the upwind face of the box.
        const double def[6] = {
            box.lo[0] + 0.02 * (box.hi[0] - box.lo[0]), box.lo[1], 0.5 * (box.lo[2] + box.hi[2]),
            box.lo[0] + 0.02 * (box.hi[0] - box.lo[0]), box.hi[1], 0.5 * (box.lo[2] + box.hi[2])};
        bool ok = numberParam(req, "t", 0.0, r.time) && intParam(req, "axis", 2, 0, 2, r.axis) &&
                  numberParam(req, "plane", 0.0, r.planeValue) &&
                  intParam(req, "res", 128, 8, 512, r.res) &&
                  intParam(req, "arrows", 16, 0, 32, r.arrows) &&
                  intParam(req, "lines", 256, 0, 1024, lines) &&
                  numberParam(req, "speedMax", 0.0, r.speedMax);
        const char* names[6] = {"ax", "ay", "az", "bx", "by", "bz"};
        for (int k = 0; ok && k < 6; ++k)
            ok = numberParam(req, names[k], def[k], k < 3 ? a[k] : b[k - 3]);
        if (!ok)
            return fail(res, 400,
                        "bad query: t, plane, speedMax and ax..bz are numbers; axis 0-2, res "
                        "8-512, arrows 0-32, "
                        "lines 0-1024 are integers");
        if (!fieldPtr)
            return fail(res, 409, "the input does not compile; see /api/state's diagnostics");
        r.rake.count = lines;
        r.rake.a = {a[0], a[1], a[2]};
        r.rake.b = {b[0], b[1], b[2]};
        FieldFrame frame;
        std::string error;
        if (!computeFieldFrame(*fieldPtr, fps, box, r, frame, error)) return fail(res, 422, error);
        viz::SliceOverlays overlays;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            overlays = mProject.overlays(r.time);
            mTime = r.time;
        }
        reply(res, fieldJson(frame, overlays));
    }

    void frame(const httplib::Request& req, httplib::Response& res) {
        int n = 0;
        if (!intParam(req, "n", -1, -1000000, 1000000, n))
            return fail(res, 400, "n: a frame number");
        int want = 0;
        if (!intParam(req, "run", 0, 0, 1 << 30, want)) return fail(res, 400, "run: a run number");
        std::string dir;
        std::vector<SimObject> simObjects;
        int run;
        {
            std::lock_guard<std::mutex> simLock(mSimMutex);
            const bool previous = want > 0 && want == mPrevRun;
            if (want > 0 && !previous && want != mRunId)
                return fail(res, 404,
                            "run " + std::to_string(want) +
                                " is gone (the current and the one it replaced are kept)");
            dir = previous ? mPrevDir : mSim.outDir();
            simObjects = previous ? mPrevObjects : mSim.objects();
            run = previous ? mPrevRun : mRunId.load();
        }
        if (dir.empty()) return fail(res, 404, "no simulation yet: POST /api/simulate");
        std::vector<viz::GeometryOverlay> rest;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            rest = mProject.restGeometry();
        }
        json objects = json::array();
        for (const SimObject& o : simObjects) {
            viz::GeometryOverlay g;
            std::string error;
            if (!viz::loadFrameGeometry(simFramePath(dir, o.name, n, o.format), g, error))
                return fail(res, 404, "frame " + std::to_string(n) + " is not written yet");
            g.label = o.name;
            json j = geometryJson(g);
            // Strain against the rest shape the solver starts from (viz/strain.h), per vertex.
            for (const viz::GeometryOverlay& r : rest)
                if (r.label == o.name) {
                    json strain = json::array();
                    for (double x : viz::vertexStrain(r, g))
                        strain.push_back(std::round(x * 1e4) / 1e4);
                    j["strain"] = strain;
                }
            objects.push_back(j);
        }
        reply(res, json{{"frame", n}, {"run", run}, {"objects", objects}});
    }

    // The simulation's run.json (written at most once a second while it runs, then at the end)
    // summarised per frame for the timeline: contacts, halved and recovered substeps, the
    // largest stretch against [solver] over_stretch, failures, and each object's events.
    void run(httplib::Response& res) {
        const std::string dir = mSim.outDir();
        if (dir.empty()) return fail(res, 404, "no simulation yet: POST /api/simulate");
        std::string text;
        if (!readFile((fs::path(dir) / "run.json").string(), text, 64u << 20))
            return reply(res, json{{"status", "starting"}, {"frames", json::array()}});
        const json run = json::parse(text, nullptr, false);
        if (run.is_discarded() || !run.is_object())
            return reply(res, json{{"status", "starting"}, {"frames", json::array()}});
        const double overStretch = run.value("/settings/solver/over_stretch"_json_pointer, 1.5);
        json frames = json::array();
        for (const json& f : run.value("frames", json::array())) {
            long contacts = 0, halved = 0, recovered = 0;
            double stretch = 0;
            json events = json::array();
            for (const json& o : f.value("objects", json::array())) {
                contacts += o.value("contacts", 0L);
                halved += o.value("rejected_substeps", 0L);
                recovered += o.value("recovered_substeps", 0L);
                stretch = std::max(stretch, o.value("max_stretch", 0.0));
                for (const json& e : o.value("events", json::array()))
                    if (e.is_string())
                        events.push_back(o.value("name", std::string()) + ": " +
                                         e.get<std::string>());
            }
            frames.push_back({{"frame", f.value("frame", 0L)},
                              {"failed", f.value("failed", false)},
                              {"contacts", contacts},
                              {"halved", halved},
                              {"recovered", recovered},
                              {"maxStretch", stretch},
                              {"overStretched", stretch >= overStretch},
                              {"events", events}});
        }
        reply(res, json{{"status", run.value("status", std::string())},
                        {"overStretch", overStretch},
                        {"frames", frames}});
    }

    bool bodyJson(const httplib::Request& req, httplib::Response& res, json& out) {
        out = json::parse(req.body, nullptr, false);
        if (out.is_discarded() || !out.is_object()) {
            fail(res, 400, "the body must be a JSON object");
            return false;
        }
        return true;
    }

    // Reloads at once after an edit (the reply is the new state); the watcher's event follows.
    void replyState(httplib::Response& res) {
        std::lock_guard<std::mutex> lock(mMutex);
        mProject.load();
        reply(res, stateJson(mProject, mTime));
    }

    void setParam(const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!bodyJson(req, res, body)) return;
        const json& name = body["name"];
        const json& value = body["value"];
        std::vector<double> v;
        if (value.is_number()) v.push_back(value.get<double>());
        if (value.is_array())
            for (const json& x : value) {
                if (!x.is_number()) return fail(res, 400, "value: a number or an array of numbers");
                v.push_back(x.get<double>());
            }
        if (!name.is_string() || v.empty())
            return fail(res, 400,
                        "expected {\"name\": \"speed\", \"value\": 4.5} (value a number or array)");
        const std::string fieldName = body.contains("field") && body["field"].is_string()
                                          ? body["field"].get<std::string>()
                                          : "";
        std::string error;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            if (!mProject.setParam(name.get<std::string>(), fieldName, v, error))
                return fail(res, 422, error);
        }
        replyState(res);
    }

    void setRamp(const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!bodyJson(req, res, body)) return;
        if (!body["id"].is_number_integer() || !body["points"].is_array())
            return fail(
                res, 400,
                "expected {\"id\": 0, \"points\": [{\"position\", \"value\", \"interp\"}, ...]}");
        std::vector<RampPoint> points;
        for (const json& p : body["points"]) {
            RampPoint q;
            if (!p.is_object() || !p["position"].is_number() || !p["interp"].is_number_integer())
                return fail(res, 400,
                            "each point: {\"position\": number, \"value\": number or [r,g,b], "
                            "\"interp\": 0-4}");
            q.position = p["position"].get<double>();
            q.interp = p["interp"].get<int>();
            if (p["value"].is_number())
                q.value.push_back(p["value"].get<double>());
            else if (p["value"].is_array())
                for (const json& x : p["value"]) {
                    if (!x.is_number())
                        return fail(res, 400, "a ramp value: a number or [r, g, b]");
                    q.value.push_back(x.get<double>());
                }
            points.push_back(std::move(q));
        }
        std::string error;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            if (!mProject.setRamp(body["id"].get<int>(), points, error))
                return fail(res, 422, error);
        }
        replyState(res);
    }

    void simulate(const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!bodyJson(req, res, body)) return;
        const std::string action = body.value("action", std::string("start"));
        if (action == "stop") {
            std::lock_guard<std::mutex> simLock(mSimMutex);
            mSimulateOn = false;
            mSim.stop();
        } else if (action == "start") {
            std::string error;
            int status = 500;
            if (!startSimulation(false, error, &status)) return fail(res, status, error);
            mSimulateOn = true;
        } else {
            return fail(res, 400, "action: start or stop");
        }
        reply(res, json{{"running", mSim.running()},
                        {"dir", mSim.outDir()},
                        {"last", mSim.lastFrame()},
                        {"run", mRunId.load()},
                        {"on", mSimulateOn.load()}});
    }

    ServerOptions mOpt;
    std::mutex mMutex; // the project and mTime
    Project mProject;
    double mTime = 0.0;
    EventStreams mEvents;
    FileWatcher mWatcher;
    SimJob mSim;
    HttpServer mHttp;
    std::thread mThread;
    int mPort = 0;
    std::string mTempDir;
    int mRuns = 0;
    std::mutex mSimMutex;       // starting and stopping the simulation, mTempDir
    bool mShuttingDown = false; // (under mSimMutex) stop() has begun
    std::string mPrevDir;       // (under mSimMutex) the run the last edit replaced
    int mPrevRun = 0;
    std::vector<SimObject> mPrevObjects;
    std::atomic<int> mRunId{0};           // the current run, in its events
    std::atomic<bool> mSimulateOn{false}; // Simulate pressed and not stopped: edits re-simulate
    std::mutex mStopMutex, mWaitMutex;
    std::condition_variable mWaitCv;
    bool mStopped = false, mDone = false;
};

Server::Server(ServerOptions options) : mImpl(std::make_unique<Impl>(std::move(options))) {}
Server::~Server() {
    mImpl->stop();
}
bool Server::start(std::string& error) {
    return mImpl->start(error);
}
void Server::wait() {
    mImpl->wait();
}
void Server::stop() {
    mImpl->stop();
}
int Server::port() const {
    return mImpl->port();
}
const std::string& Server::token() const {
    return mImpl->token();
}
std::string Server::url() const {
    return mImpl->url();
}

} // namespace gale::live
