// `gale wedge`'s library part: --vary parsing, variants and their folder names, task lines,
// completion checks, manifest lines and the local process pool (posix_spawn, one process group
// per task so a killed wedge takes its running simulations with it).
#include "cli/wedge/wedge.h"

#include "cli/common.h"
#include "io/pointset.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

extern char** environ;

namespace gale::cli {

namespace fs = std::filesystem;

namespace {

std::string trim(const std::string& s) {
    const size_t a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return "";
    const size_t b = s.find_last_not_of(" \t");
    return s.substr(a, b - a + 1);
}

std::vector<std::string> splitDots(const std::string& key) {
    std::vector<std::string> parts;
    size_t start = 0;
    for (;;) {
        const size_t dot = key.find('.', start);
        parts.push_back(
            key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
        if (dot == std::string::npos) return parts;
        start = dot + 1;
    }
}

// The last `n` dotted parts of `key`.
std::string suffix(const std::vector<std::string>& parts, size_t n) {
    std::string s;
    for (size_t i = parts.size() - n; i < parts.size(); ++i) s += (s.empty() ? "" : ".") + parts[i];
    return s;
}

// The JSON of a --vary value: a number when the whole text is one, else a string.
std::string jsonValue(const std::string& text) {
    const char* begin = text.c_str();
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (!text.empty() && end == begin + text.size() && std::isfinite(v)) return io::formatNumber(v);
    return jsonString(text);
}

// The running tasks' process groups, for the signal handler.
constexpr int kMaxJobs = 256;
volatile sig_atomic_t gRunning[kMaxJobs];

extern "C" void forwardSignal(int sig) {
    for (int i = 0; i < kMaxJobs; ++i)
        if (gRunning[i] > 0) kill(-static_cast<pid_t>(gRunning[i]), sig);
    signal(sig, SIG_DFL);
    raise(sig);
}

} // namespace

bool parseVary(const std::string& text, VaryAxis& out, std::string& error) {
    const size_t eq = text.find('=');
    out = VaryAxis{};
    if (eq != std::string::npos) out.key = trim(text.substr(0, eq));
    const std::vector<std::string> parts = splitDots(out.key);
    bool ok = eq != std::string::npos && !out.key.empty();
    for (const std::string& p : parts)
        ok = ok && !p.empty() && p.find_first_of(" \t") == std::string::npos;
    if (ok) {
        const std::string rest = text.substr(eq + 1);
        int depth = 0;
        char quote = 0;
        std::string current;
        for (char c : rest) {
            if (quote) {
                if (c == quote) quote = 0;
            } else if (c == '"' || c == '\'') {
                quote = c;
            } else if (c == '[' || c == '{' || c == '(') {
                ++depth;
            } else if (c == ']' || c == '}' || c == ')') {
                --depth;
            } else if (c == ',' && depth == 0) {
                out.values.push_back(trim(current));
                current.clear();
                continue;
            }
            current += c;
        }
        out.values.push_back(trim(current));
        for (const std::string& v : out.values) ok = ok && !v.empty();
        ok = ok && depth == 0 && quote == 0;
    }
    if (!ok)
        error = "--vary '" + text +
                "': expected KEY=V1,V2,... with a dotted scene path and values as --set takes "
                "them (cloth.cape.lift=0.1,0.3,0.5; vectors in brackets: "
                "windicator.direction=[1,0,0],[1,0,1])";
    return ok;
}

std::string sanitiseName(const std::string& text) {
    std::string out;
    for (unsigned char c : text) {
        const bool keep =
            std::isalnum(c) || c == '.' || c == '_' || c == '=' || c == '+' || c == '-';
        out += keep ? static_cast<char>(c) : '_';
    }
    return out;
}

std::vector<std::string> shortKeyNames(const std::vector<std::string>& keys) {
    std::vector<std::string> shortNames;
    for (size_t a = 0; a < keys.size(); ++a) {
        const std::vector<std::string> parts = splitDots(keys[a]);
        std::string name = keys[a];
        for (size_t n = 1; n <= parts.size(); ++n) {
            const std::string candidate = suffix(parts, n);
            bool unique = true;
            for (size_t b = 0; b < keys.size() && unique; ++b) {
                if (b == a) continue;
                const std::vector<std::string> other = splitDots(keys[b]);
                unique = other.size() < n || suffix(other, n) != candidate;
            }
            if (unique) {
                name = candidate;
                break;
            }
        }
        shortNames.push_back(name);
    }
    return shortNames;
}

std::vector<Variant> expandVariants(const std::vector<VaryAxis>& axes) {
    std::vector<std::string> keys;
    for (const VaryAxis& a : axes) keys.push_back(a.key);
    const std::vector<std::string> shortNames = shortKeyNames(keys);
    size_t total = 1;
    for (const VaryAxis& a : axes) total *= a.values.size();
    std::vector<Variant> out;
    const int width = total > 1000 ? static_cast<int>(std::to_string(total - 1).size()) : 3;
    for (size_t i = 0; i < total; ++i) {
        Variant v;
        v.index = static_cast<int>(i);
        char id[32];
        std::snprintf(id, sizeof id, "v%0*zu", width, i);
        v.id = id;
        std::string name = v.id;
        size_t rest = i;
        std::vector<size_t> pick(axes.size());
        for (size_t a = axes.size(); a-- > 0;) {
            pick[a] = rest % axes[a].values.size();
            rest /= axes[a].values.size();
        }
        for (size_t a = 0; a < axes.size(); ++a) {
            const std::string& value = axes[a].values[pick[a]];
            v.values.emplace_back(axes[a].key, value);
            v.sets.push_back(axes[a].key + "=" + value);
            name += "_" + shortNames[a] + "=" + value;
        }
        name = sanitiseName(name);
        if (name.size() > 120) name = name.substr(0, 120); // the id keeps it unique
        v.folder = name;
        out.push_back(std::move(v));
    }
    return out;
}

std::string shellQuote(const std::string& text) {
    std::string out = "'";
    for (char c : text) {
        if (c == '\'')
            out += "'\\''";
        else
            out += c;
    }
    return out + "'";
}

std::string taskCommand(const std::string& galeBinary, const std::string& variantDir, int threads,
                        const std::vector<std::string>& allowPaths, const std::string& cache) {
    std::string sim = shellQuote(galeBinary) + " sim scene.toml -o . --resume";
    if (threads != 1) sim += " --threads " + std::to_string(threads);
    if (!cache.empty()) sim += " --cache " + shellQuote(cache);
    for (const std::string& dir : allowPaths) sim += " --allow-path " + shellQuote(dir);
    return "cd " + shellQuote(variantDir) + " && if [ ! -f DONE ]; then " + sim +
           " >> log.txt 2>&1 && touch DONE; fi";
}

bool variantComplete(const Variant& v, const std::string& dir) {
    std::error_code ec;
    if (!fs::exists(fs::path(dir) / "DONE", ec)) return false;
    for (const VariantObject& o : v.objects)
        for (int f = v.frameStart; f <= v.frameEnd; ++f) {
            char buf[32];
            std::snprintf(buf, sizeof buf, ".%04d.", f);
            if (!fs::exists(fs::path(dir) / (o.name + buf + o.format), ec)) return false;
        }
    return true;
}

std::string manifestLine(const Variant& v, const std::string& dir, const std::string& command,
                         const std::string& status, int exitCode) {
    std::string s = "{\"id\": " + jsonString(v.id) + ", \"index\": " + std::to_string(v.index) +
                    ", \"folder\": " + jsonString(v.folder) + ", \"path\": " + jsonString(dir) +
                    ", \"values\": {";
    for (size_t i = 0; i < v.values.size(); ++i)
        s += (i ? ", " : "") + jsonString(v.values[i].first) + ": " + jsonValue(v.values[i].second);
    s += "}, \"frames\": [" + std::to_string(v.frameStart) + ", " + std::to_string(v.frameEnd) +
         "], \"objects\": [";
    for (size_t i = 0; i < v.objects.size(); ++i)
        s += (i ? ", " : "") + std::string("{\"name\": ") + jsonString(v.objects[i].name) +
             ", \"format\": " + jsonString(v.objects[i].format) + "}";
    s += "], \"scene\": " + jsonString((fs::path(dir) / "scene.toml").string()) +
         ", \"command\": " + jsonString(command) + ", \"status\": " + jsonString(status);
    if (exitCode >= 0) s += ", \"exit_code\": " + std::to_string(exitCode);
    return s + "}";
}

void runPool(const std::vector<std::string>& commands, int jobs,
             const std::function<void(size_t, int)>& done) {
    jobs = std::max(1, std::min(jobs, kMaxJobs));
    for (int i = 0; i < kMaxJobs; ++i) gRunning[i] = 0;
    struct sigaction action {};
    action.sa_handler = forwardSignal;
    sigemptyset(&action.sa_mask);
    struct sigaction oldInt {
    }, oldTerm{}, oldHup{};
    sigaction(SIGINT, &action, &oldInt);
    sigaction(SIGTERM, &action, &oldTerm);
    sigaction(SIGHUP, &action, &oldHup);

    std::map<pid_t, std::pair<size_t, int>> running; // pid -> (command, slot)
    size_t next = 0;
    while (next < commands.size() || !running.empty()) {
        while (next < commands.size() && static_cast<int>(running.size()) < jobs) {
            int slot = 0;
            while (gRunning[slot] != 0) ++slot;
            posix_spawnattr_t attr;
            posix_spawnattr_init(&attr);
            posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
            posix_spawnattr_setpgroup(&attr, 0);
            sigset_t defaults;
            sigemptyset(&defaults);
            sigaddset(&defaults, SIGINT);
            sigaddset(&defaults, SIGTERM);
            sigaddset(&defaults, SIGHUP);
            posix_spawnattr_setsigdefault(&attr, &defaults);
            const std::string& line = commands[next];
            char* argv[] = {const_cast<char*>("sh"), const_cast<char*>("-c"),
                            const_cast<char*>(line.c_str()), nullptr};
            pid_t pid = 0;
            const int rc = posix_spawn(&pid, "/bin/sh", nullptr, &attr, argv, environ);
            posix_spawnattr_destroy(&attr);
            if (rc != 0) {
                done(next++, 127);
                continue;
            }
            gRunning[slot] = pid;
            running[pid] = {next++, slot};
        }
        int status = 0;
        const pid_t pid = waitpid(-1, &status, 0);
        if (pid < 0) {
            if (errno == EINTR) continue;
            break; // no children left (should not happen)
        }
        auto it = running.find(pid);
        if (it == running.end()) continue;
        gRunning[it->second.second] = 0;
        const size_t index = it->second.first;
        running.erase(it);
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        done(index, code);
    }
    sigaction(SIGINT, &oldInt, nullptr);
    sigaction(SIGTERM, &oldTerm, nullptr);
    sigaction(SIGHUP, &oldHup, nullptr);
}

} // namespace gale::cli
