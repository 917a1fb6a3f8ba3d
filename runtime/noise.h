// The noise core: gradient noise in 2-4 dimensions (with analytic derivatives), cellular and
// Voronoi noise, and the fractal sums built on them, computed for many points per call in
// structure-of-arrays form so that the lane loops vectorise. Integer hashing, no table lookups.
#pragma once

#include <cstdint>

namespace gale::runtime::noise {

// Lanes processed per internal pass (every function accepts any n and loops in passes of this).
constexpr int kPass = 256;

// Octave counts are clamped to this range (SeExpr2: octaves = int(clamp(octaves, 1, 8))).
constexpr int kMaxOctaves = 8;

// The SIMD level the lane loops run at: chosen by CPUID (every level gives identical bits).
enum class Simd { Sse2 = 0, Sse42 = 1, Avx2 = 2, Avx512 = 3 };
Simd detectedSimd();   // the best level this CPU supports
Simd simdLevel();      // the level in use: detectedSimd(), capped by limitSimd()
void limitSimd(Simd max); // tests and benchmarks: run at most at this level (process-wide)
const char* simdName(Simd s);

// Seeds: channel k of a multi-channel noise, octave o of a fractal sum. Independent seeds play
// the role of SeExpr2's P + 1000k channel offset without costing float precision.
uint32_t channelSeed(int channel, int octave = 0);

// ---- Gradient noise (signed; 0 on lattice points; quintic fade; rms 0.19, |n| < ~0.75) -----

// The 2D form (noise(x, y)).
template <class T>
void gradient2(int n, const T* x, const T* y, uint32_t seed, T* out);

// 3D: `channels` (1..3) independent noises at the same points, channel c with seeds[c]; the
// lattice work is shared between channels. out[c][i].
template <class T>
void gradient3(int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds, T* const* out);

// 3D with the analytic gradient: value[i] and d/dx, d/dy, d/dz in grad[0..2][i]. The value
// is bit-identical to gradient3's.
template <class T>
void gradient3Deriv(int n, const T* x, const T* y, const T* z, uint32_t seed, T* value, T* const* grad);

// 3D with every lattice gradient turned by the rotation R (row-major, per lane: rot[9][i]),
// and its analytic gradient. With R = identity it equals gradient3Deriv. Flow noise.
template <class T>
void gradient3Rotated(int n, const T* x, const T* y, const T* z, const T* const* rot, uint32_t seed, T* value,
                      T* const* grad);

// 3D, periodic: the lattice wraps with the integer periods px, py, pz (per lane, >= 1).
template <class T>
void gradient3Periodic(int n, const T* x, const T* y, const T* z, const int32_t* px, const int32_t* py,
                       const int32_t* pz, uint32_t seed, T* out);

// 4D: as gradient3 with a fourth coordinate w.
template <class T>
void gradient4(int n, const T* x, const T* y, const T* z, const T* w, int channels, const uint32_t* seeds,
               T* const* out);
// 4D with the analytic gradient (grad[0..3]); the value equals gradient4's.
template <class T>
void gradient4Deriv(int n, const T* x, const T* y, const T* z, const T* w, uint32_t seed, T* value, T* const* grad);

// ---- Cellular noise ------------------------------------------------------------------------

// A uniform random value in [0, 1] per integer cell floor(x, y, z), for `channels` seeds.
template <class T>
void cell3(int n, const T* x, const T* y, const T* z, int channels, const uint32_t* seeds, T* const* out);

// Worley/Voronoi: one feature point per cell c at c + 0.5 + jitter * (cell3(c) - 0.5); the
// distances to the nearest (f1, pos1) and second nearest (f2, pos2) of the 27 cells around each
// point, and the nearest point's cell. jitter is per lane (the caller clamps it to [1e-3, 1]).
template <class T>
struct VoronoiLanes {
    T* f1;
    T* f2;
    T* pos1[3];
    T* pos2[3];
    int32_t* cell1[3];
};
template <class T>
void voronoi3(int n, const T* x, const T* y, const T* z, const T* jitter, const VoronoiLanes<T>& out);

// ---- Fractal sums --------------------------------------------------------------------------

// Per-lane fractal parameters (arrays of n). Octaves are clamped to 1..8 and truncated; NaN
// gives 1. Each octave: P = P * lacunarity + offset (a fixed fractional offset per octave),
// amplitude *= gain.
template <class T>
struct FractalLanes {
    const T* octaves;
    const T* lacunarity;
    const T* gain;
};

// Σ amp_o * n_o(P_o) (turbulence: Σ amp_o * |n_o(P_o)|), for `channels` (1..3) channels.
template <class T>
void fbm3(int n, const T* x, const T* y, const T* z, const FractalLanes<T>& f, bool turbulence, int channels,
          T* const* out);
// The 4D form: P_o = (P, t) * lacunarity^o + offsets.
template <class T>
void fbm4(int n, const T* x, const T* y, const T* z, const T* w, const FractalLanes<T>& f, int channels,
          T* const* out);

// Curl noise (Bridson, Hourihan, Nordenstam 2007): curl of the vector potential
// psi = Σ_o (gain/lacunarity)^o N_o(P_o), three independent gradient noises, so that octave o
// contributes gain^o times a unit-frequency curl field. Divergence-free by construction. Scaled
// so that one octave has component rms 0.19 (like vnoise).
template <class T>
void curl3(int n, const T* x, const T* y, const T* z, const FractalLanes<T>& f, T* const* out);
// The same with a 4D potential N(P_o, t_o); the curl is taken in space.
template <class T>
void curl4(int n, const T* x, const T* y, const T* z, const T* t, const FractalLanes<T>& f, T* const* out);
// Flow noise: curl noise whose lattice gradients turn with time. Octave o's gradients of
// potential channel c rotate about the fixed axis a_c by the angle t * (lacunarity*gain)^o.
template <class T>
void flow3(int n, const T* x, const T* y, const T* z, const T* t, const FractalLanes<T>& f, T* const* out);

// sin and cos by polynomial (identical results on every machine, vectorisable).
template <class T>
void sinCos(int n, const T* x, T* s, T* c);

} // namespace gale::runtime::noise
