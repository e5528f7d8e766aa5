// The render loop's stages for a spectral render through a dispersive thin or
// thick lens (since session 29): no wavelength is drawn. Each camera sample
// becomes one ray carrying the whole spectrum, or, where its wavelengths'
// film points straddle a pixel's edge, a ray per stretch of the spectrum
// that lands in one pixel (cameras/thin_lens_bands.h), and each ray's
// reading is the film's integral over its wavelengths, exact (spectral_bands.h,
// Scene::spectral_band_radiance). Every wavelength is still sampled exactly
// as its own camera would (its film point uniform over the pixel given the
// lens point), so the sample's value, the sum over its rays, is unbiased; and
// where its rays see the same colours it has no colour noise at all, as the
// render through a camera that does not disperse (SpectralPath::Integrated).
// SpectralTables::integrate_still = false (render(sample_wavelengths=True))
// draws hero wavelengths instead (render_tile_spectral.h, RidingOnHero).
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>

#include "cameras/thin_lens_bands.h"
#include "render_tile.h"
#include "render_tile_spectral.h"
#include "spectral_bands.h"

namespace lc {

// Rays waiting for the scene. A whole sample's ray, carrying the whole
// spectrum, goes to a packet of its own, shaded as through a camera that
// does not disperse (RayPacket, integrate_wavelengths), with no band to
// look up or carry. A split sample's rays go here each with its band; they
// arrive together and in order, the sample's value (their sum) going to the
// pixel after its last, so that an adaptive render's variance is the
// samples'.
class BandRayPacket {
  public:
    BandRayPacket(const Scene& scene, TileAccumulator& sums, const FocusBandIntegrals& integrals,
                  const DispersionRuns& runs)
        : scene_(scene), sums_(sums), whole_(scene, sums, true), bands_{&integrals, &runs, k_lo_, k_hi_, whole_part_} {}

    void cull_by(const CameraPencil& pencil) {
        scene_.camera_candidates(pencil, &batch_);
        whole_.cull_by(pencil);
    }
    void uncull() { batch_.uncull(), whole_.uncull(); }

    // Queues whole samples' rays [0, n) of rows, ray i for the pixel at
    // slot[i] (those alive, with their weights, where weights are used).
    void add_whole(const CameraRayRows& rows, int n, const float* time_u, const size_t* slot,
                   const BandRayWeights& weights) {
        if (weights.used) whole_.add_rows(rows, n, time_u, slot, weights.alive, weights.weight);
        else whole_.add_rows(rows, n, time_u, slot);
    }
    // Queues rows[at[r]], r in [0, n), as whole samples' rays, each with
    // the time, pixel, aliveness and weight of its index.
    void add_whole_at(const CameraRayRows& rows, const int* at, int n, const float* time_u, const size_t* slot,
                      const bool* alive, const float* weight) {
        whole_.add_rows_at(rows, at, n, time_u, slot, alive, weight);
    }

    // Queues row i of rows carrying the wavelengths of planes of focus
    // [k_lo, k_hi) (the lens system: of its dispersion parameter) plus
    // whole_part times the whole spectrum (BandRoulette), its radiance
    // scaled by weight; last: its sample's last ray.
    void add(const CameraRayRows& rows, int i, double k_lo, double k_hi, float whole_part, float weight,
             float time_u, bool last, size_t slot) {
        const int j = batch_.count;
        whole_part_[j] = whole_part;
        batch_.set(j, rows, i);
        batch_.time[j] = time_u;
        weight_[j] = weight;
        k_lo_[j] = k_lo, k_hi_[j] = k_hi;
        last_[j] = last;
        slot_[j] = slot;
        if (++batch_.count == kPacketSize) flush_bands();
    }

    void flush() {
        whole_.flush();
        flush_bands();
    }

    uint64_t samples_shaded() const { return samples_shaded_ + whole_.rays_shaded(); }
    const FocusBandIntegrals& integrals() const { return *bands_.integrals; }

  private:
    void flush_bands() {
        if (batch_.count == 0) return;
        scene_.spectral_band_radiance(batch_, &bands_, radiance_);
        Vec3f pending = pending_;
        for (int j = 0; j < batch_.count; ++j) {
            pending += radiance_[j] * weight_[j];
            if (last_[j]) {
                finished_.add(slot_[j], pending);
                pending = Vec3f{};
            }
        }
        samples_shaded_ += uint64_t(finished_.add_to(sums_));
        pending_ = pending;
        batch_.count = 0;
    }

    const Scene& scene_;
    TileAccumulator& sums_;
    RayPacket whole_;
    RayBatch batch_;
    double k_lo_[kPacketSize], k_hi_[kPacketSize];
    float weight_[kPacketSize];
    float whole_part_[kPacketSize];
    RayFocusBands bands_;  // batch_'s bands: k_lo_ and k_hi_
    bool last_[kPacketSize];
    size_t slot_[kPacketSize];
    Vec3f radiance_[kPacketSize];
    Vec3f pending_;  // the current camera sample's value so far
    FinishedSamples finished_;  // flush_bands' finished samples
    uint64_t samples_shaded_ = 0;
};

// Cameras whose split rays are traced (the lens system) say so with
// kPoolsSplitRays: the batcher then keeps the split samples of many batches
// and has them traced together (trace_split_rays), a few rays a batch
// costing a whole batch's trace otherwise.
template <class Camera, class = void>
struct PoolsSplitRays : std::false_type {};
template <class Camera>
struct PoolsSplitRays<Camera, std::void_t<decltype(Camera::kPoolsSplitRays)>>
    : std::bool_constant<Camera::kPoolsSplitRays> {};

// Cameras whose whole samples' rays are their samples' own rays as band_rays
// traced them (the lens system: BandRays::sample_rows) say so with
// kWholeRaysInSampleRows: the batcher then queues those rows where they are
// (a gather of every whole sample's row was 2 % of a band render, perf,
// session 49).
template <class Camera, class = void>
struct WholeRaysInSampleRows : std::false_type {};
template <class Camera>
struct WholeRaysInSampleRows<Camera, std::void_t<decltype(Camera::kWholeRaysInSampleRows)>>
    : std::bool_constant<Camera::kWholeRaysInSampleRows> {};

// Samples waiting for the camera, a batch at a time: the camera splits them
// into their rays (band_rays), and the rays go to the packet in float, the
// whole samples' at once (whole_ray_rows), the split samples' a camera
// batch's worth at a time (band_ray_rows). A moving camera's rays
// start where the camera is at their sample's time: a translation of the
// whole camera moves every wavelength's ray alike, so the bands are a still
// camera's.
template <class Camera>
class BandCameraSampleBatcher {
  public:
    BandCameraSampleBatcher(const Camera& camera, const SceneMotion& motion, BandRayPacket& packet)
        : camera_(camera), motion_(motion), moves_camera_(motion.moves_camera()), packet_(packet),
          roulette_{&packet.integrals()} {
        if (camera.band_roulette()) rays_.roulette = &roulette_;
    }

    void add_pixel(int x, int y, const PixelSamples& samples, int first, int end, size_t slot) {
        for (int i = first; i < end;) {
            const int n = std::min(end - i, kCameraBatch - pending_);
            staged_.take(pending_, x, y, samples, i, n, slot);
            pending_ += n, i += n;
            if (pending_ == kCameraBatch) flush();
        }
    }

    // As CameraSampleBatcher's (the lens system's measured pencil): every
    // ray of a batch, whole or split, is checked.
    void check_by(const LensPencilCheck& check) { check_.start(check); }

    void flush() {
        if (pending_ == 0) return;
        // Pooled: the split rays of earlier batches stay (emit_split_rays).
        const int first_entry = kPooled ? rays_.count : 0;
        if (kPooled) rays_.whole_count = 0;
        else rays_.clear();
        check_.passed(camera_.band_rays(staged_.raster_px, staged_.lens, pending_, &rays_, check_.active()), packet_);
        if (const int whole = rays_.whole_count; whole > 0 && kWholeInSampleRows && !moves_camera_) {
            packet_.add_whole_at(rays_.sample_rows, rays_.whole_sample, whole, staged_.time, staged_.slot,
                                 rays_.sample_alive, rays_.sample_weight);
        } else if (whole > 0) {
            camera_.whole_ray_rows(rays_, &rows_, &weights_);
            float time_u[kCameraBatch];
            size_t slot[kCameraBatch];
            for (int r = 0; r < whole; ++r) {
                const int sample = rays_.whole_sample[r];
                time_u[r] = staged_.time[sample], slot[r] = staged_.slot[sample];
            }
            if (moves_camera_) move_origins(motion_, whole, time_u, &rows_);
            packet_.add_whole(rows_, whole, time_u, slot, weights_);
        }
        if constexpr (kPooled) {
            // Each new split ray's time and pixel, its sample numbered within the pool.
            const size_t count = size_t(rays_.count);
            split_time_.resize(count), split_slot_.resize(count);
            for (size_t at = size_t(first_entry); at < count; ++at) {
                const int sample = rays_.sample[at];
                split_time_[at] = staged_.time[sample], split_slot_[at] = staged_.slot[sample];
                rays_.sample[at] += pooled_samples_;
            }
            pooled_samples_ += pending_;
            pending_ = 0;
            if (rays_.count >= kPoolRays) emit_split_rays();
            return;
        }
        emit_split_rays();
        pending_ = 0;
    }

    // The last batch, and the pool.
    void finish() {
        flush();
        if constexpr (kPooled) emit_split_rays();
    }

  private:
    static constexpr bool kPooled = PoolsSplitRays<Camera>::value;
    static constexpr bool kWholeInSampleRows = WholeRaysInSampleRows<Camera>::value;
    // A pool's rays: about half of them traced, four batches' worth.
    static constexpr int kPoolRays = 8 * kCameraBatch;

    // The split samples' rays in rays_, in order, to the packet.
    void emit_split_rays() {
        if constexpr (kPooled) check_.passed(camera_.trace_split_rays(&rays_, check_.active()), packet_);
        const int count = rays_.size();
        auto time_of = [&](size_t ray) { return kPooled ? split_time_[ray] : staged_.time[rays_.sample[ray]]; };
        auto slot_of = [&](size_t ray) { return kPooled ? split_slot_[ray] : staged_.slot[rays_.sample[ray]]; };
        for (int first = 0; first < count; first += kCameraBatch) {
            const int n = std::min(kCameraBatch, count - first);
            camera_.band_ray_rows(rays_, first, n, &rows_, &weights_);
            if (moves_camera_) {
                float time_u[kCameraBatch];
                for (int r = 0; r < n; ++r) time_u[r] = time_of(size_t(first + r));
                move_origins(motion_, n, time_u, &rows_);
            }
            for (int r = 0; r < n; ++r) {
                const size_t ray = size_t(first + r);
                const int sample = rays_.sample[ray];
                const bool last = int(ray) + 1 == count || rays_.sample[ray + 1] != sample;
                // A vignetted ray (finite, weight 0) still goes: it may close its sample.
                const float weight = !weights_.used ? 1.0f : weights_.alive[r] ? weights_.weight[r] : 0.0f;
                packet_.add(rows_, r, rays_.k_lo[ray], rays_.k_hi[ray], rays_.entry_whole_part[ray],
                            weight * rays_.entry_scale[ray], time_of(ray), last, slot_of(ray));
            }
        }
        if constexpr (kPooled) rays_.clear(), pooled_samples_ = 0;
    }

    const Camera& camera_;
    const SceneMotion& motion_;
    bool moves_camera_;
    BandRayPacket& packet_;
    SampleColumns staged_;
    BandRays rays_;
    CameraRayRows rows_;
    BandRayWeights weights_;
    TileCheck check_;
    int pending_ = 0;
    std::vector<float> split_time_;  // pooled: each split ray's sample's time and pixel
    std::vector<size_t> split_slot_;
    int pooled_samples_ = 0;
    BandRoulette roulette_;
};

template <class Camera>
RenderStats render_band_rays(const Scene& scene, const Camera& camera, const RenderSettings& s, const Tile& tile,
                             const FocusBandIntegrals& integrals, float* rgb);

// render_tile (render.h) for a spectral render whose rays carry bands
// (spectral_path's IntegratedBands, which only cameras with HasBandRays take),
// read from integrals (Scene::focus_band_integrals of the camera's table,
// made once per render). Its pixel loop is written out again, as
// render_tile_spectral's is (why: there).
template <class Camera>
RenderStats render_tile_bands(const Scene& scene, const Camera& camera, const RenderSettings& s, const Tile& tile,
                              const std::optional<FocusBandIntegrals>& integrals, float* rgb) {
    if constexpr (!HasBandRays<Camera>::value) {
        return RenderStats{};
    } else {
        return render_band_rays(scene, camera, s, tile, *integrals, rgb);
    }
}

template <class Camera>
RenderStats render_band_rays(const Scene& scene, const Camera& camera, const RenderSettings& s, const Tile& tile,
                             const FocusBandIntegrals& integrals, float* rgb) {
    TileAccumulator sums(tile, s.variance_of_mean != nullptr);
    BandRayPacket packet(scene, sums, integrals, camera.band_runs());
    BandCameraSampleBatcher<Camera> batcher(camera, scene.motion(), packet);
    // The derived pencil spans the planes of focus (ThinLensCamera::pencil):
    // every band's ray is some wavelength's own ray from a film point in its
    // pixel (a moving camera: swept along its path, cull_tile). The lens
    // system's is measured at the d line, each batch checked (the split
    // rays start up to a pixel outside the tile).
    cull_tile(camera, scene.motion(), tile, &packet, &batcher);
    PixelSamples samples(s.spp, scene.motion().samples_time(), false, true);
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
    batcher.finish();
    packet.flush();
    sums.finish(s, rgb);
    stats.rays_passed = packet.samples_shaded();
    return stats;
}

}  // namespace lc
