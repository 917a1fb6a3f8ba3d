// Transitional: atomic files and point sets moved to io/ (io/atomic_file.h, io/pointset.h,
// namespace gale::io). This header keeps the old names for cli/sim_command.cpp until it
// includes io/ itself; new code includes io/ directly. Remove it with that change.
#pragma once

#include "io/atomic_file.h"
#include "io/pointset.h"

namespace gale::fields {
using io::formatNumber;
using io::IoError;
using io::PointFormat;
using io::removeStaleTempFiles;
using io::writeBytesAtomic;
using io::writePointsFile;
} // namespace gale::fields
