// The render loop's stages for a spectral render ([render] spectral = true)
// whose wavelengths are drawn: through a camera that disperses, or any camera
// when asked to (SpectralTables::integrate_still false). Through a camera
// that does not disperse the wavelengths are integrated exactly instead and
// the render is render_tile's (render.h, Scene::spectral_integrated_radiance).
// Each camera sample draws four hero wavelengths (spectral.h), the scene
// returns radiance at them and the film weights each by its CIE 1931 response
// over its density. A sample's value is
//     (1 / 4) sum_k L(λ_k) film(λ_k) / p(λ_k)
// in linear sRGB, summed into the pixel like an RGB sample (TileAccumulator).
//
// A camera that disperses (generate_rays_at: its ray depends on the
// wavelength) cannot share one ray between the four. Then 1, 2 or 4 of them
// (SpectralTables::traced_wavelengths, evenly spaced through the rotation,
// hero first) each get their own ray and the others are dropped: the sample's
// value is (1 / n) sum over the n traced of L(λ_k) film(λ_k) / p(λ_k), still
// unbiased since each traced wavelength is drawn from the density. The lens
// system traces 2, the hero and the wavelength half the distribution away
// (lenscompare/render_spectral.py): bench/bench_spectral.py --cpu-time,
// showcase through dgauss_abbe, time to 1 % relative RMSE over RGB's: one
// 8.6x (its colour noise: 2.7x RGB's RMSE), two 3.9x, four 4.6x. A pair's
// colour noise is what is left: the antipode beats any other spacing and
// mirrored pairs (u, 1 - u), and refitting the density for pairs took 15 %
// off it (numerically, for white), too little to matter. A camera that can
// say when a wavelength's own sample gives the hero's very ray
// (generate_rays_sharing: the thin and thick lens) traces all four, with
// those wavelengths riding on the hero's ray and only the others traced.
//
// Tried and not kept (session 8, branch lambda1, commit b579fb3): control
// variates, the secondaries on the hero's ray every sample and their own rays
// on one sample in N adding N (own - shared). Unbiased, but a dispersed ray
// sees something else often enough that the correction's noise outweighs the
// rays saved: 4.4x RGB's time to 1 % for N = 2, 3; 4.7x for N = 4.
//
// Tried and not kept (session 10): the d-line ray as a control variate
// whose wavelength integral is exact (Scene::spectral_integrated_radiance's
// reading of it, less its reading at each traced wavelength, plus the
// traced rays' own). Unbiased, and it removes the colour noise of drawing
// wavelengths where dispersion changes nothing, but what is left (where it
// does: fringes of the defocused lamps) is most of the noise: showcase
// through dgauss_abbe, 180x120, 64 spp, relative RMSE 0.0360 with one traced
// wavelength against 0.0384 for two traced without it, at the same cost
// (2 rays a sample), so time to 1 % 3.55x RGB's against 3.86x; the thin
// lens derived from it 4.45x, worse than riding on the hero (3.1x).
//
// Tried and not kept (session 7, branch mis): one ray per sample with the
// secondaries weighted by multiple importance sampling over the four
// wavelengths' cameras (Wilkie et al. 2014's spectral MIS applied to the
// lens system, back-tracing the hero's ray at each wavelength). Unbiased, but
// dispersion moves a secondary's film point across pixel boundaries often
// enough that the noise rose 1.8x (showcase through dgauss_abbe, 180x120):
// 9.3x RGB's time to 1 % against 4.4x for tracing every wavelength.
#pragma once

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "render_tile.h"
#include "spectral.h"

namespace lc {

// Cameras whose ray depends on the wavelength say so with generate_rays_at(raster, lens, nm, n, out)
// and disperses() (false when the lens has no glass with dispersion).
template <class Camera, class = void>
struct HasWavelengthRays : std::false_type {};
template <class Camera>
struct HasWavelengthRays<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_rays_at(
                                     Point2f{}, Point2f{}, nullptr, 0, static_cast<MaybeRay*>(nullptr)))>>
    : std::true_type {};

// Cameras that turn a batch of samples into rays at their wavelengths at
// once (the lens system traces them in lockstep) say so with
// generate_rays_at_batch(raster, lens, nm, n, traced, out).
template <class Camera, class = void>
struct HasWavelengthBatches : std::false_type {};
template <class Camera>
struct HasWavelengthBatches<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_rays_at_batch(
                                        nullptr, nullptr, nullptr, 0, 0,
                                        static_cast<MaybeRay(*)[kHeroWavelengths]>(nullptr)))>>
    : std::true_type {};

// Cameras that find those rays in float, a CameraRayRows per traced
// wavelength with their weights and vignetting (the lens system), say so with
// generate_weighted_ray_rows_at(raster, lens, nm, n, traced, rows, weight, alive, check).
template <class Camera, class = void>
struct HasWavelengthRayRows : std::false_type {};
template <class Camera>
struct HasWavelengthRayRows<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_weighted_ray_rows_at(
                                        static_cast<const Point2f*>(nullptr), static_cast<const Point2f*>(nullptr),
                                        static_cast<const float (*)[kHeroWavelengths]>(nullptr), 0, 0,
                                        static_cast<CameraRayRows*>(nullptr),
                                        static_cast<float (*)[kCameraBatch]>(nullptr),
                                        static_cast<bool (*)[kCameraBatch]>(nullptr),
                                        static_cast<const LensPencilCheck*>(nullptr)))>> : std::true_type {};

// Rays for n <= kCameraBatch samples, sample i at wavelengths nm[i][0, traced).
template <class Camera>
void wavelength_rays(const Camera& camera, const Point2f* raster_px, const Point2f* lens,
                     const float (*nm)[kHeroWavelengths], int n, int traced, MaybeRay (*out)[kHeroWavelengths]) {
    if constexpr (HasWavelengthBatches<Camera>::value) {
        camera.generate_rays_at_batch(raster_px, lens, nm, n, traced, out);
    } else if constexpr (HasWavelengthRays<Camera>::value) {
        for (int i = 0; i < n; ++i) camera.generate_rays_at(raster_px[i], lens[i], nm[i], traced, out[i]);
    }
}

// Cameras that can tell which wavelengths' rays are the hero's (see the top)
// say so with generate_rays_sharing(raster, lens, nm, out, shares).
template <class Camera, class = void>
struct HasSharedWavelengthRays : std::false_type {};
template <class Camera>
struct HasSharedWavelengthRays<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_rays_sharing(
                                           Point2f{}, Point2f{}, nullptr, static_cast<MaybeRay*>(nullptr),
                                           static_cast<bool*>(nullptr)))>>
    : std::true_type {};

// Those that find the same rays for a whole batch in float rows say so with
// generate_shared_ray_rows(raster, lens, wavelengths, n, rows, own).
template <class Camera, class = void>
struct HasSharedWavelengthRows : std::false_type {};
template <class Camera>
struct HasSharedWavelengthRows<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_shared_ray_rows(
                                           static_cast<const Point2f*>(nullptr), static_cast<const Point2f*>(nullptr),
                                           static_cast<const HeroWavelengths*>(nullptr), 0,
                                           static_cast<CameraRayRows*>(nullptr),
                                           static_cast<bool (*)[kCameraBatch]>(nullptr)))>> : std::true_type {};

template <class Camera>
bool camera_disperses(const Camera& camera) {
    if constexpr (HasWavelengthRays<Camera>::value) return camera.disperses();
    else return false;
}

// Rays waiting for the scene, each with its wavelengths; a camera sample's
// rays arrive together and in order, its value goes to the pixel after its last.
// Every ray is shaded at all four of its sample's wavelengths, 4 wide (as
// cheap as one); those it does not carry have a film weight of 0. A ray
// holds its sample's wavelengths by pointer, not a copy of their 28 floats
// (3 % off a lens-system render with 2 traced wavelengths, session 13): the
// batcher keeps them until release.
class SpectralRayPacket {
  public:
    SpectralRayPacket(const Scene& scene, TileAccumulator& sums) : scene_(scene), sums_(sums) {}

    // As RayPacket's: from now on the rays only test the own primitives some
    // ray of pencil may meet, or (uncull) every one again.
    void cull_by(const CameraPencil& pencil) { scene_.camera_candidates(pencil, &batch_); }
    void uncull() { batch_.uncull(); }
    // The packets' stream (RayBatch::stream), [0, RayBatch::kStreams).
    void set_stream(int stream) { batch_.stream = stream; }

    // Queues a ray carrying the lanes of *w in lanes (bit m: lane m), each
    // weighted by s (the ray's weight over the sample's traced wavelength
    // count); last: the sample's last ray.
    void add(const CameraRay& ray, float time_u, const HeroWavelengths* w, float s, unsigned lanes, bool last,
             size_t slot) {
        batch_.set(batch_.count, ray);
        batch_.time[batch_.count] = time_u;
        queue(w, s, lanes, last, slot);
    }

    // Queues the rays of samples [0, n) of a camera batch, each sample's in
    // wavelength order: rays[k] holds sample i's ray at the k-th traced
    // wavelength (the rotation's k * stride) or, when carries_all, rays[0]
    // its one ray carrying all four. As add, ray by ray, with no CameraRay
    // between: the rows rounded to float first, as RayPacket::add_batch.
    void add_batch(const CameraRayBatch* rays, int traced, int stride, bool carries_all, int n,
                   const HeroWavelengths* w, const float* time_u, const size_t* slot) {
        const float* weight[kHeroWavelengths];
        const bool* alive[kHeroWavelengths];
        for (int k = 0; k < traced; ++k) {
            round_rows(rays[k], n, &rounded_[k]);
            weight[k] = rays[k].weight, alive[k] = rays[k].alive;
        }
        add_rows(rounded_, weight, alive, traced, stride, carries_all, n, w, time_u, slot);
    }

    // As add_batch for rays found in float: rows[k], weight[k] and alive[k]
    // the k-th traced wavelength's.
    void add_rows(const CameraRayRows* rows, const float* const* weight, const bool* const* alive, int traced,
                  int stride, bool carries_all, int n, const HeroWavelengths* w, const float* time_u,
                  const size_t* slot) {
        // 1 / (1, 2 or 4): the product is the quotient, exactly.
        const float share = 1.0f / float(carries_all ? kHeroWavelengths : traced);
        for (int i = 0; i < n; ++i) {
            int last = -1;
            for (int k = 0; k < traced; ++k)
                if (alive[k][i]) last = k;
            for (int k = 0; k <= last; ++k) {
                if (!alive[k][i]) continue;  // vignetted, or blocked at this wavelength
                const int j = batch_.count;
                batch_.set(j, rows[k], i);
                batch_.time[j] = time_u[i];
                const unsigned lanes = carries_all ? 0xfu : 1u << w[i].lane(k * stride);
                queue(&w[i], weight[k][i] * share, lanes, k == last, slot[i]);
            }
        }
    }

    // Queues samples [0, n)'s rays of generate_shared_ray_rows: sample i's
    // ray k where own[k][i], in k order, the hero's (k = 0) carrying every
    // wavelength that shares it, each weighted 1/4 (a thin lens's weight is 1).
    void add_shared_rows(const CameraRayRows* rows, const bool (*own)[kCameraBatch], int n,
                         const HeroWavelengths* w, const float* time_u, const size_t* slot) {
        const float share = 1.0f / float(kHeroWavelengths);
        for (int i = 0; i < n; ++i) {
            int last = 0;
            unsigned hero_lanes = 0;
            for (int k = 0; k < kHeroWavelengths; ++k) {
                if (own[k][i] && k > 0) last = k;
                if (k == 0 || !own[k][i]) hero_lanes |= 1u << w[i].lane(k);
            }
            for (int k = 0; k <= last; ++k) {
                if (!own[k][i]) continue;
                const int j = batch_.count;
                batch_.set(j, rows[k], i);
                batch_.time[j] = time_u[i];
                queue(&w[i], share, k == 0 ? hero_lanes : 1u << w[i].lane(k), k == last, slot[i]);
            }
        }
    }

    // Queues samples [0, n)'s rays found in float, each carrying all four
    // wavelengths with weight 1 (GeneratesRayRows): as add_batch with
    // carries_all, no double columns between.
    void add_rows(const CameraRayRows& rows, int n, const HeroWavelengths* w, const float* time_u,
                  const size_t* slot) {
        const float share = 1.0f / float(kHeroWavelengths);
        for (int i = 0; i < n; ++i) {
            const int j = batch_.count;
            batch_.set(j, rows, i);
            batch_.time[j] = time_u[i];
            queue(&w[i], share, 0xfu, true, slot[i]);
        }
    }

    // Shades the queued rays now if any holds wavelengths in [first, end),
    // which the caller is about to overwrite.
    void release(const HeroWavelengths* first, const HeroWavelengths* end) {
        bool holds = false;
        const auto from = reinterpret_cast<uintptr_t>(first), to = reinterpret_cast<uintptr_t>(end);
        for (int j = 0; j < batch_.count; ++j) {
            const auto at = reinterpret_cast<uintptr_t>(wavelengths_[j]);
            holds |= at >= from && at < to;
        }
        if (holds) flush();
    }

    void flush() {
        if (batch_.count == 0) return;
        alignas(16) float radiance[kPacketSize][kHeroWavelengths];
        scene_.spectral_radiance(batch_, wavelengths_, radiance);
        // The sample's value in a local: the member, stored in two parts at
        // every ray and reloaded whole at the next, stalled store forwarding.
        Vec3f pending = pending_;
        for (int j = 0; j < batch_.count; ++j) {
            // CIE 1931 response over the density times the ray's scale (0
            // for lanes it does not carry), wavelength by wavelength, in lane order
            const HeroWavelengths& w = *wavelengths_[j];
            float scale[kHeroWavelengths];  // lane by lane (a vector load of scattered stores stalls)
            for (int m = 0; m < kHeroWavelengths; ++m) scale[m] = (lanes_[j] >> m & 1u) ? scale_[j] : 0.0f;
            float sum[3][kHeroWavelengths];
            for (int c = 0; c < 3; ++c)
                for (int m = 0; m < kHeroWavelengths; ++m)
                    sum[c][m] = (w.film_over_pdf[c][m] * scale[m]) * radiance[j][m];
            pending += Vec3f{(sum[0][0] + sum[0][1]) + (sum[0][2] + sum[0][3]),
                             (sum[1][0] + sum[1][1]) + (sum[1][2] + sum[1][3]),
                             (sum[2][0] + sum[2][1]) + (sum[2][2] + sum[2][3])};
            if (last_[j]) {
                finished_.add(slot_[j], pending);
                pending = Vec3f{};
            }
        }
        samples_shaded_ += uint64_t(finished_.add_to(sums_));
        pending_ = pending;
        batch_.count = 0;
    }

    // Camera samples with at least one ray that reached the scene.
    uint64_t samples_shaded() const { return samples_shaded_; }

  private:
    // The rest of queueing ray batch_.count (its geometry and time written);
    // a full packet is shaded at once.
    void queue(const HeroWavelengths* w, float s, unsigned lanes, bool last, size_t slot) {
        const int j = batch_.count;
        wavelengths_[j] = w;
        scale_[j] = s;
        lanes_[j] = lanes;
        last_[j] = last;
        slot_[j] = slot;
        if (++batch_.count == kPacketSize) flush();
    }

    const Scene& scene_;
    TileAccumulator& sums_;
    RayBatch batch_;
    const HeroWavelengths* wavelengths_[kPacketSize];  // each ray's sample's, the batcher's
    float scale_[kPacketSize];
    unsigned lanes_[kPacketSize];  // bit m: the ray carries lane m
    bool last_[kPacketSize];
    size_t slot_[kPacketSize];
    Vec3f pending_;  // the current camera sample's value so far
    FinishedSamples finished_;  // flush's finished samples
    CameraRayRows rounded_[kHeroWavelengths];  // add_batch's rays in float, per traced wavelength
    uint64_t samples_shaded_ = 0;
};

// Cameras whose rays can each carry a band of wavelengths, integrated
// exactly (render_tile_bands.h: the dispersive thin and thick lens), say so
// with carries_bands(), band_rays, band_ray_rows and band_runs.
template <class Camera, class = void>
struct HasBandRays : std::false_type {};
template <class Camera>
struct HasBandRays<Camera, std::void_t<decltype(std::declval<const Camera&>().carries_bands())>> : std::true_type {};

// How a render's camera samples become rays (see the top of this file).
enum class SpectralPath {
    Integrated,        // the camera does not disperse: no wavelengths drawn, their integral exact (render.h)
    IntegratedBands,   // it disperses, each ray carrying a band of wavelengths, integrated (render_tile_bands.h)
    OneRay,            // the camera does not disperse but wavelengths are drawn: one ray carries all four
    RidingOnHero,      // generate_rays_sharing: secondaries ride on the hero's ray where it is theirs
    RayPerWavelength   // a ray per traced wavelength
};

// (A moving camera takes the same path as a still one: a translation moves
// every wavelength's ray alike, so the band rays shift with the sample's time.)
template <class Camera>
SpectralPath spectral_path(const Camera& camera, const SpectralTables& spectra) {
    if (!camera_disperses(camera)) return spectra.integrate_still ? SpectralPath::Integrated : SpectralPath::OneRay;
    if constexpr (HasBandRays<Camera>::value)
        if (spectra.integrate_still && camera.carries_bands()) return SpectralPath::IntegratedBands;
    if constexpr (HasSharedWavelengthRays<Camera>::value)
        if (spectra.traced_wavelengths == kHeroWavelengths) return SpectralPath::RidingOnHero;
    return SpectralPath::RayPerWavelength;
}

// Samples waiting for the camera. A camera that does not disperse turns a
// batch of them into rays at once, each ray carrying all four wavelengths; a
// dispersive one is asked for a ray per traced wavelength, the whole batch at
// once too (the lens system traces its lanes in lockstep, each lane through
// the glass at its own wavelength), or, when it can, for the hero's ray and
// the secondaries that are not on it.
template <class Camera>
class SpectralCameraSampleBatcher {
  public:
    SpectralCameraSampleBatcher(const Camera& camera, const SceneMotion& motion, const SpectralTables& spectra,
                                SpectralRayPacket& packet, SpectralPath path)
        : camera_(camera), motion_(motion), moves_camera_(motion.moves_camera()), spectra_(spectra),
          packet_(packet), path_(path) {}

    // Queues samples [first, end) of pixel (x, y) (at slot), in runs that
    // fill the batch, as CameraSampleBatcher::add_pixel; each sample draws
    // its four wavelengths here.
    void add_pixel(int x, int y, const PixelSamples& samples, int first, int end, size_t slot) {
        for (int i = first; i < end;) {
            if (pending_ == 0) packet_.release(wavelengths_, wavelengths_ + kCameraBatch);
            const int n = std::min(end - i, kCameraBatch - pending_);
            const float* u = samples.wavelength.data() + i;
            for (int j = 0; j < n; ++j) prefetch_hero_wavelengths(spectra_, u[j]);
            staged_.take(pending_, x, y, samples, i, n, slot);
            for (int j = 0; j < n; ++j) sample_hero_wavelengths(spectra_, u[j], &wavelengths_[pending_ + j]);
            pending_ += n, i += n;
            if (pending_ == kCameraBatch) flush();
        }
    }

    // As CameraSampleBatcher's: from now on each batch's rays, at every
    // traced wavelength, are checked against check (the packet culled by its
    // pencil); the first that is not within makes the packet test every
    // primitive again.
    void check_by(const LensPencilCheck& check) { check_.start(check); }

    void flush() {
        if (pending_ == 0) return;
        switch (path_) {
            case SpectralPath::Integrated:  // render.h renders these without drawing wavelengths
            case SpectralPath::IntegratedBands:  // and these by render_tile_bands.h
            case SpectralPath::OneRay: flush_shared(); break;
            case SpectralPath::RidingOnHero: flush_riding(); break;
            case SpectralPath::RayPerWavelength: flush_dispersed(); break;
        }
        pending_ = 0;
        // The packet may hold rays of this batch still: the next one fills the other buffer.
        std::swap(wavelengths_, other_wavelengths_);
    }

  private:
    // One ray per sample, carrying all four wavelengths.
    void flush_shared() {
        if constexpr (GeneratesRayRows<Camera>::value) {  // in float straight to the packet
            camera_.generate_ray_rows(staged_.raster_px, staged_.lens, pending_, &rows_);
            if (moves_camera_) move_origins(motion_, pending_, staged_.time, &rows_);
            packet_.add_rows(rows_, pending_, wavelengths_, staged_.time, staged_.slot);
            return;
        } else if constexpr (GeneratesRayBatches<Camera>::value) {  // in columns
            camera_.generate_ray_batch(staged_.raster_px, staged_.lens, pending_, &columns_[0]);
            if (moves_camera_) move_origins(motion_, pending_, staged_.time, &columns_[0]);
            packet_.add_batch(columns_, 1, 1, true, pending_, wavelengths_, staged_.time, staged_.slot);
            return;
        }
        MaybeRay* rays = shared_rays_;
        camera_rays(camera_, staged_.raster_px, staged_.lens, pending_, rays);
        for (int i = 0; i < pending_; ++i) {
            if (!rays[i]) continue;  // vignetted: contributes nothing
            moved(&*rays[i], staged_.time[i]);
            packet_.add(*rays[i], staged_.time[i], &wavelengths_[i], rays[i]->weight / float(kHeroWavelengths), 0xfu,
                        true, staged_.slot[i]);
        }
    }

    // The hero's ray carrying every wavelength whose ray it is, then a ray for
    // each other wavelength carrying that one alone.
    void flush_riding() {
        if constexpr (HasSharedWavelengthRows<Camera>::value) {  // in float straight to the packet
            camera_.generate_shared_ray_rows(staged_.raster_px, staged_.lens, wavelengths_, pending_, shared_rows_,
                                             shared_own_);
            if (moves_camera_)
                for (CameraRayRows& rows : shared_rows_) move_origins(motion_, pending_, staged_.time, &rows);
            packet_.add_shared_rows(shared_rows_, shared_own_, pending_, wavelengths_, staged_.time, staged_.slot);
            return;
        }
        if constexpr (HasSharedWavelengthRays<Camera>::value) {
            for (int i = 0; i < pending_; ++i) {
                const HeroWavelengths& w = wavelengths_[i];
                MaybeRay rays[kHeroWavelengths];
                bool shares[kHeroWavelengths];
                camera_.generate_rays_sharing(staged_.raster_px[i], staged_.lens[i], w.nm, rays, shares);
                int last = -1;
                for (int k = 0; k < kHeroWavelengths; ++k)
                    if (rays[k] && (k == 0 || !shares[k])) last = k;
                for (int k = 0; k <= last; ++k) {
                    if (!rays[k] || (k > 0 && shares[k])) continue;
                    moved(&*rays[k], staged_.time[i]);
                    // Lane m holds wavelength (m - hero_lane) % 4.
                    unsigned lanes = 0;
                    for (int m = 0; m < kHeroWavelengths; ++m) {
                        const int j = (m - w.hero_lane) & (kHeroWavelengths - 1);
                        if (j == k || (k == 0 && shares[j])) lanes |= 1u << m;
                    }
                    packet_.add(*rays[k], staged_.time[i], &w, rays[k]->weight / float(kHeroWavelengths), lanes,
                                k == last, staged_.slot[i]);
                }
            }
        }
    }

    // A ray per traced wavelength (every stride-th of the four, hero first),
    // a sample's rays in wavelength order.
    void flush_dispersed() {
        const int traced = spectra_.traced_wavelengths, stride = kHeroWavelengths / traced;
        float nm[kCameraBatch][kHeroWavelengths];
        for (int i = 0; i < pending_; ++i)
            for (int k = 0; k < traced; ++k) nm[i][k] = wavelengths_[i].nm[k * stride];
        if constexpr (HasWavelengthRayRows<Camera>::value) {  // in float straight to the packet
            check_.passed(camera_.generate_weighted_ray_rows_at(staged_.raster_px, staged_.lens, nm, pending_, traced,
                                                                dispersed_rows_, dispersed_weight_, dispersed_alive_,
                                                                check_.active()),
                          packet_);
            if (moves_camera_)
                for (int k = 0; k < traced; ++k) move_origins(motion_, pending_, staged_.time, &dispersed_rows_[k]);
            const float* weight[kHeroWavelengths];
            const bool* alive[kHeroWavelengths];
            for (int k = 0; k < traced; ++k) weight[k] = dispersed_weight_[k], alive[k] = dispersed_alive_[k];
            packet_.add_rows(dispersed_rows_, weight, alive, traced, stride, false, pending_, wavelengths_,
                             staged_.time, staged_.slot);
            return;
        }
        // (Only the rows above are checked: a camera with a checked pencil
        // makes them.)
        MaybeRay (*rays)[kHeroWavelengths] = dispersed_rays_;
        wavelength_rays(camera_, staged_.raster_px, staged_.lens, nm, pending_, traced, rays);
        for (int i = 0; i < pending_; ++i) {
            int last = -1;
            for (int k = 0; k < traced; ++k)
                if (rays[i][k]) last = k;
            for (int k = 0; k <= last; ++k) {
                if (!rays[i][k]) continue;
                moved(&*rays[i][k], staged_.time[i]);
                packet_.add(*rays[i][k], staged_.time[i], &wavelengths_[i], rays[i][k]->weight / float(traced),
                            1u << wavelengths_[i].lane(k * stride), k == last, staged_.slot[i]);
            }
        }
    }

    void moved(CameraRay* ray, float time_u) const {
        if (moves_camera_) ray->origin += motion_.camera_offset_m(time_u);
    }

    // Members, not locals of the flushes: a local array of these was zeroed
    // at every flush (8 KB for the dispersed batch; see RayPacket::radiance_).
    MaybeRay shared_rays_[kCameraBatch];
    MaybeRay dispersed_rays_[kCameraBatch][kHeroWavelengths];
    CameraRayBatch columns_[kHeroWavelengths];  // a batch's rays at each traced wavelength
    CameraRayRows dispersed_rows_[kHeroWavelengths];  // the same in float (HasWavelengthRayRows)
    float dispersed_weight_[kHeroWavelengths][kCameraBatch];
    bool dispersed_alive_[kHeroWavelengths][kCameraBatch];
    CameraRayRows rows_;  // flush_shared's rays, for cameras that find them in float
    CameraRayRows shared_rows_[kHeroWavelengths];  // flush_riding's, per wavelength (HasSharedWavelengthRows)
    bool shared_own_[kHeroWavelengths][kCameraBatch];
    const Camera& camera_;
    const SceneMotion& motion_;
    bool moves_camera_;
    const SpectralTables& spectra_;
    SpectralRayPacket& packet_;
    SpectralPath path_;
    SampleColumns staged_;
    // Two buffers of the batch's wavelengths, swapped after each flush
    // (the packet reads a ray's until it is shaded: SpectralRayPacket::release).
    HeroWavelengths wavelength_buffers_[2][kCameraBatch];
    HeroWavelengths* wavelengths_ = wavelength_buffers_[0];
    HeroWavelengths* other_wavelengths_ = wavelength_buffers_[1];
    TileCheck check_;
    int pending_ = 0;
};

// render_tile (render.h) for a spectral render. The pixel loop is written out
// again on purpose: one walker shared through a callback made the RGB thin
// lens 4-7 % slower (session 6, same-run A/B).
template <class Camera>
RenderStats render_tile_spectral(const Scene& scene, const Camera& camera, const RenderSettings& s,
                                 const Tile& tile, float* rgb) {
    const SpectralTables& spectra = *scene.spectral();
    const SpectralPath path = spectral_path(camera, spectra);
    TileAccumulator sums(tile, s.variance_of_mean != nullptr);
    SpectralRayPacket packet(scene, sums);
    SpectralCameraSampleBatcher<Camera> batcher(camera, scene.motion(), spectra, packet, path);
    // A derived pencil holds every path's rays (a dispersive thin or thick
    // lens's spans its planes of focus: ThinLensCamera::pencil); a measured
    // one holds dispersed rays as long as each traced batch passes its check.
    cull_tile(camera, scene.motion(), tile, &packet, &batcher, true, path == SpectralPath::RayPerWavelength);
    PixelSamples samples(s.spp, scene.motion().samples_time(), true, UsesLensSamples<Camera>::value);
    RenderStats stats;
    for (int y = tile.rows().begin(); y < tile.rows().end(); ++y) {
        for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            const uint64_t pixel_index = uint64_t(y) * uint64_t(s.width_px) + uint64_t(x);
            const auto [first, end] = s.samples_of(pixel_index);
            if (end == first) continue;
            samples.fill(s, pixel_index, end);
            stats.samples += uint64_t(end - first);
            batcher.add_pixel(x, y, samples, first, end, sums.slot(x, y));
        }
    }
    batcher.flush();
    packet.flush();
    sums.finish(s, rgb);
    stats.rays_passed = packet.samples_shaded();
    return stats;
}

}  // namespace lc
