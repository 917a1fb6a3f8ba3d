// The geometry built-ins of the expression language: sdf, sdfgrad, shadow, vdb and meshvel
// (docs/geometry.md). Their file names resolve under a FileAccess (file_policy.h), checked at
// compile time by validate hooks; kernels sample the volumes of cache.h per block.
#pragma once

#include "geometry/file_policy.h"
#include "runtime/builtins.h"

#include <memory>

namespace gale::geometry {

// Adds (or replaces) the geometry built-ins in `t`, resolving file names under `access`.
void addGeometryBuiltins(runtime::FunctionTable& t, const FileAccess& access);

// A copy of `table` (the standard built-ins when null) whose geometry built-ins resolve file
// names under `access`.
std::shared_ptr<const runtime::FunctionTable>
withFileAccess(const std::shared_ptr<const runtime::FunctionTable>& table, const FileAccess& access);

} // namespace gale::geometry
