// Atomic file writes: temporary name + rename, with devices, pipes and symbolic links handled.
#include "io/atomic_file.h"

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <signal.h>
#include <unistd.h>

namespace gale::io {

IoError ioErrorAt(const std::string& file, const std::string& what, int err) {
    IoError e;
    e.kind = IoError::Io;
    e.file = file;
    e.message = what + ": " + (err ? std::strerror(err) : "write failed");
    return e;
}

IoError writeFileAtomic(const std::string& path,
                        const std::function<IoError(const std::string& tmpPath)>& write) {
    namespace fs = std::filesystem;
    std::error_code ec;
    std::string target = path;
    // Through a symbolic link: replace the file it points to, not the link.
    if (fs::is_symlink(fs::symlink_status(path, ec))) {
        const fs::path resolved = fs::canonical(path, ec);
        if (!ec) target = resolved.string();
    }
    const fs::file_status status = fs::status(target, ec);
    if (fs::is_directory(status)) return ioErrorAt(path, "cannot write", EISDIR);
    if (fs::exists(status) && !fs::is_regular_file(status)) {
        // A device or a pipe (/dev/null, /dev/stdout, a FIFO): a rename would replace it, so
        // it is written in place.
        IoError e = write(target);
        if (e) e.file = path;
        return e;
    }
    const std::string tmp = target + ".tmp." + std::to_string(static_cast<long>(::getpid()));
    errno = 0;
    IoError e = write(tmp);
    if (!e && std::rename(tmp.c_str(), target.c_str()) != 0)
        e = ioErrorAt(path, "cannot write", errno);
    if (e) {
        std::remove(tmp.c_str());
        e.file = path;
    }
    return e;
}

IoError writeBytesAtomic(const std::string& path, const std::string& bytes) {
    return writeFileAtomic(path, [&](const std::string& tmp) -> IoError {
        errno = 0;
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) return ioErrorAt(path, "cannot write", errno);
        f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        f.flush();
        const int err = errno;
        f.close();
        if (f.fail()) return ioErrorAt(path, "cannot write", err);
        return {};
    });
}

namespace {

// Whether process `pid` exists and is not a zombie (killed, its exit not yet collected): kill(pid,
// 0) fails with ESRCH only when no such process exists (EPERM: it runs as another user).
bool processRuns(long pid) {
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) return false;
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text;
    if (!stat || !std::getline(stat, text)) return true;
    const size_t paren = text.rfind(')'); // the state follows "pid (name)"
    return paren == std::string::npos || paren + 2 >= text.size() ||
           (text[paren + 2] != 'Z' && text[paren + 2] != 'X');
}

} // namespace

std::vector<std::string>
removeStaleTempFiles(const std::string& folder,
                     const std::function<bool(const std::string& target)>& isOurs) {
    namespace fs = std::filesystem;
    std::vector<fs::path> stale;
    std::error_code ec;
    for (fs::directory_iterator it(folder.empty() ? "." : folder, ec), end; !ec && it != end;
         it.increment(ec)) {
        if (!it->is_regular_file(ec)) continue;
        const std::string name = it->path().filename().string();
        const size_t mark = name.rfind(".tmp.");
        if (mark == std::string::npos || mark == 0 || mark + 5 == name.size() ||
            name.size() - mark - 5 > 9)
            continue;
        bool digits = true;
        for (size_t i = mark + 5; i < name.size(); ++i)
            digits = digits && std::isdigit(static_cast<unsigned char>(name[i]));
        if (!digits) continue;
        const long pid = std::stol(name.substr(mark + 5));
        if (pid <= 0 || pid == static_cast<long>(::getpid()) || processRuns(pid)) continue;
        if (isOurs(name.substr(0, mark))) stale.push_back(it->path());
    }
    std::vector<std::string> removed;
    for (const fs::path& p : stale)
        if (fs::remove(p, ec)) removed.push_back(p.string());
    return removed;
}

} // namespace gale::io
