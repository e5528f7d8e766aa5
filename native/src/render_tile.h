// The stages one tile of the render loop passes its samples through, in order:
// PixelSamples (the sampler fills a pixel's set), CameraSampleBatcher (the
// camera turns samples into rays), RayPacket (Embree shades the rays) and
// TileAccumulator (each pixel's sum, then its mean and variance).
// Camera samples are gathered across the tile's pixels into batches of
// kCameraBatch, and the rays packed into 8-wide Embree packets, so that low
// sample counts still fill both. Each pixel's samples are still summed in
// sample order.
#pragma once

#include <tbb/blocked_range2d.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>
#include <vector>

#include "cameras/camera_ray.h"
#include "cameras/lens_pencil.h"
#include "motion.h"
#include "packet_append.h"
#include "render_settings.h"
#include "samplers.h"
#include "scene.h"
#include "tile_sums.h"

namespace lc {

using Tile = tbb::blocked_range2d<int>;  // rows x columns of pixels

// One pixel's film, lens and (for a moving scene) time samples, and (for a
// spectral render) wavelength samples: a sampler fills a pixel's whole set at once.
struct PixelSamples {
    std::vector<Point2f> film, lens;
    std::vector<float> time;        // empty unless times are drawn; then in [0, 1) over the shutter
    std::vector<float> wavelength;  // empty unless wavelengths are drawn; then in [0, 1) (spectral.h)
    // false: the camera ignores lens samples; the samplers whose lens points
    // are a stream of their own then draw none (lens stays at 0; see fill_pixel_samples).
    bool with_lens = true;

    PixelSamples(int spp, bool with_time, bool with_wavelength = false, bool with_lens_samples = true)
        : film(size_t(spp)), lens(size_t(spp)), time(with_time ? size_t(spp) : 0),
          wavelength(with_wavelength ? size_t(spp) : 0), with_lens(with_lens_samples) {}

    // Samples [0, end) of the pixel; the buffers grow when an adaptive pass asks for more.
    void fill(const RenderSettings& s, uint64_t pixel_index, int end) {
        const bool with_time = !time.empty(), with_wavelength = !wavelength.empty();
        if (film.size() < size_t(end)) {
            film.resize(size_t(end)), lens.resize(size_t(end));
            if (with_time) time.resize(size_t(end));
            if (with_wavelength) wavelength.resize(size_t(end));
        }
        // sobol: time i / end (film and time one net) when the pixel's samples
        // are drawn whole; dimension 6 when an adaptive pass continues them,
        // since i / end over [first, end) would cover only the shutter's end.
        // Both are unbiased: each time is uniform on [0, 1) by itself (Owen
        // scrambling); dimension 6's points [first, end) are moreover whole
        // Sobol' blocks, stratified over the shutter, when first and end are
        // powers of two.
        fill_pixel_samples(pass_sampler(s.sampler, s.first_sample), s.seed, pixel_index, end, film.data(),
                           with_lens ? lens.data() : nullptr,
                           with_time ? time.data() : nullptr, with_wavelength ? wavelength.data() : nullptr);
    }
};

// Cameras whose rays ignore the lens sample (the pinhole) say so with
// kUsesLensSamples = false: their pixels then draw none.
template <class Camera, class = void>
struct UsesLensSamples : std::true_type {};
template <class Camera>
struct UsesLensSamples<Camera, std::void_t<decltype(Camera::kUsesLensSamples)>>
    : std::bool_constant<Camera::kUsesLensSamples> {};

// Cameras whose rays through a film rectangle form a pencil (camera_pencil.h)
// say so with pencil(x0, y0, x1, y1, out): a tile's camera rays then skip the
// own primitives the pencil cannot reach.
template <class Camera, class = void>
struct HasPencil : std::false_type {};
template <class Camera>
struct HasPencil<Camera, std::void_t<decltype(std::declval<const Camera&>().pencil(
                             0.0, 0.0, 0.0, 0.0, static_cast<CameraPencil*>(nullptr)))>> : std::true_type {};

// Cameras whose pencil is measured rather than derived (the lens system:
// lens_pencil.h) say so with checked_pencil(x0, y0, x1, y1, pencil, check):
// their tiles cull as HasPencil's do while every traced batch passes check.
template <class Camera, class = void>
struct HasCheckedPencil : std::false_type {};
template <class Camera>
struct HasCheckedPencil<Camera, std::void_t<decltype(std::declval<const Camera&>().checked_pencil(
                                    0.0, 0.0, 0.0, 0.0, static_cast<CameraPencil*>(nullptr),
                                    static_cast<LensPencilCheck*>(nullptr)))>> : std::true_type {};

// A tile's measured-pencil check as a batcher holds it (check_by): each
// traced batch is checked while it lasts; the first batch outside the pencil
// makes the packet test every primitive again, and the checking stops.
class TileCheck {
  public:
    void start(const LensPencilCheck& check) { check_ = check, checking_ = true; }
    // The check for the next traced batch; null once it has been left.
    const LensPencilCheck* active() const { return checking_ ? &check_ : nullptr; }
    // within: whether the batch just traced lay within the pencil.
    template <class Packet>
    void passed(bool within, Packet& packet) {
        if (!within) packet.uncull(), checking_ = false;
    }

  private:
    LensPencilCheck check_{};
    bool checking_ = false;
};

// Per-pixel sums of one tile, in double: 1024 spp of float radiance would lose bits.
class TileAccumulator {
  public:
    TileAccumulator(const Tile& tile, bool with_squares)
        : tile_(tile),
          width_(size_t(tile.cols().size())),
          sums_(width_ * size_t(tile.rows().size()) * 3, 0.0),
          squares_(with_squares ? sums_.size() : 0, 0.0) {}

    // Where pixel (x, y) of the tile keeps its sums.
    size_t slot(int x, int y) const {
        return size_t(y - tile_.rows().begin()) * width_ + size_t(x - tile_.cols().begin());
    }

    // One sample's weighted radiance into its pixel's sums (and squares).
    void add(size_t slot, const Vec3f& radiance, float weight) { add(1, &slot, &radiance, &weight); }

    // Samples [0, n) of a packet, each weighted radiance into its pixel's sums
    // (and squares, for the variance), in order (tile_sums.h).
    void add(int n, const size_t* slot, const Vec3f* radiance, const float* weight) {
        add_tile_samples(n, slot, radiance, weight, sums_.data(), squares_.empty() ? nullptr : squares_.data());
    }

    // Each pixel's mean into rgb, and the variance of that mean when asked for.
    void finish(const RenderSettings& s, float* rgb) const {
        for (int y = tile_.rows().begin(); y < tile_.rows().end(); ++y)
            for (int x = tile_.cols().begin(); x < tile_.cols().end(); ++x) {
                const size_t local = slot(x, y);
                const uint64_t pixel_index = uint64_t(y) * uint64_t(s.width_px) + uint64_t(x);
                const auto [first, end] = s.samples_of(pixel_index);
                const int count = end - first;
                float* out = rgb + 3 * pixel_index;
                double variance = 0.0;
                for (int c = 0; c < 3; ++c) {
                    const double mean = count > 0 ? sums_[3 * local + size_t(c)] / count : 0.0;
                    out[c] = float(mean);
                    if (!squares_.empty() && count > 1)
                        variance += std::max(squares_[3 * local + size_t(c)] / count - mean * mean, 0.0) /
                                    (count - 1);
                }
                if (s.variance_of_mean) s.variance_of_mean[pixel_index] = float(variance);
            }
    }

  private:
    Tile tile_;
    size_t width_;
    std::vector<double> sums_, squares_;
};

// The camera samples a spectral packet finishes while it shades (each
// sample's value summed over its rays, weight 1), added to the tile's sums in
// one call once the packet is done: the same additions in the same order as
// one call per sample, so the same bits, without a call per sample.
class FinishedSamples {
  public:
    void add(size_t slot, const Vec3f& value) { slot_[count_] = slot, value_[count_] = value, ++count_; }

    // Into sums, in the order added; how many there were.
    int add_to(TileAccumulator& sums) {
        static constexpr std::array<float, kPacketSize> kUnitWeights = [] {
            std::array<float, kPacketSize> w{};
            for (float& x : w) x = 1.0f;
            return w;
        }();
        const int n = count_;
        sums.add(n, slot_, value_, kUnitWeights.data());
        count_ = 0;
        return n;
    }

  private:
    // At most one sample finishes per ray of a packet. Members, not locals:
    // a local array of Vec3f would be zeroed at every packet.
    size_t slot_[kPacketSize];
    Vec3f value_[kPacketSize];
    int count_ = 0;
};

// Whether the n = kPacketSize flags are all set.
inline bool all_alive(const bool* alive) {
    bool all = true;
    for (int i = 0; i < kPacketSize; ++i) all &= alive[i];
    return all;
}

// A camera batch's rays rounded to float row by row (whole vectors), as
// the packets take them.
inline void round_rows(const CameraRayBatch& rays, int n, CameraRayRows* rows) {
    for (int a = 0; a < 3; ++a)
        for (int i = 0; i < n; ++i)
            rows->origin[a][i] = float(rays.origin[a][i]), rows->direction[a][i] = float(rays.direction[a][i]);
}

// Rays waiting for the scene: Embree traces a full 8-wide packet faster than
// its rays one at a time, camera rays and shadow rays alike.
class RayPacket {
  public:
    // integrate_wavelengths: a spectral render through a camera that does not
    // disperse, shaded by Scene::spectral_integrated_radiance.
    RayPacket(const Scene& scene, TileAccumulator& sums, bool integrate_wavelengths = false)
        : scene_(scene), sums_(sums), integrate_wavelengths_(integrate_wavelengths) {}

    // From now on the rays only test the own primitives some ray of pencil may meet.
    void cull_by(const CameraPencil& pencil) { scene_.camera_candidates(pencil, &batch_); }
    // From now on the rays test every own primitive again (a ray left the pencil).
    void uncull() { batch_.uncull(); }
    // The packets' stream (RayBatch::stream), [0, RayBatch::kStreams).
    void set_stream(int stream) { batch_.stream = stream; }

    // Queues a ray for the pixel at slot, seen at shutter time u; a full packet is shaded at once.
    void add(const CameraRay& ray, float time_u, size_t slot) {
        batch_.set(batch_.count, ray);
        batch_.time[batch_.count] = time_u;
        weight_[batch_.count] = ray.weight;
        slot_[batch_.count++] = slot;
        if (batch_.count == kPacketSize) flush();
    }

    // Queues rays [0, n) of a camera batch (those alive), ray i at shutter
    // time time_u[i] for the pixel at slot[i]: as add, without a CameraRay between.
    void add_batch(const CameraRayBatch& rays, int n, const float* time_u, const size_t* slot) {
        round_rows(rays, n, &rounded_);
        add_rows(rounded_, n, time_u, slot, rays.alive, rays.weight);
    }

    // As add_batch for rays found in float (GeneratesRayRows), every one
    // alive with weight 1 (alive and weight nullptr), or as alive and weight say.
    void add_rows(const CameraRayRows& rows, int n, const float* time_u, const size_t* slot,
                  const bool* alive = nullptr, const float* weight = nullptr) {
        // A run of a packet's worth of live rays into an empty packet goes
        // as row copies (every run, for cameras that vignette nothing),
        // others one by one.
        for (int i = 0; i < n;) {
            if (batch_.count == 0 && i + kPacketSize <= n && (!alive || all_alive(alive + i))) {
                // memcpy, not std::copy_n: GCC inlines a fixed-size memcpy but
                // called memmove for copy_n's (under perf, 9 % of an empty scene's render).
                for (int a = 0; a < 3; ++a) {
                    std::memcpy(batch_.origin[a], rows.origin[a] + i, sizeof(batch_.origin[a]));
                    std::memcpy(batch_.direction[a], rows.direction[a] + i, sizeof(batch_.direction[a]));
                }
                std::memcpy(batch_.time, time_u + i, sizeof(batch_.time));
                if (weight) std::memcpy(weight_, weight + i, sizeof(weight_));
                else std::fill_n(weight_, kPacketSize, 1.0f);
                std::memcpy(slot_, slot + i, sizeof(slot_));
                batch_.count = kPacketSize;
                flush();
                i += kPacketSize;
                continue;
            }
            if (append_in_vectors_ && i + kPacketSize <= n) {
                // The run's live rays after the queued ones, a full packet shaded on the way.
                uint32_t live = alive ? live_bits(alive + i) : (uint32_t(1) << kPacketSize) - 1u;
                while (live) {
                    append_live_rows(rows, i, time_u, weight, slot, &live, &batch_, weight_, slot_);
                    if (batch_.count == kPacketSize) flush();
                }
                i += kPacketSize;
                continue;
            }
            queue_row(rows, i, time_u[i], weight ? weight[i] : 1.0f, slot[i], alive ? alive[i] : true);
            ++i;
        }
    }

    // As add_rows for rays rows[at[r]], r in [0, n), each with the time,
    // pixel, aliveness and weight of its index in rows: some rows of a
    // camera batch (a band render's whole samples, render_tile_bands.h)
    // without first gathering them into rows of their own.
    void add_rows_at(const CameraRayRows& rows, const int* at, int n, const float* time_u, const size_t* slot,
                     const bool* alive, const float* weight) {
        for (int r = 0; r < n; ++r) {
            const int i = at[r];
            queue_row(rows, i, time_u[i], weight[i], slot[i], alive[i]);
        }
    }

    // Shades the queued rays and adds each one's radiance to its pixel, in queue order.
    void flush() {
        if (batch_.count == 0) return;
        if (integrate_wavelengths_) scene_.spectral_integrated_radiance(batch_, radiance_);
        else scene_.radiance(batch_, radiance_);
        sums_.add(batch_.count, slot_, radiance_, weight_);
        rays_shaded_ += uint64_t(batch_.count);
        batch_.count = 0;
    }

    uint64_t rays_shaded() const { return rays_shaded_; }

  private:
    // Row i of rows into the queue, written whether alive or not, the count
    // moving only for a live ray (a vignetted one contributes nothing; the
    // next overwrites it): no branch on the vignetting for the predictor to miss.
    __attribute__((always_inline)) void queue_row(const CameraRayRows& rows, int i, float time_u, float weight,
                                                  size_t slot, bool alive) {
        const int j = batch_.count;
        batch_.set(j, rows, i);
        batch_.time[j] = time_u;
        weight_[j] = weight;
        slot_[j] = slot;
        batch_.count += int(alive);
        if (batch_.count == kPacketSize) flush();
    }

    const Scene& scene_;
    TileAccumulator& sums_;
    bool integrate_wavelengths_;
    bool append_in_vectors_ = packet_append_available();
    RayBatch batch_;
    float weight_[kPacketSize];
    size_t slot_[kPacketSize];
    // Members rather than locals of flush: a local array of these was zeroed
    // (rep stos) at every flush, a few per cent of render_tile under perf.
    Vec3f radiance_[kPacketSize];
    CameraRayRows rounded_;  // add_batch's rays in float
    uint64_t rays_shaded_ = 0;
};

// A camera batch's samples, in columns: raster positions, lens points,
// shutter times and the pixels' slots.
struct SampleColumns {
    Point2f raster_px[kCameraBatch], lens[kCameraBatch];
    float time[kCameraBatch];
    size_t slot[kCameraBatch];

    // Samples [first, first + n) of pixel (x, y) (at slot pixel_slot) into columns [at, at + n).
    void take(int at, int x, int y, const PixelSamples& samples, int first, int n, size_t pixel_slot) {
        const float px = float(x), py = float(y);
        const Point2f* film = samples.film.data() + first;
        const Point2f* lens_points = samples.lens.data() + first;
        // Three loops, not one: GCC vectorises the first and copies the lens
        // points whole, where the one loop moved them a point at a time.
        for (int j = 0; j < n; ++j) raster_px[at + j] = {px + film[j].x, py + film[j].y};
        std::memcpy(lens + at, lens_points, sizeof(Point2f) * size_t(n));
        std::fill_n(slot + at, n, pixel_slot);
        if (samples.time.empty()) std::fill_n(time + at, n, 0.0f);
        else std::copy_n(samples.time.data() + first, n, time + at);
    }
};

// A moving camera is the camera at t = 0 translated by v t: every model's ray
// origin moves by the same offset and no direction changes. Rays [0, n) of
// rows, ray i at shutter time time_u[i], from where the camera then is (the
// offset added in double, the origin rounded to float once).
inline void move_origins(const SceneMotion& motion, int n, const float* time_u, CameraRayRows* rows) {
    for (int i = 0; i < n; ++i) {
        const Vec3d offset_m = motion.camera_offset_m(time_u[i]);
        rows->origin[0][i] = float(double(rows->origin[0][i]) + offset_m.x);
        rows->origin[1][i] = float(double(rows->origin[1][i]) + offset_m.y);
        rows->origin[2][i] = float(double(rows->origin[2][i]) + offset_m.z);
    }
}

// The same for rays found in double columns.
inline void move_origins(const SceneMotion& motion, int n, const float* time_u, CameraRayBatch* columns) {
    for (int i = 0; i < n; ++i) {
        const Vec3d offset_m = motion.camera_offset_m(time_u[i]);
        columns->origin[0][i] += offset_m.x, columns->origin[1][i] += offset_m.y, columns->origin[2][i] += offset_m.z;
    }
}

// Samples waiting for the camera: the lens system traces kCameraBatch of them
// in lockstep, and a tile's pixels together fill a batch at any spp. A moving
// camera's offset (move_origins) is applied here, once for all models.
template <class Camera>
class CameraSampleBatcher {
  public:
    CameraSampleBatcher(const Camera& camera, const SceneMotion& motion, RayPacket& packet)
        : camera_(camera), motion_(motion), moves_camera_(motion.moves_camera()), packet_(packet) {}

    // Queues samples [first, end) of pixel (x, y) (at slot; sample i at its
    // raster position, lens point and shutter time), in runs that fill the
    // batch, a full batch going to the camera at once.
    void add_pixel(int x, int y, const PixelSamples& samples, int first, int end, size_t slot) {
        for (int i = first; i < end;) {
            const int n = std::min(end - i, kCameraBatch - pending_);
            staged_.take(pending_, x, y, samples, i, n, slot);
            pending_ += n, i += n;
            if (pending_ == kCameraBatch) flush();
        }
    }

    // From now on each batch's rays are checked against check (the packet
    // culled by its pencil); the first that is not within makes the packet
    // test every primitive again.
    void check_by(const LensPencilCheck& check) { check_.start(check); }

    // Turns the queued samples into rays for the packet, in queue order.
    void flush() {
        if constexpr (GeneratesRayRows<Camera>::value) {
            // In float straight to the packet.
            camera_.generate_ray_rows(staged_.raster_px, staged_.lens, pending_, &rows_);
            if (moves_camera_) move_origins(motion_, pending_, staged_.time, &rows_);
            packet_.add_rows(rows_, pending_, staged_.time, staged_.slot);
        } else if constexpr (GeneratesWeightedRayRows<Camera>::value) {
            check_.passed(camera_.generate_weighted_ray_rows(staged_.raster_px, staged_.lens, pending_, &rows_,
                                                             weight_, alive_, check_.active()),
                          packet_);
            if (moves_camera_) move_origins(motion_, pending_, staged_.time, &rows_);
            packet_.add_rows(rows_, pending_, staged_.time, staged_.slot, alive_, weight_);
        } else if constexpr (GeneratesRayBatches<Camera>::value) {
            // In columns straight to the packet.
            camera_.generate_ray_batch(staged_.raster_px, staged_.lens, pending_, &columns_);
            if (moves_camera_) move_origins(motion_, pending_, staged_.time, &columns_);
            packet_.add_batch(columns_, pending_, staged_.time, staged_.slot);
        } else {
            camera_rays(camera_, staged_.raster_px, staged_.lens, pending_, rays_);
            for (int i = 0; i < pending_; ++i) {
                if (!rays_[i]) continue;  // vignetted: contributes nothing
                if (moves_camera_) rays_[i]->origin += motion_.camera_offset_m(staged_.time[i]);
                packet_.add(*rays_[i], staged_.time[i], staged_.slot[i]);
            }
        }
        pending_ = 0;
    }

  private:
    const Camera& camera_;
    const SceneMotion& motion_;
    bool moves_camera_;
    RayPacket& packet_;
    SampleColumns staged_;
    MaybeRay rays_[kCameraBatch];  // a member, not a local of flush: see RayPacket::radiance_
    CameraRayBatch columns_;
    CameraRayRows rows_;
    float weight_[kCameraBatch];  // generate_weighted_ray_rows' weights and vignetting
    bool alive_[kCameraBatch];
    TileCheck check_;
    int pending_ = 0;
};

// Culls a camera's tile: packet tests only the own primitives some ray of
// the camera's pencil may meet. A derived pencil (HasPencil) where
// derived_holds, i.e. it holds the rays the render makes, swept over the
// shutter for a moving camera (CameraPencil::sweep_mid_m); a measured one
// (HasCheckedPencil) where measured_holds and the camera is still, batcher
// then checking every traced batch against it (its check reads the rays
// before a moving camera's offset).
template <class Camera, class Packet, class Batcher>
void cull_tile(const Camera& camera, const SceneMotion& motion, const Tile& tile, Packet* packet, Batcher* batcher,
               bool derived_holds = true, bool measured_holds = true) {
    const int x0 = tile.cols().begin(), y0 = tile.rows().begin(), x1 = tile.cols().end(), y1 = tile.rows().end();
    CameraPencil pencil;
    if constexpr (HasPencil<Camera>::value) {
        if (derived_holds && camera.pencil(x0, y0, x1, y1, &pencil)) {
            if (motion.moves_camera()) {
                const Vec3d open_m = motion.camera_offset_m(0.0f), close_m = motion.camera_offset_m(1.0f);
                pencil.sweep_mid_m = (open_m + close_m) * 0.5;
                pencil.sweep_half_m = 0.5 * length(close_m - open_m);
            }
            packet->cull_by(pencil);
        }
    }
    if (motion.moves_camera()) return;
    if constexpr (HasCheckedPencil<Camera>::value) {
        LensPencilCheck check;
        if (measured_holds && camera.checked_pencil(x0, y0, x1, y1, &pencil, &check)) {
            packet->cull_by(pencil);
            batcher->check_by(check);
        }
    }
}

}  // namespace lc
