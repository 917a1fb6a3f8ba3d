// FFT turbulence: per-mode synthesis of a helical, divergence-free von Kármán field, FFTW
// inverse transforms (float, cached plans, threads), trilinear/tricubic periodic sampling, the
// grid cache and spectral analysis for tests. The fftturb/fftturb4 built-ins that sample it
// from expressions are in fftturb_builtins.cpp.
#include "fields/fftturb.h"

#include <fftw3.h>
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <future>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <tuple>

namespace gale::fields {
namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- Sizes ----------------------------------------------------------------------------------

bool isSmoothEven(int n) {
    if (n < 2 || n % 2 != 0) return false;
    for (int p : {2, 3, 5})
        while (n % p == 0) n /= p;
    return n == 1;
}

// ---- Deterministic random numbers -----------------------------------------------------------

uint64_t splitmix(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

// Uniform in (0, 1), never 0 (Box-Muller takes its log).
double unit(uint64_t h) { return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53; }

// The random numbers of the integer wavevector m: a complex vector with components uniform in
// the square [-1, 1]², a phase, a helicity sign and a standard normal (the mode's frequency).
// A pure function of (seed, m), so a mode is the same at any resolution that keeps it.
struct ModeNoise {
    double v[6];
    double phase;
    bool positiveHelicity;
    double normal;
};

ModeNoise modeNoise(uint64_t seedKey, int mx, int my, int mz, bool wantNormal) {
    const uint64_t packed = (static_cast<uint64_t>(static_cast<uint32_t>(mx) & 0x1FFFFFu)) |
                            (static_cast<uint64_t>(static_cast<uint32_t>(my) & 0x1FFFFFu) << 21) |
                            (static_cast<uint64_t>(static_cast<uint32_t>(mz) & 0x1FFFFFu) << 42);
    const uint64_t h = splitmix(seedKey ^ splitmix(packed));
    ModeNoise n;
    for (int j = 0; j < 3; ++j) {
        const uint64_t r = splitmix(h + j + 1);
        n.v[2 * j] = static_cast<double>(r >> 32) * 0x1.0p-31 - 1.0;
        n.v[2 * j + 1] = static_cast<double>(r & 0xFFFFFFFFu) * 0x1.0p-31 - 1.0;
    }
    const uint64_t r = splitmix(h + 4);
    n.phase = 2.0 * kPi * unit(r);
    n.positiveHelicity = (r & 1u) != 0;
    n.normal = 0.0;
    if (wantNormal) { // Box-Muller
        const double u1 = unit(splitmix(h + 5)), u2 = unit(splitmix(h + 6));
        n.normal = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
    }
    return n;
}

uint64_t seedKeyOf(int64_t seed) { return splitmix(static_cast<uint64_t>(seed) ^ 0x6761'6C65'7475'7262ull); }

// ---- FFTW plans -----------------------------------------------------------------------------

struct FftFree {
    void operator()(void* p) const { fftwf_free(p); }
};
using FftBuffer = std::unique_ptr<fftwf_complex, FftFree>;

// n³ in-place transform buffer: n·n·(n/2+1) complex values, zeroed.
FftBuffer makeBuffer(int n) {
    const size_t count = static_cast<size_t>(n) * n * (n / 2 + 1);
    auto* p = static_cast<fftwf_complex*>(fftwf_malloc(count * sizeof(fftwf_complex)));
    if (!p) throw std::bad_alloc();
    std::memset(p, 0, count * sizeof(fftwf_complex));
    return FftBuffer(p);
}

struct PlanRegistry {
    std::mutex mutex;
    std::map<std::tuple<int, bool, int, bool>, fftwf_plan> plans; // (n, forward, threads, measure)
    bool measure = false;
    bool initialised = false;
};

PlanRegistry& plans() {
    static PlanRegistry* r = new PlanRegistry(); // never destroyed: plans outlive static dtors
    return *r;
}

void initFftwLocked(PlanRegistry& r) {
    if (r.initialised) return;
    fftwf_init_threads();
    fftwf_make_planner_thread_safe();
    r.initialised = true;
}

// In-place 3-D plan of size n³: forward r2c or backward c2r. Executed with new arrays (all
// from fftwf_malloc, so equally aligned).
fftwf_plan planFor(int n, bool forward, int threads) {
    PlanRegistry& r = plans();
    std::lock_guard<std::mutex> lock(r.mutex);
    initFftwLocked(r);
    const auto key = std::make_tuple(n, forward, threads, r.measure);
    auto it = r.plans.find(key);
    if (it != r.plans.end()) return it->second;
    fftwf_plan_with_nthreads(threads);
    FftBuffer scratch = makeBuffer(n);
    const unsigned flags = r.measure ? FFTW_MEASURE : FFTW_ESTIMATE;
    fftwf_plan p = forward ? fftwf_plan_dft_r2c_3d(n, n, n, reinterpret_cast<float*>(scratch.get()), scratch.get(), flags)
                           : fftwf_plan_dft_c2r_3d(n, n, n, scratch.get(), reinterpret_cast<float*>(scratch.get()), flags);
    if (!p) throw std::runtime_error("FFTW could not plan a transform");
    r.plans.emplace(key, p);
    return p;
}

int resolveThreads(int threads) {
    if (threads > 0) return threads;
    return std::max(1u, std::thread::hardware_concurrency());
}

// A parallel loop over [0, n) in its own arena: a thread waiting here never picks up outer
// work (a VM block that might wait for the grid this thread is making).
template <class F>
void parallelFor(int n, int threads, const F& f) {
    tbb::task_arena arena(std::max(1, std::min(threads, tbb::info::default_concurrency())));
    arena.execute([&] {
        tbb::this_task_arena::isolate([&] {
            tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
                for (int i = r.begin(); i != r.end(); ++i) f(i);
            });
        });
    });
}

int signedIndex(int i, int n) { return i <= n / 2 ? i : i - n; }

// ---- Sampling -------------------------------------------------------------------------------

// Wraps p/h into [0, n): cell index and fraction. False for non-finite input.
inline bool wrapAxis(double p, double invH, int n, double invN, int& i, float& frac) {
    double u = p * invH;
    if (!(std::abs(u) < 1e15)) {
        if (!std::isfinite(u)) return false;
        u = std::fmod(u, static_cast<double>(n));
    }
    const double q = u * invN;
    double fq = static_cast<double>(static_cast<int64_t>(q));
    if (fq > q) fq -= 1.0;
    u -= fq * n; // [0, n) up to rounding
    if (u < 0.0) u += n;
    if (u >= n) u -= n;
    i = static_cast<int>(u);
    if (i >= n) { // u was -tiny: n - tiny rounded to n
        i = 0;
        u = 0.0;
    }
    frac = static_cast<float>(u - i);
    return true;
}

inline void catmullRom(float t, float w[4]) {
    const float t2 = t * t, t3 = t2 * t;
    w[0] = 0.5f * (-t3 + 2.0f * t2 - t);
    w[1] = 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f);
    w[2] = 0.5f * (-3.0f * t3 + 4.0f * t2 + t);
    w[3] = 0.5f * (t3 - t2);
}

} // namespace

// ---- Spectrum and sizes ---------------------------------------------------------------------

double vonKarmanEnergy(double k, double lengthScale, double sigma) {
    // (55/9) Γ(5/6) / (√π Γ(1/3))
    static const double c = 55.0 / 9.0 * std::tgamma(5.0 / 6.0) / (std::sqrt(kPi) * std::tgamma(1.0 / 3.0));
    const double le = kVonKarmanLeOverL * lengthScale;
    const double x2 = (k * le) * (k * le);
    return c * sigma * sigma * le * x2 * x2 / std::pow(1.0 + x2, 17.0 / 6.0);
}

bool TurbulenceSpec::operator<(const TurbulenceSpec& o) const {
    return std::tie(lengthScale, tile, res, seed, tau, time) < std::tie(o.lengthScale, o.tile, o.res, o.seed, o.tau, o.time);
}
bool TurbulenceSpec::operator==(const TurbulenceSpec& o) const {
    return std::tie(lengthScale, tile, res, seed, tau, time) == std::tie(o.lengthScale, o.tile, o.res, o.seed, o.tau, o.time);
}

double defaultTurbulenceTile(double lengthScale) { return 8.0 * lengthScale; }

int resolveTurbulenceRes(double res, double lengthScale, double tile, double minScale) {
    if (res > 0.0) {
        int r = static_cast<int>(std::ceil(std::min(res, 512.0)));
        r += r % 2;
        return std::clamp(r, 8, 512);
    }
    if (std::isfinite(minScale) && minScale > 0.0) {
        const double limit = std::min(2.0 * tile / minScale, 256.0);
        int r = 16;
        for (int n = 16; n <= limit; ++n)
            if (isSmoothEven(n)) r = n;
        return r;
    }
    const double want = 4.0 * tile / lengthScale;
    for (int n = 16; n < 256; ++n)
        if (isSmoothEven(n) && n >= want) return n;
    return 256;
}

// ---- Synthesis ------------------------------------------------------------------------------

std::shared_ptr<const TurbulenceGrid> TurbulenceGrid::synthesize(const TurbulenceSpec& spec, int threads) {
    threads = resolveThreads(threads);
    const int n = spec.res, nh = n / 2 + 1, mmax = n / 2 - 1;
    const double tile = spec.tile, dk = 2.0 * kPi / tile, dk3 = dk * dk * dk;
    const double l = spec.lengthScale;
    const bool animated = spec.tau > 0.0f;
    // Per-mode frequency ω = ω0 ξ, ξ ~ N(0, 1): ⟨cos ωt⟩ = exp(-ω0² t²/2), integral time τ.
    const double omega0 = animated ? std::sqrt(kPi / 2.0) / spec.tau : 0.0;
    const double time = animated ? spec.time : 0.0;
    const uint64_t seedKey = seedKeyOf(spec.seed);

    FftBuffer buf[3] = {makeBuffer(n), makeBuffer(n), makeBuffer(n)};
    std::vector<double> planeEnergy(static_cast<size_t>(n), 0.0);

    // |û|² by |m|²: ½|û|² = E(k)/(4πk²) Δk³ per mode (σ = 1).
    std::vector<double> power(static_cast<size_t>(mmax) * mmax + 1, 0.0);
    for (size_t m2 = 1; m2 < power.size(); ++m2) {
        const double kk = std::sqrt(static_cast<double>(m2)) * dk;
        power[m2] = 2.0 * vonKarmanEnergy(kk, l, 1.0) / (4.0 * kPi * kk * kk) * dk3;
    }

    // The coefficient of a canonical mode m (its partner -m holds the conjugate): a random
    // vector w projected by ½(P ± i k̂×) onto one helicity — circularly polarised and
    // divergence-free — scaled to the mode's exact power and turned by a uniform random phase
    // (plus ω t when animated).
    auto mode = [&](int mx, int my, int mz, std::complex<double> u[3]) {
        const int m2 = mx * mx + my * my + mz * mz;
        const double mm = std::sqrt(static_cast<double>(m2));
        const double kh[3] = {mx / mm, my / mm, mz / mm};
        const ModeNoise z = modeNoise(seedKey, mx, my, mz, animated);
        const std::complex<double> w[3] = {{z.v[0], z.v[1]}, {z.v[2], z.v[3]}, {z.v[4], z.v[5]}};
        const std::complex<double> kw = kh[0] * w[0] + kh[1] * w[1] + kh[2] * w[2];
        const std::complex<double> cross[3] = {kh[1] * w[2] - kh[2] * w[1], kh[2] * w[0] - kh[0] * w[2],
                                               kh[0] * w[1] - kh[1] * w[0]};
        const std::complex<double> is(0.0, z.positiveHelicity ? 1.0 : -1.0);
        double norm2 = 0.0;
        for (int c = 0; c < 3; ++c) {
            u[c] = (w[c] - kh[c] * kw) + is * cross[c];
            norm2 += std::norm(u[c]);
        }
        const double s = norm2 > 0.0 ? std::sqrt(power[static_cast<size_t>(m2)] / norm2) : 0.0;
        double phase = z.phase;
        if (animated) phase += std::fmod(omega0 * z.normal * time, 2.0 * kPi);
        const std::complex<double> rot = std::polar(s, phase);
        for (int c = 0; c < 3; ++c) u[c] *= rot;
    };

    parallelFor(n, threads, [&](int iz) {
        const int mz = signedIndex(iz, n);
        if (std::abs(mz) > mmax) return;
        double energy = 0.0;
        for (int iy = 0; iy < n; ++iy) {
            const int my = signedIndex(iy, n);
            if (mz * mz + my * my > mmax * mmax) continue;
            for (int mx = 0; mx <= mmax; ++mx) {
                const int m2 = mx * mx + my * my + mz * mz;
                if (m2 == 0 || m2 > mmax * mmax) continue;
                const bool canonical = mx > 0 || my > 0 || (my == 0 && mz > 0);
                std::complex<double> u[3];
                if (canonical) {
                    mode(mx, my, mz, u);
                } else {
                    mode(-mx, -my, -mz, u);
                    for (auto& v : u) v = std::conj(v);
                }
                const size_t at = (static_cast<size_t>(iz) * n + iy) * nh + mx;
                for (int c = 0; c < 3; ++c) {
                    buf[c].get()[at][0] = static_cast<float>(u[c].real());
                    buf[c].get()[at][1] = static_cast<float>(u[c].imag());
                }
                energy += (mx > 0 ? 2.0 : 1.0) * power[static_cast<size_t>(m2)];
            }
        }
        planeEnergy[static_cast<size_t>(iz)] = energy;
    });
    double total = 0.0; // Σ|û|² over all of k-space = mean |u|², summed in a fixed order
    for (double e : planeEnergy) total += e;

    auto grid = std::shared_ptr<TurbulenceGrid>(new TurbulenceGrid());
    grid->mRes = n;
    grid->mTile = tile;
    grid->mSpec = spec;
    grid->mEnergyScale = total > 0.0 ? 3.0 / total : 1.0;
    const float scale = static_cast<float>(total > 0.0 ? std::sqrt(3.0 / total) : 0.0);
    grid->mData.resize(static_cast<size_t>(n) * n * n * 3);

    const fftwf_plan plan = planFor(n, false, threads);
    const size_t rowPad = 2 * static_cast<size_t>(nh);
    for (int c = 0; c < 3; ++c) {
        fftwf_execute_dft_c2r(plan, buf[c].get(), reinterpret_cast<float*>(buf[c].get()));
        const float* real = reinterpret_cast<const float*>(buf[c].get());
        float* out = grid->mData.data();
        parallelFor(n, threads, [&](int iz) {
            for (int iy = 0; iy < n; ++iy) {
                const float* src = real + (static_cast<size_t>(iz) * n + iy) * rowPad;
                float* dst = out + (static_cast<size_t>(iz) * n + iy) * n * 3 + c;
                for (int ix = 0; ix < n; ++ix) dst[3 * ix] = src[ix] * scale;
            }
        });
        buf[c].reset();
    }
    return grid;
}

std::shared_ptr<const TurbulenceGrid> TurbulenceGrid::fromData(int res, double tile, std::vector<float> data) {
    if (res < 2 || data.size() != static_cast<size_t>(res) * res * res * 3)
        throw std::invalid_argument("TurbulenceGrid::fromData: expected 3 res³ values");
    auto grid = std::shared_ptr<TurbulenceGrid>(new TurbulenceGrid());
    grid->mRes = res;
    grid->mTile = tile;
    grid->mSpec.res = res;
    grid->mSpec.tile = static_cast<float>(tile);
    grid->mData = std::move(data);
    return grid;
}

// ---- Sampling -------------------------------------------------------------------------------

void TurbulenceGrid::sample(double x, double y, double z, TurbulenceInterp interp, float out[3]) const {
    const int n = mRes;
    const double invH = n / mTile, invN = 1.0 / n;
    int ix, iy, iz;
    float fx, fy, fz;
    if (!wrapAxis(x, invH, n, invN, ix, fx) || !wrapAxis(y, invH, n, invN, iy, fy) ||
        !wrapAxis(z, invH, n, invN, iz, fz)) {
        out[0] = out[1] = out[2] = std::numeric_limits<float>::quiet_NaN();
        return;
    }
    const float* d = mData.data();
    const size_t sy = 3 * static_cast<size_t>(n), sz = sy * n;
    if (interp == TurbulenceInterp::Trilinear) {
        const size_t xo[2] = {3 * static_cast<size_t>(ix), 3 * static_cast<size_t>(ix + 1 == n ? 0 : ix + 1)};
        const size_t yo[2] = {sy * iy, sy * (iy + 1 == n ? 0 : iy + 1)};
        const size_t zo[2] = {sz * iz, sz * (iz + 1 == n ? 0 : iz + 1)};
        const float wx[2] = {1.0f - fx, fx}, wy[2] = {1.0f - fy, fy}, wz[2] = {1.0f - fz, fz};
        float a0 = 0.0f, a1 = 0.0f, a2 = 0.0f;
        for (int c = 0; c < 2; ++c)
            for (int b = 0; b < 2; ++b) {
                const float* row = d + zo[c] + yo[b];
                const float* p0 = row + xo[0];
                const float* p1 = row + xo[1];
                const float w = wz[c] * wy[b];
                a0 += w * (wx[0] * p0[0] + wx[1] * p1[0]);
                a1 += w * (wx[0] * p0[1] + wx[1] * p1[1]);
                a2 += w * (wx[0] * p0[2] + wx[1] * p1[2]);
            }
        out[0] = a0;
        out[1] = a1;
        out[2] = a2;
        return;
    }
    size_t xo[4], yo[4], zo[4];
    for (int a = 0; a < 4; ++a) {
        int jx = ix + a - 1, jy = iy + a - 1, jz = iz + a - 1;
        jx = jx < 0 ? jx + n : (jx >= n ? jx - n : jx);
        jy = jy < 0 ? jy + n : (jy >= n ? jy - n : jy);
        jz = jz < 0 ? jz + n : (jz >= n ? jz - n : jz);
        xo[a] = 3 * static_cast<size_t>(jx);
        yo[a] = sy * jy;
        zo[a] = sz * jz;
    }
    float wx[4], wy[4], wz[4];
    catmullRom(fx, wx);
    catmullRom(fy, wy);
    catmullRom(fz, wz);
    float a0 = 0.0f, a1 = 0.0f, a2 = 0.0f;
    for (int c = 0; c < 4; ++c)
        for (int b = 0; b < 4; ++b) {
            const float* row = d + zo[c] + yo[b];
            float r0 = 0.0f, r1 = 0.0f, r2 = 0.0f;
            for (int a = 0; a < 4; ++a) {
                const float* p = row + xo[a];
                r0 += wx[a] * p[0];
                r1 += wx[a] * p[1];
                r2 += wx[a] * p[2];
            }
            const float w = wz[c] * wy[b];
            a0 += w * r0;
            a1 += w * r1;
            a2 += w * r2;
        }
    out[0] = a0;
    out[1] = a1;
    out[2] = a2;
}

void TurbulenceGrid::sampleMany(const double* xyz, size_t n, TurbulenceInterp interp, float* out) const {
    for (size_t i = 0; i < n; ++i) sample(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], interp, out + 3 * i);
}

// ---- Cache ----------------------------------------------------------------------------------

struct TurbulenceCache::Impl {
    using GridFuture = std::shared_future<std::shared_ptr<const TurbulenceGrid>>;
    struct Entry {
        GridFuture grid;
        size_t bytes = 0;
        uint64_t lastUse = 0;
    };
    mutable std::mutex mutex;
    std::map<TurbulenceSpec, Entry> entries;
    size_t maxBytes, maxEntries;
    int threads;
    size_t bytes = 0, hits = 0, misses = 0;
    uint64_t clock = 0;

    // Drops least recently used entries (never `keep`) until within both limits. Holders of
    // a dropped grid keep it alive; a dropped grid still being made completes for its waiters.
    void evict(const TurbulenceSpec& keep) {
        while ((entries.size() > maxEntries || bytes > maxBytes) && entries.size() > 1) {
            auto victim = entries.end();
            for (auto it = entries.begin(); it != entries.end(); ++it)
                if (!(it->first == keep) && (victim == entries.end() || it->second.lastUse < victim->second.lastUse))
                    victim = it;
            if (victim == entries.end()) break;
            bytes -= victim->second.bytes;
            entries.erase(victim);
        }
    }
};

TurbulenceCache::TurbulenceCache(size_t maxBytes, size_t maxEntries, int threads) : mImpl(std::make_unique<Impl>()) {
    mImpl->maxBytes = maxBytes;
    mImpl->maxEntries = std::max<size_t>(1, maxEntries);
    mImpl->threads = threads;
}

TurbulenceCache::~TurbulenceCache() = default;

const std::shared_ptr<TurbulenceCache>& TurbulenceCache::global() {
    static const std::shared_ptr<TurbulenceCache> cache = std::make_shared<TurbulenceCache>();
    return cache;
}

std::shared_ptr<const TurbulenceGrid> TurbulenceCache::get(const TurbulenceSpec& asked) const {
    Impl& m = *mImpl;
    TurbulenceSpec spec = asked;
    if (!(spec.tau > 0.0f)) { // frozen: one grid for every instant
        spec.tau = 0.0f;
        spec.time = 0.0f;
    }
    std::promise<std::shared_ptr<const TurbulenceGrid>> promise;
    Impl::GridFuture future;
    bool mine = false;
    {
        std::lock_guard<std::mutex> lock(m.mutex);
        auto it = m.entries.find(spec);
        if (it != m.entries.end()) {
            ++m.hits;
            it->second.lastUse = ++m.clock;
            future = it->second.grid;
        } else {
            ++m.misses;
            future = promise.get_future().share();
            Impl::Entry e;
            e.grid = future;
            e.bytes = static_cast<size_t>(spec.res) * spec.res * spec.res * 3 * sizeof(float);
            e.lastUse = ++m.clock;
            m.entries.emplace(spec, e);
            m.bytes += e.bytes;
            m.evict(spec);
            mine = true;
        }
    }
    if (mine) {
        try {
            promise.set_value(TurbulenceGrid::synthesize(spec, m.threads));
        } catch (...) {
            promise.set_exception(std::current_exception());
            std::lock_guard<std::mutex> lock(m.mutex);
            auto it = m.entries.find(spec);
            if (it != m.entries.end()) {
                m.bytes -= it->second.bytes;
                m.entries.erase(it);
            }
        }
    }
    return future.get();
}

TurbulenceCache::Stats TurbulenceCache::stats() const {
    std::lock_guard<std::mutex> lock(mImpl->mutex);
    Stats s;
    s.hits = mImpl->hits;
    s.misses = mImpl->misses;
    s.entries = mImpl->entries.size();
    s.bytes = mImpl->bytes;
    return s;
}

void TurbulenceCache::clear() {
    std::lock_guard<std::mutex> lock(mImpl->mutex);
    mImpl->entries.clear();
    mImpl->bytes = 0;
}

// ---- FFTW planning --------------------------------------------------------------------------

void setTurbulenceFftPlanning(FftPlanning p) {
    std::lock_guard<std::mutex> lock(plans().mutex);
    plans().measure = p == FftPlanning::Measure;
}

std::string exportTurbulenceFftWisdom() {
    PlanRegistry& r = plans();
    std::lock_guard<std::mutex> lock(r.mutex);
    initFftwLocked(r);
    char* s = fftwf_export_wisdom_to_string();
    std::string out = s ? s : "";
    std::free(s);
    return out;
}

bool importTurbulenceFftWisdom(const std::string& wisdom) {
    PlanRegistry& r = plans();
    std::lock_guard<std::mutex> lock(r.mutex);
    initFftwLocked(r);
    return fftwf_import_wisdom_from_string(wisdom.c_str()) != 0;
}

// ---- Analysis -------------------------------------------------------------------------------

TurbulenceSpectrum::TurbulenceSpectrum(const TurbulenceGrid& grid)
    : mRes(grid.res()), mTile(grid.tile()), mEnergyScale(grid.energyScale()) {
    const int n = mRes, nh = n / 2 + 1;
    const size_t rowPad = 2 * static_cast<size_t>(nh);
    const fftwf_plan plan = planFor(n, true, 1);
    const double norm = 1.0 / (static_cast<double>(n) * n * n);
    for (int c = 0; c < 3; ++c) {
        FftBuffer buf = makeBuffer(n);
        float* real = reinterpret_cast<float*>(buf.get());
        for (int iz = 0; iz < n; ++iz)
            for (int iy = 0; iy < n; ++iy)
                for (int ix = 0; ix < n; ++ix)
                    real[(static_cast<size_t>(iz) * n + iy) * rowPad + ix] =
                        grid.data()[((static_cast<size_t>(iz) * n + iy) * n + ix) * 3 + c];
        fftwf_execute_dft_r2c(plan, real, buf.get());
        const size_t count = static_cast<size_t>(n) * n * nh;
        mCoef[c].resize(count);
        for (size_t i = 0; i < count; ++i)
            mCoef[c][i] = std::complex<float>(static_cast<float>(buf.get()[i][0] * norm),
                                              static_cast<float>(buf.get()[i][1] * norm));
    }
}

std::complex<double> TurbulenceSpectrum::coefficient(int mx, int my, int mz, int c) const {
    const int n = mRes;
    bool conj = false;
    if (mx < 0) {
        mx = -mx;
        my = -my;
        mz = -mz;
        conj = true;
    }
    if (mx > n / 2) return {};
    const int iy = ((my % n) + n) % n, iz = ((mz % n) + n) % n;
    const std::complex<float> v = mCoef[c][(static_cast<size_t>(iz) * n + iy) * (n / 2 + 1) + mx];
    const std::complex<double> d(v.real(), v.imag());
    return conj ? std::conj(d) : d;
}

namespace {

// Visits every stored coefficient: (mx, my, mz signed, weight = modes it stands for, index).
template <class F>
void forEachMode(int n, const F& f) {
    const int nh = n / 2 + 1;
    for (int iz = 0; iz < n; ++iz)
        for (int iy = 0; iy < n; ++iy)
            for (int ix = 0; ix < nh; ++ix) {
                const double weight = (ix == 0 || ix == n / 2) ? 1.0 : 2.0;
                f(ix, signedIndex(iy, n), signedIndex(iz, n), weight, (static_cast<size_t>(iz) * n + iy) * nh + ix);
            }
}

} // namespace

double TurbulenceSpectrum::divergence() const {
    const double dk = 2.0 * kPi / mTile;
    double num = 0.0, den = 0.0;
    forEachMode(mRes, [&](int mx, int my, int mz, double w, size_t i) {
        const double k[3] = {mx * dk, my * dk, mz * dk};
        std::complex<double> kdotu = 0.0;
        double u2 = 0.0;
        for (int c = 0; c < 3; ++c) {
            const std::complex<double> u(mCoef[c][i].real(), mCoef[c][i].imag());
            kdotu += k[c] * u;
            u2 += std::norm(u);
        }
        num += w * std::norm(kdotu);
        den += w * (k[0] * k[0] + k[1] * k[1] + k[2] * k[2]) * u2;
    });
    return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

std::vector<TurbulenceShell> TurbulenceSpectrum::shells(double lengthScale) const {
    const int mmax = mRes / 2 - 1;
    const double dk = 2.0 * kPi / mTile, dk3 = dk * dk * dk;
    std::vector<double> wsum(mmax + 1, 0.0), esum(mmax + 1, 0.0), ksum(mmax + 1, 0.0);
    std::vector<int> count(mmax + 1, 0);
    forEachMode(mRes, [&](int mx, int my, int mz, double w, size_t i) {
        const int m2 = mx * mx + my * my + mz * mz;
        if (m2 == 0 || m2 > mmax * mmax) return;
        const double mm = std::sqrt(static_cast<double>(m2));
        const int shell = static_cast<int>(std::floor(mm + 0.5));
        const double kk = mm * dk;
        double u2 = 0.0;
        for (int c = 0; c < 3; ++c) u2 += std::norm(std::complex<double>(mCoef[c][i].real(), mCoef[c][i].imag()));
        wsum[shell] += w;
        esum[shell] += w * 4.0 * kPi * kk * kk * 0.5 * u2 / dk3;
        ksum[shell] += w * kk;
        count[shell] += static_cast<int>(w);
    });
    std::vector<TurbulenceShell> out;
    for (int s = 1; s <= mmax; ++s) {
        if (wsum[s] == 0.0) continue;
        TurbulenceShell sh;
        sh.index = s;
        sh.k = ksum[s] / wsum[s];
        sh.modes = count[s];
        sh.measured = esum[s] / wsum[s];
        sh.expected = mEnergyScale * vonKarmanEnergy(sh.k, lengthScale, 1.0);
        out.push_back(sh);
    }
    return out;
}

void TurbulenceSpectrum::evaluate(double x, double y, double z, double out[3]) const {
    const double dk = 2.0 * kPi / mTile;
    out[0] = out[1] = out[2] = 0.0;
    forEachMode(mRes, [&](int mx, int my, int mz, double w, size_t i) {
        const double phase = dk * (mx * x + my * y + mz * z);
        const double cs = std::cos(phase), sn = std::sin(phase);
        // (ix = 0 or n/2: the partner is stored too; its imaginary parts cancel with this one's.)
        for (int c = 0; c < 3; ++c) out[c] += w * (mCoef[c][i].real() * cs - mCoef[c][i].imag() * sn);
    });
}

void turbulenceMoments(const TurbulenceGrid& grid, double mean[3], double variance[3]) {
    const size_t count = static_cast<size_t>(grid.res()) * grid.res() * grid.res();
    double s[3] = {0, 0, 0}, s2[3] = {0, 0, 0};
    for (size_t i = 0; i < count; ++i)
        for (int c = 0; c < 3; ++c) {
            const double v = grid.data()[3 * i + c];
            s[c] += v;
            s2[c] += v * v;
        }
    for (int c = 0; c < 3; ++c) {
        mean[c] = s[c] / count;
        variance[c] = s2[c] / count - mean[c] * mean[c];
    }
}

} // namespace gale::fields
