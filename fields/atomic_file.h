// Files that are never half-written: written under a temporary name in the same folder, then
// renamed over the target. Devices and pipes (/dev/null, a FIFO) are written in place, since a
// rename would replace them; a symbolic link is followed so the link survives.
#pragma once

#include "fields/pointset.h"

#include <functional>
#include <string>

namespace gale::fields {

// `write` fills the path it is given (the temporary file, or the device itself); on any error
// the temporary file is removed and `path` is left untouched. A folder is an Io error.
IoError writeFileAtomic(const std::string& path,
                        const std::function<IoError(const std::string& tmpPath)>& write);

// The same for a block of bytes already in memory.
IoError writeBytesAtomic(const std::string& path, const std::string& bytes);

// An Io error for `file`: "what: strerror(err)".
IoError ioErrorAt(const std::string& file, const std::string& what, int err);

} // namespace gale::fields
