// The geometry cache: a map of keys to shared futures (so one builder per key, built outside
// the lock) with an LRU list bounded by a byte budget.
#include "geometry/cache.h"

#include <charconv>
#include <cstdlib>
#include <exception>
#include <future>

namespace gale::geometry {

struct GeometryCache::Entry {
    std::shared_future<Built> future;
    std::list<std::string>::iterator lru;
    size_t bytes = 0;
    bool ready = false;
};

GeometryCache& GeometryCache::global() {
    static GeometryCache cache([] {
        size_t mb = 2048;
        if (const char* env = std::getenv("GALE_GEOMETRY_CACHE_MB")) {
            char* end = nullptr;
            const unsigned long long v = std::strtoull(env, &end, 10);
            if (end && *end == '\0' && v > 0) mb = static_cast<size_t>(v);
        }
        return mb << 20;
    }());
    return cache;
}

GeometryCache::Built GeometryCache::getErased(const std::string& key, const Builder& build) {
    std::unique_lock<std::mutex> lock(mMutex);
    auto it = mEntries.find(key);
    if (it != mEntries.end()) {
        std::shared_ptr<Entry> e = it->second;
        mLru.splice(mLru.begin(), mLru, e->lru);
        std::shared_future<Built> f = e->future;
        lock.unlock();
        return f.get();
    }
    std::promise<Built> promise;
    auto entry = std::make_shared<Entry>();
    entry->future = promise.get_future().share();
    mLru.push_front(key);
    entry->lru = mLru.begin();
    mEntries.emplace(key, entry);
    ++mBuilds;
    lock.unlock();

    Built built;
    try {
        built = build();
    } catch (const std::exception& ex) {
        built.error.kind = io::IoError::Data;
        built.error.message = ex.what();
    } catch (...) {
        built.error.kind = io::IoError::Data;
        built.error.message = "unknown failure";
    }
    promise.set_value(built);

    lock.lock();
    auto again = mEntries.find(key);
    if (again != mEntries.end() && again->second == entry) {
        if (built.error) {
            mLru.erase(entry->lru);
            mEntries.erase(again);
        } else {
            entry->ready = true;
            entry->bytes = built.bytes;
            mBytes += built.bytes;
            evictLocked(key);
        }
    }
    return built;
}

void GeometryCache::evictLocked(const std::string& keep) {
    auto it = mLru.end();
    while (mBytes > mBudget && it != mLru.begin()) {
        --it;
        if (*it == keep) continue;
        auto e = mEntries.find(*it);
        if (e == mEntries.end() || !e->second->ready) continue;
        mBytes -= e->second->bytes;
        mEntries.erase(e);
        it = mLru.erase(it);
    }
}

void GeometryCache::setBudget(size_t bytes) {
    std::lock_guard<std::mutex> lock(mMutex);
    mBudget = bytes;
    evictLocked(std::string());
}

size_t GeometryCache::budget() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mBudget;
}

size_t GeometryCache::bytes() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mBytes;
}

size_t GeometryCache::entries() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mEntries.size();
}

size_t GeometryCache::builds() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mBuilds;
}

void GeometryCache::clear() {
    std::lock_guard<std::mutex> lock(mMutex);
    // Entries still being built stay (their builders will finish them).
    for (auto it = mLru.begin(); it != mLru.end();) {
        auto e = mEntries.find(*it);
        if (e != mEntries.end() && e->second->ready) {
            mBytes -= e->second->bytes;
            mEntries.erase(e);
            it = mLru.erase(it);
        } else {
            ++it;
        }
    }
}

// ---- cached loaders ----

namespace {

// Exact text of a double (shortest round trip) for keys.
std::string keyNumber(double v) {
    char buf[64];
    const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

} // namespace

io::IoError cachedMesh(const FrameFile& file, std::shared_ptr<const TriangleMesh>& out) {
    return GeometryCache::global().get<TriangleMesh>(
        "mesh|" + file.key,
        [&](std::shared_ptr<const TriangleMesh>& v, size_t& bytes) -> io::IoError {
            auto mesh = std::make_shared<TriangleMesh>();
            if (io::IoError e = readTriangleMesh(file.path, *mesh)) return e;
            bytes = mesh->points.size() * sizeof(mesh->points[0]) +
                    mesh->triangles.size() * sizeof(mesh->triangles[0]);
            v = std::move(mesh);
            return {};
        },
        out);
}

io::IoError cachedSdf(const FrameFile& file, double voxel, std::shared_ptr<const SdfVolume>& out) {
    return GeometryCache::global().get<SdfVolume>(
        "sdf|" + file.key + "|" + keyNumber(voxel),
        [&](std::shared_ptr<const SdfVolume>& v, size_t& bytes) -> io::IoError {
            std::shared_ptr<const TriangleMesh> mesh;
            if (io::IoError e = cachedMesh(file, mesh)) return e;
            SdfOptions options;
            options.voxel = voxel;
            if (io::IoError e = SdfVolume::build(*mesh, options, v, file.path)) return e;
            bytes = v->memoryBytes();
            return {};
        },
        out);
}

io::IoError cachedVelocity(const FrameFile& file, const std::string& gridName,
                           std::shared_ptr<const VelocityVolume>& out) {
    return GeometryCache::global().get<VelocityVolume>(
        "vdb|" + file.key + "|" + gridName,
        [&](std::shared_ptr<const VelocityVolume>& v, size_t& bytes) -> io::IoError {
            if (io::IoError e = VelocityVolume::load(file.path, gridName, v)) return e;
            bytes = v->memoryBytes();
            return {};
        },
        out);
}

io::IoError cachedTriangleIndex(const FrameFile& file, double voxel, int bandVoxels,
                                std::shared_ptr<const ClosestTriangleIndex>& out) {
    return GeometryCache::global().get<ClosestTriangleIndex>(
        "tri|" + file.key + "|" + keyNumber(voxel) + "|" + std::to_string(bandVoxels),
        [&](std::shared_ptr<const ClosestTriangleIndex>& v, size_t& bytes) -> io::IoError {
            std::shared_ptr<const TriangleMesh> mesh;
            if (io::IoError e = cachedMesh(file, mesh)) return e;
            if (io::IoError e =
                    ClosestTriangleIndex::build(*mesh, voxel, bandVoxels * voxel, v, file.path))
                return e;
            bytes = v->memoryBytes();
            return {};
        },
        out);
}

} // namespace gale::geometry
