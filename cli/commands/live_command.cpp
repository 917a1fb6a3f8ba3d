// `gale live (SCENE.toml | FILE.se) [--port N] [--no-open] [--host H]`: starts the live server
// (live/server.h), prints its URL with the token on stderr, opens a browser unless --no-open,
// and serves until SIGINT or SIGTERM.
#include "cli/commands.h"
#include "cli/common.h"
#include "live/server.h"

#include <CLI/CLI.hpp>

#include <csignal>
#include <fcntl.h>
#include <iostream>
#include <memory>
#include <pthread.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace gale::cli {

namespace {

struct LiveOptions {
    std::string input;
    int port = 0;
    bool noOpen = false;
    std::string host = "127.0.0.1";
    std::vector<std::string> allowPaths;
};

std::string selfPath() {
    char buf[4096];
    const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
    return n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string();
}

// xdg-open URL in the background when there is a display; quietly nothing otherwise.
void openBrowser(const std::string& url) {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((!display || !*display) && (!wayland || !*wayland)) return;
    std::string prog = "xdg-open", arg = url;
    char* argv[] = {prog.data(), arg.data(), nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    pid_t pid;
    if (posix_spawnp(&pid, "xdg-open", &actions, nullptr, argv, environ) == 0)
        ::waitpid(pid, nullptr, WNOHANG);
    posix_spawn_file_actions_destroy(&actions);
}

int runLive(const LiveOptions& o) {
    if (o.port < 0 || o.port > 65535) {
        printError("--port " + std::to_string(o.port) + ": expected 0 (a free port) to 65535");
        return kExitUsage;
    }
    if (o.host != "127.0.0.1" && o.host != "localhost" && o.host != "::1")
        std::cerr << "gale live: warning: listening on " << o.host
                  << ", not loopback only: anyone who can reach it and has the token can edit the "
                     "scene's files\n";
    // SIGINT and SIGTERM are waited for on this thread; every thread the server starts
    // inherits the blocked mask.
    sigset_t stopSignals;
    sigemptyset(&stopSignals);
    sigaddset(&stopSignals, SIGINT);
    sigaddset(&stopSignals, SIGTERM);
    sigaddset(&stopSignals, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &stopSignals, nullptr);
    std::signal(SIGPIPE, SIG_IGN);

    live::ServerOptions options;
    options.input = o.input;
    options.host = o.host == "localhost" ? "127.0.0.1" : o.host;
    options.port = o.port;
    options.allowPaths = o.allowPaths;
    options.galeExecutable = selfPath();
    live::Server server(options);
    std::string error;
    if (!server.start(error)) {
        printError(error);
        return error.find("no such file") != std::string::npos ? kExitIo : kExitUsage;
    }
    std::cerr << "gale live: " << server.url() << std::endl;
    if (!o.noOpen) openBrowser(server.url());
    int sig = 0;
    sigwait(&stopSignals, &sig);
    server.stop();
    std::cerr << "gale live: stopped\n";
    return kExitOk;
}

} // namespace

Command addLiveCommand(CLI::App& app) {
    auto o = std::make_shared<LiveOptions>();
    CLI::App* sub = app.add_subcommand(
        "live",
        "Serve the wind of a scene or expression to a browser page, live: a slice coloured by "
        "speed, "
        "arrows, streamlines on a rake, the rigs and the cloth, sliders for `$name = v; # min, "
        "max` "
        "parameters and ramp editors for curve()/ccurve(); edits are written back into the files, "
        "and every file change recompiles and updates the page.");
    sub->add_option("input", o->input, "SCENE.toml or FILE.se")->required()->type_name("SCENE");
    sub->add_option("--port", o->port, "Port (0: a free one)")
        ->capture_default_str()
        ->type_name("N");
    sub->add_flag("--no-open", o->noOpen, "Do not open a browser");
    sub->add_option("--host", o->host, "Address to listen on (default loopback only)")
        ->capture_default_str()
        ->type_name("H");
    sub->add_option("--allow-path", o->allowPaths,
                    "Folders that files named in expressions may reach besides their own")
        ->type_name("DIR");
    sub->footer(
        "Prints 'gale live: http://127.0.0.1:PORT/?token=TOKEN' on stderr; every request needs "
        "the\n"
        "token. Stop with Ctrl-C. Exit codes: 2 bad flags or port in use, 3 missing input.");
    return {sub, [o] { return runLive(*o); }};
}

} // namespace gale::cli
