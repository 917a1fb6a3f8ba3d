// A bounded, thread-safe LRU cache of built geometry (meshes, SDFs, velocity volumes, closest-
// triangle indices) shared by every expression of the process. Each key is built once: the
// first caller builds outside the lock, later callers of the same key wait for it.
#pragma once

#include "geometry/file_policy.h"
#include "geometry/geometry.h"
#include "io/pointset.h"

#include <cstddef>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace gale::geometry {

class GeometryCache {
public:
    // What a builder returns: the value and its size in bytes (for the budget), or an error.
    struct Built {
        std::shared_ptr<const void> value;
        size_t bytes = 0;
        io::IoError error;
    };
    using Builder = std::function<Built()>;

    explicit GeometryCache(size_t budgetBytes) : mBudget(budgetBytes) {}

    // The cache every built-in uses: 2 GiB, or GALE_GEOMETRY_CACHE_MB megabytes.
    static GeometryCache& global();

    // The value of `key`, built by `build` when absent. Errors are returned, not cached (a
    // missing file may appear later). Entries beyond the budget are dropped least recently used
    // first; a dropped value stays alive while something still holds it.
    template <class T, class F>
    io::IoError get(const std::string& key, F&& build, std::shared_ptr<const T>& out) {
        Built b = getErased(key, [&]() -> Built {
            std::shared_ptr<const T> v;
            size_t bytes = 0;
            Built r;
            r.error = build(v, bytes);
            r.value = std::move(v);
            r.bytes = bytes;
            return r;
        });
        if (b.error) return b.error;
        out = std::static_pointer_cast<const T>(b.value);
        return {};
    }

    void setBudget(size_t bytes);
    size_t budget() const;
    size_t bytes() const; // sizes of the entries held
    size_t entries() const;
    size_t builds() const; // builder calls so far (for tests of the once-per-key rule)
    void clear();

private:
    struct Entry;
    Built getErased(const std::string& key, const Builder& build);
    void evictLocked(const std::string& keep);

    mutable std::mutex mMutex;
    std::unordered_map<std::string, std::shared_ptr<Entry>> mEntries;
    std::list<std::string> mLru; // most recently used first
    size_t mBudget;
    size_t mBytes = 0;
    size_t mBuilds = 0;
};

// Loaders through GeometryCache::global(), keyed by the file's key (path, mtime, size) and the
// build settings. Errors name the file.
io::IoError cachedMesh(const FrameFile& file, std::shared_ptr<const TriangleMesh>& out);
io::IoError cachedSdf(const FrameFile& file, double voxel, std::shared_ptr<const SdfVolume>& out);
io::IoError cachedVelocity(const FrameFile& file, const std::string& gridName,
                           std::shared_ptr<const VelocityVolume>& out);
io::IoError cachedTriangleIndex(const FrameFile& file, double voxel, int bandVoxels,
                                std::shared_ptr<const ClosestTriangleIndex>& out);

} // namespace gale::geometry
