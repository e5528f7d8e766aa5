// The lens system's batcher of mirrored samples (render_mirrored.h): a batch
// of canonical samples traced once, each mirror image's rays reflected from
// the traced ones and queued in that image's packet.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "cameras/lens_system.h"
#include "render_tile.h"

namespace lc {

// kFirstOfBatch + (kCameraBatch - n): flags whose first n are set, of kCameraBatch.
inline constexpr bool kFirstOfBatch[2 * kCameraBatch] = {
    true, true, true, true, true, true, true, true, true, true, true, true, true, true, true, true,
    true, true, true, true, true, true, true, true, true, true, true, true, true, true, true, true};
static_assert(kCameraBatch == 32, "kFirstOfBatch's ones");

// A camera batch of canonical samples, each with where its mirror images go:
// for mirror m (bit 0 x, bit 1 y reflected), the slot of the image pixel in
// that mirror's accumulator and whether the image takes this sample.
struct MirroredColumns {
    Point2f raster_px[kCameraBatch], lens[kCameraBatch];
    float time[kCameraBatch];
    size_t slot[4][kCameraBatch];
    bool taken[4][kCameraBatch];

    // Samples [first, first + n) of canonical pixel (x, y) into columns
    // [at, at + n): mirror m's image (at slot[m]) takes them from sample
    // image_first[m] on (INT_MAX: never). Loops over the run, which GCC
    // vectorises, rather than a sample at a time (a dozen scalar stores each:
    // the stores waited, perf).
    void take(int at, int x, int y, const PixelSamples& samples, int first, int n, const size_t* image_slot,
              const int* image_first) {
        const float px = float(x), py = float(y);
        const Point2f* film = samples.film.data() + first;
        for (int j = 0; j < n; ++j) raster_px[at + j] = {px + film[j].x, py + film[j].y};
        std::memcpy(lens + at, samples.lens.data() + first, sizeof(Point2f) * size_t(n));
        if (samples.time.empty()) std::fill_n(time + at, n, 0.0f);
        else std::copy_n(samples.time.data() + first, n, time + at);
        for (int m = 0; m < 4; ++m) {
            std::fill_n(slot[m] + at, n, image_slot[m]);
            const int from = image_first[m];
            for (int j = 0; j < n; ++j) taken[m][at + j] = first + j >= from;
        }
    }
};

// One mirror's traced rays in float rows, as the packets take them, alive
// only in the lanes its image takes. A moving camera's go through double
// columns (scratch: columns), each offset by the camera's motion at its time
// before rounding (move_origins).
inline void mirrored_rows(const LensToWorld& to_world, const SceneMotion& motion, const LensRayBatch& rays,
                          const double* cos_theta, const double* area_mm2, int n, const float* time,
                          const bool* taken, CameraRayBatch* columns, CameraRayRows* rows, float* weight,
                          bool* alive) {
    if (motion.moves_camera()) {
        LensSystemCamera::to_columns(to_world, rays, cos_theta, area_mm2, n, columns);
        move_origins(motion, n, time, columns);
        for (int i = 0; i < n; ++i) weight[i] = columns->weight[i], alive[i] = columns->alive[i];
        round_rows(*columns, n, rows);
    } else {
        LensSystemCamera::to_rows(to_world, rays, cos_theta, area_mm2, n, rows, weight, alive);
    }
    for (int i = 0; i < n; ++i) alive[i] = alive[i] && taken[i];
}

// Samples waiting for the lens: traced once per batch, then each mirror's
// rays moved to the world through its reflected frame (the traced rays'
// mirror images, bit for bit) and queued in that mirror's packet.
class MirroredBatcher {
  public:
    // packets[m]: mirror m's packet, or null when the tile has no image there.
    MirroredBatcher(const LensSystemCamera& camera, const SceneMotion& motion, RayPacket* const* packets)
        : camera_(camera), motion_(motion), to_world_(camera.lens_to_world()),
          traced_frames_{mirrored_frame(to_world_, 0), mirrored_frame(to_world_, 1), mirrored_frame(to_world_, 2),
                         mirrored_frame(to_world_, 3)},
          table_frames_{mirrored_frame(LensToWorldF(to_world_), 0), mirrored_frame(LensToWorldF(to_world_), 1),
                        mirrored_frame(LensToWorldF(to_world_), 2), mirrored_frame(LensToWorldF(to_world_), 3)} {
        std::copy_n(packets, 4, packets_);
    }

    // As CameraSampleBatcher::check_by, for mirror m's packet.
    void check_by(unsigned m, const LensPencilCheck& check) { check_[m].start(check); }

    // Queues samples [first, end) of canonical pixel (x, y): mirror m's
    // image, at slot[m], takes samples [image_first[m], end) (INT_MAX: none).
    void add_pixel(int x, int y, const PixelSamples& samples, int first, int end, const size_t* slot,
                   const int* image_first) {
        for (int k = first; k < end;) {
            const int n = std::min(end - k, kCameraBatch - pending_);
            staged_.take(pending_, x, y, samples, k, n, slot, image_first);
            pending_ += n, k += n;
            if (pending_ == kCameraBatch) flush();
        }
    }

    // Traces the queued samples once and hands each mirror its rays, in queue order.
    void flush() {
        if (pending_ == 0) return;
        const int n = pending_;
        if (camera_.ray_table) {
            flush_from_table(n);
            pending_ = 0;
            return;
        }
        // The traced rays are not reflected either: as flush_from_table.
        camera_.trace_batch(staged_.raster_px, staged_.lens, n, &traced_, area_mm2_, cos_theta_);
        ImageFlags images = image_flags(n, traced_.alive);
        lens_rays_within_mirrors(images.checks, traced_, images.alive, images.within);
        for (unsigned m = 0; m < 4; ++m) {
            if (!images.any_taken[m]) continue;
            mirrored_rows(traced_frames_[m], motion_, traced_, cos_theta_, area_mm2_, n, staged_.time,
                          staged_.taken[m], &columns_, &rows_, weight_, alive_);
            if (images.checks[m]) check_[m].passed(images.within[m], *packets_[m]);
            packets_[m]->add_rows(rows_, n, staged_.time, staged_.slot[m], alive_, weight_);
        }
        pending_ = 0;
    }

  private:
    // flush through the lens-ray table: its float rays looked up once and
    // sent to the world in float for each mirror, as the unmirrored table
    // path does (LensSystemCamera::look_up_ray_rows); a moving camera's
    // offset added to the float rows, as for every camera there. The rays are
    // not reflected: each mirror's frame is (mirrored_frame), and its check's
    // window (lens_rays_within_mirrors: the four checks in one pass over the
    // rays), the same bits as reflected rays without a copy of them.
    void flush_from_table(int n) {
        camera_.look_up_rays(staged_.raster_px, staged_.lens, n, &table_rays_);
        ImageFlags images = image_flags(n, table_rays_.alive);
        lens_rays_within_mirrors(images.checks, table_rays_, images.alive, images.within);
        for (unsigned m = 0; m < 4; ++m) {
            if (!images.any_taken[m]) continue;
            lens_to_world_rows(table_frames_[m], table_rays_, &rows_, weight_);
            if (motion_.moves_camera()) move_origins(motion_, n, staged_.time, &rows_);
            if (images.checks[m]) check_[m].passed(images.within[m], *packets_[m]);
            packets_[m]->add_rows(rows_, n, staged_.time, staged_.slot[m], mirror_alive_[m], weight_);
        }
    }

    // Each image's lanes for a batch of n canonical rays: its live ones (in
    // mirror_alive_), whether it takes any of the samples, and its pencil
    // check (null: none, or it takes none); within: the checks' answers,
    // lens_rays_within_mirrors' to fill.
    struct ImageFlags {
        const LensPencilCheck* checks[4] = {};
        const bool* alive[4] = {};
        bool any_taken[4] = {};
        bool within[4] = {true, true, true, true};
    };
    ImageFlags image_flags(int n, const bool* rays_alive) {
        ImageFlags images;
        for (unsigned m = 0; m < 4; ++m) {
            if (!packets_[m]) continue;
            // Flags as bytes ANDed, no branch and no early exit: a loop GCC
            // vectorises, where the branches per lane were a tenth of
            // flush_from_table (perf).
            const bool* taken = staged_.taken[m];
            bool* image_alive = mirror_alive_[m];
            const bool* queued = kFirstOfBatch + (kCameraBatch - n);  // lane i: i < n
            uint8_t any = 0;
            for (int i = 0; i < kCameraBatch; ++i) {
                const uint8_t mine = uint8_t(queued[i]) & uint8_t(taken[i]);
                image_alive[i] = mine & uint8_t(rays_alive[i]);
                any |= mine;
            }
            images.any_taken[m] = any != 0;
            images.checks[m] = images.any_taken[m] ? check_[m].active() : nullptr;
            images.alive[m] = image_alive;
        }
        return images;
    }

    const LensSystemCamera& camera_;
    const SceneMotion& motion_;
    LensToWorld to_world_;
    LensToWorld traced_frames_[4];  // the traced rays to the world, mirror by mirror (mirrored_frame)
    LensToWorldF table_frames_[4];  // the table's (flush_from_table)
    RayPacket* packets_[4];
    MirroredColumns staged_{};  // zeroed: flush_from_table reads whole rows, past the queued samples too
    LensRayBatch traced_;
    LensRaysF table_rays_;
    double area_mm2_[kLensBatch], cos_theta_[kLensBatch];
    CameraRayRows rows_;
    CameraRayBatch columns_;  // mirrored_rows' scratch for a moving camera
    float weight_[kCameraBatch];
    bool alive_[kCameraBatch];
    bool mirror_alive_[4][kCameraBatch];  // image_flags', each image's
    TileCheck check_[4];
    int pending_ = 0;
};

}  // namespace lc
