// FFT turbulence: periodic, divergence-free, von Kármán-spectrum velocity grids synthesised with
// FFTW (float), cached per parameter set, sampled trilinearly or tricubically; animated by
// per-mode random frequencies (Kraichnan) and/or Taylor advection. See docs/turbulence.md.
#pragma once

#include "runtime/builtins.h"

#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace gale::fields {

// ---- The analytic spectrum ------------------------------------------------------------------

// L_e / L: the von Kármán spectrum's length parameter over the longitudinal integral length
// scale L = ∫ f(r) dr, i.e. Γ(1/3) / (√π Γ(5/6)) (the 1.339 of the wind-engineering form).
constexpr double kVonKarmanLeOverL = 1.3389852790652803;

// E(k) = (55/9) Γ(5/6)/(√π Γ(1/3)) σ² L_e (k L_e)⁴ / (1 + (k L_e)²)^(17/6), L_e = 1.339 L:
// ∫E dk = 3σ²/2 (σ the rms of each component), longitudinal integral scale L.
double vonKarmanEnergy(double k, double lengthScale, double sigma);

// ---- Grids ----------------------------------------------------------------------------------

enum class TurbulenceInterp { Trilinear = 0, Tricubic = 1 }; // tricubic: Catmull-Rom

// Everything that determines a synthesised grid (defaults already resolved). Float fields so
// that float and double programs share grids.
struct TurbulenceSpec {
    float lengthScale = 1.0f; // L (m): longitudinal integral length scale
    float tile = 8.0f;        // period (m)
    int res = 32;             // grid points per axis (even)
    int64_t seed = 0;
    float tau = 0.0f;         // integral time scale of the mode evolution; 0: frozen
    float time = 0.0f;        // the instant (ignored when tau = 0)

    bool operator<(const TurbulenceSpec& o) const;
    bool operator==(const TurbulenceSpec& o) const;
};

// Default period: 8 L.
double defaultTurbulenceTile(double lengthScale);
// Grid size: res > 0 is rounded up to even and clamped to [8, 512]; res <= 0 picks one —
// with minScale (m) finite and > 0: the largest even 2^a 3^b 5^c <= 2 tile / minScale (no
// eddy shorter than minScale); otherwise the smallest even 2^a 3^b 5^c >= 4 tile / L (4
// cells per L); both clamped to [16, 256].
int resolveTurbulenceRes(double res, double lengthScale, double tile, double minScale);

// A res³ grid of float velocity (x, y, z interleaved, x fastest) with unit rms per component,
// periodic with period tile. Immutable, shared between threads.
class TurbulenceGrid {
public:
    // Synthesises the grid of `spec`. threads: FFTW and loop threads, 0 = hardware. The
    // result does not depend on the thread count.
    static std::shared_ptr<const TurbulenceGrid> synthesize(const TurbulenceSpec& spec, int threads = 0);
    // A grid from given samples (tests of the interpolation); data has 3 res³ floats.
    static std::shared_ptr<const TurbulenceGrid> fromData(int res, double tile, std::vector<float> data);

    int res() const { return mRes; }
    double tile() const { return mTile; }
    double cellSize() const { return mTile / mRes; }
    const float* data() const { return mData.data(); }
    size_t bytes() const { return mData.size() * sizeof(float); }
    // Discrete spectrum / analytic spectrum (σ = 1): the variance of the unresolved scales
    // (below 2π/tile, above the truncation sphere) is redistributed over the resolved modes.
    double energyScale() const { return mEnergyScale; }
    // Modes kept: 0 < |m| <= maxMode (m the integer wavevector, k = 2π m / tile).
    int maxMode() const { return mRes / 2 - 1; }
    const TurbulenceSpec& spec() const { return mSpec; }

    // Velocity at (x, y, z), wrapped into the tile (non-finite input gives NaN).
    void sample(double x, double y, double z, TurbulenceInterp interp, float out[3]) const;
    // n points, xyz interleaved in and out.
    void sampleMany(const double* xyz, size_t n, TurbulenceInterp interp, float* out) const;

private:
    TurbulenceGrid() = default;
    int mRes = 0;
    double mTile = 1.0;
    double mEnergyScale = 1.0;
    TurbulenceSpec mSpec;
    std::vector<float> mData;
};

// ---- Cache ----------------------------------------------------------------------------------

// Grids by spec, least recently used evicted beyond maxEntries or maxBytes (the newest grid
// is always kept). Thread-safe; a grid is synthesised once, outside the lock, while other
// threads asking for the same spec wait for it.
class TurbulenceCache {
public:
    static constexpr size_t kDefaultMaxBytes = size_t(1) << 30; // 1 GiB
    static constexpr size_t kDefaultMaxEntries = 8;

    explicit TurbulenceCache(size_t maxBytes = kDefaultMaxBytes, size_t maxEntries = kDefaultMaxEntries,
                             int threads = 0);
    ~TurbulenceCache();
    TurbulenceCache(const TurbulenceCache&) = delete;
    TurbulenceCache& operator=(const TurbulenceCache&) = delete;

    // The process-wide cache the built-ins use by default.
    static const std::shared_ptr<TurbulenceCache>& global();

    // The grid of `spec` (time ignored when tau = 0). Rethrows what synthesis threw.
    std::shared_ptr<const TurbulenceGrid> get(const TurbulenceSpec& spec) const;

    struct Stats {
        size_t hits = 0, misses = 0, entries = 0, bytes = 0;
    };
    Stats stats() const;
    void clear();

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

// ---- FFTW planning --------------------------------------------------------------------------

// Plans are made once per size and kept. Estimate (the default) is reproducible run to run;
// Measure may find faster plans but their rounding can differ between runs.
enum class FftPlanning { Estimate, Measure };
void setTurbulenceFftPlanning(FftPlanning p);
// FFTW's accumulated wisdom, to persist and re-import (the library never touches files).
std::string exportTurbulenceFftWisdom();
bool importTurbulenceFftWisdom(const std::string& wisdom);

// ---- Analysis (tests, benchmarks) -----------------------------------------------------------

struct TurbulenceShell {
    int index = 0;           // shell n: n - 1/2 <= |m| < n + 1/2
    double k = 0.0;          // mean |k| of its modes
    int modes = 0;           // modes in the shell (all of k-space)
    double measured = 0.0;   // shell average of 4π|k|² ½|û(k)|² / Δk³ (unit-σ grid)
    double expected = 0.0;   // energyScale · E(k) at the mean |k|, σ = 1
};

// The forward transform of a grid: its Fourier-series coefficients û(m) (u = Σ û e^{ik·x}).
class TurbulenceSpectrum {
public:
    explicit TurbulenceSpectrum(const TurbulenceGrid& grid);

    // Coefficient of component c at the integer wavevector m (|m_i| <= res/2).
    std::complex<double> coefficient(int mx, int my, int mz, int c) const;
    // sqrt(Σ |k·û|² / Σ |k|² |û|²) over all modes, with the synthesis's wavenumbers.
    double divergence() const;
    // Shells 1 .. maxMode, measured against the analytic spectrum of length scale L.
    std::vector<TurbulenceShell> shells(double lengthScale) const;
    // The band-limited (trigonometric) interpolant at a point: the exact field. Slow.
    void evaluate(double x, double y, double z, double out[3]) const;

private:
    int mRes = 0;
    double mTile = 1.0;
    double mEnergyScale = 1.0;
    std::vector<std::complex<float>> mCoef[3]; // r2c layout: ((z * res + y) * (res/2+1) + x)
};

// Per-component mean and variance over the grid points.
void turbulenceMoments(const TurbulenceGrid& grid, double mean[3], double variance[3]);

// ---- Built-ins --------------------------------------------------------------------------------

// fftturb and fftturb4 sharing `cache` (addTurbulenceBuiltins(t) uses TurbulenceCache::global()).
void addTurbulenceBuiltins(runtime::FunctionTable& t, std::shared_ptr<TurbulenceCache> cache);

} // namespace gale::fields
