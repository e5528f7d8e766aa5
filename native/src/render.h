// The render loop, written once and instantiated per camera model: per pixel,
// the sampler fills the pixel's film and lens samples (and times, when the
// scene moves during the shutter), the camera turns each into a ray (or
// nothing, when vignetted), the scene returns radiance at that time.
// Every pixel owns its random stream, so the image is the same for any thread
// count and any tiling.
#pragma once

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <type_traits>

#include "cameras/lens_system.h"
#include "render_mirrored.h"
#include "render_settings.h"
#include "render_tile.h"
#include "render_tile_bands.h"
#include "render_tile_spectral.h"
#include "scene.h"

namespace lc {

constexpr int kTileSize = 16;

// Renders one tile into rgb: each pixel's samples pass the stages of
// render_tile.h in sample order, then each pixel gets its mean.
// integrate_wavelengths: a spectral render whose wavelengths are integrated,
// not drawn (spectral_path's Integrated), so that it renders as RGB does.
template <class Camera>
RenderStats render_tile(const Scene& scene, const Camera& camera, const RenderSettings& s, const Tile& tile,
                        float* rgb, bool integrate_wavelengths = false) {
    TileAccumulator sums(tile, s.variance_of_mean != nullptr);
    RayPacket packet(scene, sums, integrate_wavelengths);
    CameraSampleBatcher<Camera> batcher(camera, scene.motion(), packet);
    cull_tile(camera, scene.motion(), tile, &packet, &batcher);
    PixelSamples samples(s.spp, scene.motion().samples_time(), false, UsesLensSamples<Camera>::value);
    RenderStats stats;
    for (int y = tile.rows().begin(); y < tile.rows().end(); ++y) {
        for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            const uint64_t pixel_index = uint64_t(y) * uint64_t(s.width_px) + uint64_t(x);
            const auto [first, end] = s.samples_of(pixel_index);
            if (end == first) continue;
            samples.fill(s, pixel_index, end);
            stats.samples += uint64_t(end - first);
            const size_t slot = sums.slot(x, y);
            batcher.add_pixel(x, y, samples, first, end, slot);
        }
    }
    // The last, partly filled batch and packet
    batcher.flush();
    packet.flush();
    sums.finish(s, rgb);
    stats.rays_passed = packet.rays_shaded();
    return stats;
}

// Renders rows [row_begin, row_end) into rgb (height x width x 3, row 0 at
// the top), and with mirror_rows their mirror images (rows height-1-y) too:
// a lens system's mirrored rays (render_mirrored.h) then serve both.
template <class Camera>
RenderStats render_rows(const Scene& scene, const Camera& camera, const RenderSettings& s, int row_begin,
                        int row_end, float* rgb, bool mirror_rows = false) {
    const SpectralPath path = scene.spectral() ? spectral_path(camera, *scene.spectral())
                                               : SpectralPath::Integrated;
    const bool integrated = scene.spectral() && path == SpectralPath::Integrated;
    const bool bands = scene.spectral() && path == SpectralPath::IntegratedBands;
    const bool sampled = scene.spectral() && !integrated && !bands;
    const RowSet rows{row_begin, row_end, mirror_rows, s.height_px};
    std::optional<FocusBandIntegrals> band_integrals;  // the bands' tables, one for every tile
    if constexpr (HasBandRays<Camera>::value)
        if (bands) band_integrals.emplace(scene.focus_band_integrals(camera.band_focus_table()));
    if constexpr (std::is_same_v<Camera, LensSystemCamera>) {
        if (camera.mirror_axes && !bands) {  // band rays are not mirrored
            if (sampled) return render_mirrored_rows<MirroredRender::Spectral>(scene, camera, s, rows, rgb);
            if (integrated) return render_mirrored_rows<MirroredRender::RgbIntegrated>(scene, camera, s, rows, rgb);
            return render_mirrored_rows<MirroredRender::Rgb>(scene, camera, s, rows, rgb);
        }
    }
    std::atomic<uint64_t> rays_passed{0}, samples_drawn{0};
    auto render_run = [&](int begin, int end) {
        if (begin >= end) return;
        tbb::blocked_range2d<int> rows_cols(begin, end, kTileSize, 0, s.width_px, kTileSize);
        tbb::parallel_for(rows_cols, [&](const Tile& tile) {
            const RenderStats tile_stats = sampled ? render_tile_spectral(scene, camera, s, tile, rgb)
                                           : bands   ? render_tile_bands(scene, camera, s, tile, band_integrals, rgb)
                                                     : render_tile(scene, camera, s, tile, rgb, integrated);
            rays_passed += tile_stats.rays_passed;
            samples_drawn += tile_stats.samples;
        });
    };
    tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        render_run(row_begin, row_end);
        const auto [mirror_begin, mirror_end] = rows.mirror_run();
        render_run(mirror_begin, mirror_end);
    });
    RenderStats stats;
    stats.samples = samples_drawn.load();
    stats.rays_passed = rays_passed.load();
    return stats;
}

}  // namespace lc
