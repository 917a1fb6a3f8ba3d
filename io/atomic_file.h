// Files that are never half-written: written under a temporary name in the same folder, then
// renamed over the target. Devices and pipes (/dev/null, a FIFO) are written in place, since a
// rename would replace them; a symbolic link is followed so the link survives.
#pragma once

#include "io/pointset.h"

#include <functional>
#include <string>
#include <vector>

namespace gale::io {

// `write` fills the path it is given (the temporary file, or the device itself); on any error
// the temporary file is removed and `path` is left untouched. A folder is an Io error.
IoError writeFileAtomic(const std::string& path,
                        const std::function<IoError(const std::string& tmpPath)>& write);

// The same for a block of bytes already in memory.
IoError writeBytesAtomic(const std::string& path, const std::string& bytes);

// The temporary files that writes killed part-way (SIGKILL, a crash) left in `folder`:
// `<target>.tmp.<pid>` where no process `pid` is running and `isOurs(target)` holds for the
// target's file name. Removes them and returns their paths; files of running writers are kept.
std::vector<std::string> removeStaleTempFiles(const std::string& folder,
                                              const std::function<bool(const std::string& target)>& isOurs);

// An Io error for `file`: "what: strerror(err)".
IoError ioErrorAt(const std::string& file, const std::string& what, int err);

} // namespace gale::io
