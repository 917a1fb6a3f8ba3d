// `gale wedge --farm slurm` and `gale wedge --status`: the Slurm array script over tasks.txt
// (per-task logs, requeue), its submission through sbatch, and each variant's progress read
// from manifest.jsonl and the frames on disk.
#include "cli/common.h"
#include "cli/wedge/wedge.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>

namespace gale::cli {

namespace {

namespace fs = std::filesystem;

// A value of the manifest's JSON lines: only what manifestLine writes (objects, arrays,
// strings, numbers, true/false/null).
struct Json {
    enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
    double number = 0.0;
    std::string text;
    std::vector<Json> items;
    std::vector<std::pair<std::string, Json>> fields;
    const Json* get(const std::string& key) const {
        for (const auto& f : fields)
            if (f.first == key) return &f.second;
        return nullptr;
    }
};

class JsonReader {
public:
    explicit JsonReader(const std::string& s) : mS(s) {}
    bool read(Json& out) {
        if (!value(out, 0)) return false;
        space();
        return mAt == mS.size();
    }

private:
    void space() {
        while (mAt < mS.size() && std::isspace(static_cast<unsigned char>(mS[mAt]))) ++mAt;
    }
    bool string(std::string& out) {
        if (mAt >= mS.size() || mS[mAt] != '"') return false;
        ++mAt;
        while (mAt < mS.size() && mS[mAt] != '"') {
            char c = mS[mAt++];
            if (c != '\\') {
                out += c;
                continue;
            }
            if (mAt >= mS.size()) return false;
            c = mS[mAt++];
            switch (c) {
            case 'n':
                out += '\n';
                break;
            case 't':
                out += '\t';
                break;
            case 'r':
                out += '\r';
                break;
            case 'b':
                out += '\b';
                break;
            case 'f':
                out += '\f';
                break;
            case 'u': {
                if (mAt + 4 > mS.size()) return false;
                const unsigned long cp = std::strtoul(mS.substr(mAt, 4).c_str(), nullptr, 16);
                mAt += 4;
                if (cp < 0x80) {
                    out += static_cast<char>(cp);
                } else if (cp < 0x800) {
                    out += static_cast<char>(0xC0 | (cp >> 6));
                    out += static_cast<char>(0x80 | (cp & 0x3F));
                } else {
                    out += static_cast<char>(0xE0 | (cp >> 12));
                    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
                    out += static_cast<char>(0x80 | (cp & 0x3F));
                }
                break;
            }
            default:
                out += c;
            }
        }
        if (mAt >= mS.size()) return false;
        ++mAt;
        return true;
    }
    bool value(Json& out, int depth) {
        if (depth > 32) return false;
        space();
        if (mAt >= mS.size()) return false;
        const char c = mS[mAt];
        if (c == '"') {
            out.kind = Json::String;
            return string(out.text);
        }
        if (c == '{' || c == '[') {
            const bool object = c == '{';
            out.kind = object ? Json::Object : Json::Array;
            ++mAt;
            space();
            if (mAt < mS.size() && mS[mAt] == (object ? '}' : ']')) return ++mAt, true;
            for (;;) {
                space();
                std::string key;
                if (object) {
                    if (!string(key)) return false;
                    space();
                    if (mAt >= mS.size() || mS[mAt++] != ':') return false;
                }
                Json item;
                if (!value(item, depth + 1)) return false;
                if (object)
                    out.fields.emplace_back(std::move(key), std::move(item));
                else
                    out.items.push_back(std::move(item));
                space();
                if (mAt >= mS.size()) return false;
                const char d = mS[mAt++];
                if (d == ',') continue;
                return d == (object ? '}' : ']');
            }
        }
        for (const char* word : {"true", "false", "null"})
            if (mS.compare(mAt, std::strlen(word), word) == 0) {
                mAt += std::strlen(word);
                out.kind = word[0] == 'n' ? Json::Null : Json::Bool;
                return true;
            }
        char* end = nullptr;
        out.number = std::strtod(mS.c_str() + mAt, &end);
        if (end == mS.c_str() + mAt) return false;
        out.kind = Json::Number;
        mAt = static_cast<size_t>(end - mS.c_str());
        return true;
    }

    const std::string& mS;
    size_t mAt = 0;
};

bool readAll(const fs::path& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}

// An #SBATCH value: quoted when it holds blanks or quotes (sbatch reads the quotes).
std::string sbatchWord(const std::string& s) {
    if (s.find_first_of(" \t\"'") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\\\"") : std::string(1, c);
    return q + "\"";
}

} // namespace

std::string slurmScript(const std::string& outDir, size_t tasks, int threads,
                        const std::string& partition, const std::string& scene) {
    const std::string logs = (fs::path(outDir) / "logs").string();
    std::string s =
        "#!/bin/bash\n"
        "# gale wedge: " +
        std::to_string(tasks) + " variant(s) of " + scene +
        ", one array task per line of\n"
        "# tasks.txt. Submit with `sbatch " +
        (fs::path(outDir) / "submit.sbatch").string() +
        "` (gale wedge --submit does);\n"
        "# re-submitting after failures or cancellations is safe: finished variants return at "
        "once,\n"
        "# interrupted ones resume after their last complete frame (gale sim --resume).\n";
    s += "#SBATCH --job-name=gale-wedge\n";
    s += "#SBATCH --array=1-" + std::to_string(tasks) + "\n";
    if (threads > 0) s += "#SBATCH --cpus-per-task=" + std::to_string(threads) + "\n";
    s += "#SBATCH --output=" + sbatchWord(logs + "/%A_%a.out") + "\n";
    s += "#SBATCH --open-mode=append\n";
    s += "#SBATCH --requeue\n";
    s += "#SBATCH --chdir=" + sbatchWord(outDir) + "\n";
    if (!partition.empty()) s += "#SBATCH --partition=" + sbatchWord(partition) + "\n";
    s += "set -u\n";
    s += "task=$(sed -n \"${SLURM_ARRAY_TASK_ID}p\" " +
         shellQuote((fs::path(outDir) / "tasks.txt").string()) + ")\n";
    s += "if [ -z \"$task\" ]; then echo \"gale wedge: no line ${SLURM_ARRAY_TASK_ID} in "
         "tasks.txt\" >&2; exit 2; fi\n";
    s += "echo \"gale wedge: task ${SLURM_ARRAY_TASK_ID} on $(hostname) at $(date -u +%FT%TZ): "
         "$task\"\n";
    s += "exec /bin/sh -c \"$task\"\n";
    return s;
}

int submitSlurm(const std::string& script, std::string& jobId) {
    // sbatch --parsable prints "jobid[;cluster]".
    int fds[2];
    if (::pipe(fds) != 0) {
        printError("cannot run sbatch: " + std::string(std::strerror(errno)));
        return kExitIo;
    }
    const pid_t pid = ::fork();
    if (pid < 0) {
        printError("cannot run sbatch: " + std::string(std::strerror(errno)));
        return kExitIo;
    }
    if (pid == 0) {
        ::dup2(fds[1], 1);
        ::close(fds[0]);
        ::close(fds[1]);
        ::execlp("sbatch", "sbatch", "--parsable", script.c_str(), static_cast<char*>(nullptr));
        std::fprintf(stderr,
                     "gale: cannot run sbatch: %s (is Slurm's client installed and on PATH?)\n",
                     std::strerror(errno));
        ::_exit(127);
    }
    ::close(fds[1]);
    std::string out;
    char buf[256];
    ssize_t n;
    while ((n = ::read(fds[0], buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR))
        if (n > 0) out.append(buf, static_cast<size_t>(n));
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (code != 0) {
        if (code != 127)
            printError("sbatch " + script + " failed (exit " + std::to_string(code) + ")");
        return kExitIo;
    }
    jobId = out.substr(0, out.find_first_of(";\n"));
    if (jobId.empty()) {
        printError("sbatch printed no job id");
        return kExitIo;
    }
    return kExitOk;
}

int runWedgeStatus(const std::string& outDir) {
    const fs::path manifest = fs::path(outDir) / "manifest.jsonl";
    std::string text;
    if (!readAll(manifest, text)) {
        printError(manifest.string() + ": cannot read the manifest (is " + outDir +
                   " a gale wedge -o folder?)");
        return kExitIo;
    }
    size_t done = 0, partial = 0, notStarted = 0, failed = 0, lineNo = 0;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(start, end - start);
        start = end + 1;
        ++lineNo;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        Json v;
        const Json *folder = nullptr, *path = nullptr, *frames = nullptr, *objects = nullptr;
        if (JsonReader(line).read(v) && v.kind == Json::Object) {
            folder = v.get("folder");
            path = v.get("path");
            frames = v.get("frames");
            objects = v.get("objects");
        }
        if (!folder || !path || !frames || !objects || frames->items.size() != 2 ||
            objects->kind != Json::Array) {
            printError(manifest.string() + ":" + std::to_string(lineNo) +
                       ": not a gale wedge manifest line; run gale wedge ... --emit-only again to "
                       "rewrite it");
            return kExitInput;
        }
        const int a = static_cast<int>(frames->items[0].number),
                  b = static_cast<int>(frames->items[1].number);
        // Frames on disk: those with every object's file, counted from the first frame on.
        int have = 0;
        std::error_code ec;
        for (int f = a; f <= b; ++f) {
            bool all = true;
            for (const Json& o : objects->items) {
                const Json* name = o.get("name");
                const Json* format = o.get("format");
                char buf[32];
                std::snprintf(buf, sizeof buf, ".%04d.", f);
                if (!name || !format ||
                    !fs::exists(fs::path(path->text) / (name->text + buf + format->text), ec))
                    all = false;
            }
            if (!all) break;
            ++have;
        }
        const int total = b - a + 1;
        const bool marked = fs::exists(fs::path(path->text) / "DONE", ec);
        std::string run;
        readAll(fs::path(path->text) / "run.json", run);
        const bool runFailed = run.compare(0, 20, "{\"status\": \"failed\"") == 0;
        std::string state;
        if (marked && have == total) {
            state = "done (" + std::to_string(total) + " frames)";
            ++done;
        } else if (runFailed) {
            state = "failed after " + std::to_string(have) + " of " + std::to_string(total) +
                    " frames (see " + (fs::path(path->text) / "log.txt").string() + ")";
            ++failed;
        } else if (have > 0) {
            state =
                "partial (" + std::to_string(have) + " of " + std::to_string(total) + " frames)";
            ++partial;
        } else {
            state = "not started";
            ++notStarted;
        }
        std::cout << folder->text << "  " << state << '\n';
    }
    std::cout << done << " done, " << partial << " partial, " << failed << " failed, " << notStarted
              << " not started\n"
              << std::flush;
    return std::cout ? kExitOk : kExitIo;
}

} // namespace gale::cli
