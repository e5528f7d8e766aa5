// Per-pixel sample sets over the camera's sample space: film (2D) + lens (2D)
// + time (1D, when something moves during the shutter; motion.h).
// A sampler fills all of a pixel's samples at once; the render loop then hands
// them to the camera in order (film[i] with lens[i]). Dispatch on the sampler
// kind happens once per pixel, never per sample. New samplers add an enum value
// and one function.
//
// Every sampler gives points in [0,1)^2, depends only on (seed, pixel_index,
// spp) — never on threads or tiling — and pairs film and lens points so that
// the two 2-D dimensions are decorrelated or, for sobol, jointly stratified.
//
//   random    independent uniform points (PCG32 stream per pixel and dimension)
//   jittered  one uniform point per stratum of an nx x ny grid; lens order
//             shuffled per pixel
//   regular   the centres of the same nx x ny grid, identical in every pixel and
//             for every seed; lens cells paired with film cells by a fixed
//             shear of the grid (samplers.cpp)
//   poisson   blue noise: Poisson-disk sets made by weighted sample elimination
//             (Yuksel 2015), a fixed pool per spp, each pixel drawing a pattern
//             under a random toroidal shift and square symmetry
//             (sampler_poisson.cpp)
//   sobol     the first spp points of Sobol' dimensions 0-3, Owen-scrambled per
//             pixel by hashing (Burley 2020): film from dimensions 0-1 (a
//             (0,2)-sequence), lens from 2-3, jointly a (3,4)-sequence
//             (sampler_sobol.cpp); time i / spp, Owen-scrambled, for a
//             pixel drawn whole (film and time a (0,m,3)-net), or dimension 6
//             of the same sequence for a pass continuing a pixel
//             (pass_sampler), so film, lens and time are stratified jointly
//
// Time, for the others: a stratified 1-D set of spp points (one per interval
// [k/spp, (k+1)/spp)), paired with the film and lens samples by a per-pixel
// random permutation (random: independent uniform times; regular: interval
// centres in a fixed order from Roberts' R2 lattice over the film cells, the
// same in every pixel; samplers.cpp). Each
// dimension is stratified on its own and the pairing decorrelates them; only
// sobol stratifies time jointly with film and lens. Drawing times never
// changes a pixel's film and lens points: the time streams are their own.
//
// Wavelength (spectral renders; spectral.h maps it to nm) is drawn the same
// way as time, from streams of its own: sobol from dimension 5 of the same
// sequence (jointly stratified with film, lens and time), the others a
// stratified 1-D set paired by a per-pixel permutation (regular: interval
// centres ranked by a lattice other than time's). Drawing wavelengths never
// changes a pixel's film, lens or time points.
#pragma once

#include <cmath>
#include <cstdint>

#include "vec.h"

namespace lc {

enum class SamplerKind : int {
    Random = 0,
    Jittered = 1,
    Regular = 2,
    Poisson = 3,
    Sobol = 4,
    // For tests only, not offered by scene files: the bare Sobol' points
    // 0..spp-1, the same for film and lens, every pixel and every seed.
    SobolUnscrambled = 5,
    // For the joint-stratification study only: film, lens and time each from
    // their own Owen-scrambled Sobol' points (dimensions 0-1, 0-1, 0), the
    // lens and time points paired with the film points by random per-pixel
    // permutations ("padding"): each group stratified alone, not jointly.
    SobolPadded = 6,
    // sobol, but each pixel's time from the index, i / spp (Owen-scrambled),
    // not from dimension 6: film (dimensions 0-1) and time then form a
    // (0,m,3)-net in base 2 (generator matrices I, Pascal, reversal). Not
    // extensible (a sample's time depends on spp): the render uses it for
    // sobol only where a pixel's samples are drawn whole (pass_sampler).
    SobolTimeNet = 7,
};

// Square -> unit disk mappings for lens samples.
enum class DiskMapping : int { Polar = 0, Concentric = 1 };

// Fills film[0..spp) and lens[0..spp) with points in [0,1)^2 for one pixel.
// The same (seed, pixel_index) always gives the same points.
// time (nullptr: not drawn) receives spp sample times in [0, 1), and
// wavelength (nullptr: not drawn) spp wavelength samples in [0, 1). lens may
// be nullptr too (a camera that ignores it): the film, time and wavelength
// points are the same either way.
void fill_pixel_samples(SamplerKind kind, uint64_t seed, uint64_t pixel_index, int spp,
                        Point2f* film, Point2f* lens, float* time = nullptr, float* wavelength = nullptr);

// The sampler a render pass fills a pixel with when the pass takes the
// pixel's samples from first_sample on: sobol becomes SobolTimeNet (time from
// the index) when the samples are drawn whole (first_sample 0), and stays
// sobol (time from dimension 6) when a pass continues them. Others unchanged.
SamplerKind pass_sampler(SamplerKind kind, int first_sample);

// Strata of the jittered and regular samplers: nx * ny == spp, ny the largest
// divisor of spp not above sqrt(spp) (8x8 for 64, 16x8 for 128; a prime spp
// gets spp x 1).
void jittered_strata(int spp, int* nx, int* ny);

// Unit-square sample -> point in the unit disk, area-preserving.
Point2f map_to_disk(Point2f u, DiskMapping mapping);

// sin and cos of phi in [-pi/4, pi/4] by their Taylor series to phi^9 and
// phi^10 in single precision (the next terms are below 2e-9, a thirtieth of
// a float's last bit at 1): no libm call, so a batch of lens samples maps
// side by side in SIMD lanes (cameras/thin_lens_lanes.cpp) with the same bits
// as one at a time, on every instruction set. In double to phi^14 this was a
// tenth of an empty scene's thin-lens render (perf), and its result was
// rounded to float anyway.
[[gnu::always_inline]] inline void sin_cos_quarter_turn(float phi, float* sin_phi, float* cos_phi) {
    const float p = phi * phi;
    *sin_phi = phi * (1.0f + p * (-1.0f / 6.0f + p * (1.0f / 120.0f + p * (-1.0f / 5040.0f + p * (1.0f / 362880.0f)))));
    *cos_phi = 1.0f + p * (-1.0f / 2.0f + p * (1.0f / 24.0f + p * (-1.0f / 720.0f + p * (1.0f / 40320.0f +
               p * (-1.0f / 3628800.0f)))));
}

// Shirley & Chiu 1997 concentric mapping (map_to_disk's DiskMapping::Concentric),
// in single precision, as map_to_disk returns it. Without branches, so that
// it runs in SIMD lanes.
[[gnu::always_inline]] inline void concentric_disk(Point2f u, double* x, double* y) {
    const float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
    // The wider coordinate is the radius, the other over it the angle in
    // quarter turns: phi = pi/4 (oy/ox) from the x axis, or from the y axis.
    const bool from_x_axis = std::fabs(ox) > std::fabs(oy);
    const float r = from_x_axis ? ox : oy, across = from_x_axis ? oy : ox;
    const float phi = 0.785398163f * (across / (r != 0.0f ? r : 1.0f));  // r = 0 only at the centre
    float s, c;
    sin_cos_quarter_turn(phi, &s, &c);
    // Both selects as plain values: written inside the products, GCC kept a
    // branch and left the loop in concentric_disk_lanes scalar (8 % of a thin
    // lens render, perf).
    const float along = from_x_axis ? c : s, side = from_x_axis ? s : c;
    *x = double(r * along);
    *y = double(r * side);
}

// The same point as (r cos theta, r sin theta) before the last step; r may be
// negative (the concentric map's left and lower halves). For shaped
// apertures (aperture.h), which map theta onto a polygon.
struct PolarDiskPoint {
    float r, theta;
};
PolarDiskPoint map_to_disk_polar(Point2f u, DiskMapping mapping);

// One function per sampler defined in its own file; each fills one pixel.
void fill_poisson(uint64_t seed, uint64_t pixel_index, int spp, Point2f* film, Point2f* lens);
// Makes the poisson sampler's patterns for spp now (they are otherwise made on first use).
void prepare_poisson_patterns(int spp);
void fill_sobol(uint64_t seed, uint64_t pixel_index, int spp, bool scrambled, Point2f* film, Point2f* lens,
                float* time, float* wavelength = nullptr, bool time_from_index = false);
void fill_sobol_padded(uint64_t seed, uint64_t pixel_index, int spp, Point2f* film, Point2f* lens, float* time);

// Largest float below 1: where a sample that rounds up to 1 is put back.
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

// std::fmin(v, kOneMinusEpsilon), inline: std::fmin is a libm call through the
// PLT at the baseline instruction set (its NaN rule has no SSE instruction),
// about 1 % of a jittered render's loop (perf). The same result for every v,
// NaN included.
inline float below_one(float v) { return v < kOneMinusEpsilon ? v : kOneMinusEpsilon; }

}  // namespace lc
