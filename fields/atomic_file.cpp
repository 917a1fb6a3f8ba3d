// Atomic file writes: temporary name + rename, with devices, pipes and symbolic links handled.
#include "fields/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace gale::fields {

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

} // namespace gale::fields
