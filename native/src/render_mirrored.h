// The lens system's render loop with mirrored rays. A lens of round surfaces
// is symmetric under reflections of its frame's x and y: the ray from the
// reflected film point through the reflected pupil point is the traced ray
// reflected. So the pixels (x, y), (W-1-x, y), (x, H-1-y) and (W-1-x, H-1-y)
// take one set of samples, the canonical pixel's (the one in the top-left
// quarter), mirrored: it is traced through the lens once and its rays
// reflected into the other three. The trace and pupil pick, most of the lens
// system's cost, then run once for four pixels. Every pixel still gets its
// own estimate, unbiased, with its own scene rays; only the four pixels'
// film and lens points are mirror images of one another (their errors are
// correlated, not their scenes). A pixel's value never depends on which
// pixels a call renders with it: an image's rays always come from its
// canonical pixel's trace, reflected.
#pragma once

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <utility>

#include "cameras/lens_system.h"
#include "mirrored_batcher.h"
#include "mirrored_batcher_spectral.h"
#include "render_settings.h"
#include "render_tile.h"
#include "render_tile_spectral.h"
#include "scene.h"

namespace lc {

// Half render.h's tile side: each canonical tile is up to four tiles of work.
constexpr int kMirroredTileSize = 8;

// The rows a render call covers: [begin, end), and their mirror images
// (H-1-y) too when mirrored.
struct RowSet {
    int begin, end;
    bool mirrored;
    int height;

    bool has(int y) const {
        return (y >= begin && y < end) || (mirrored && height - 1 - y >= begin && height - 1 - y < end);
    }
    // The mirror rows [first, second) that [begin, end) does not hold
    // (empty when not mirrored): all of them, or where the two runs overlap
    // about the middle, the part beyond.
    std::pair<int, int> mirror_run() const {
        if (!mirrored) return {end, end};
        const int lo = height - end, hi = height - begin;
        if (hi <= begin || lo >= end) return {lo, hi};
        return lo < begin ? std::pair{lo, begin} : std::pair{end, hi};
    }
};

// Pixel rectangle [x0, x1) x [y0, y1).
struct PixelRect {
    int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    bool has(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

// Where mirror m puts the canonical tile's pixels: the reflected rectangle,
// less the pixels that are their own image (a middle column or row, which
// mirror 0 renders) and the rows the call does not cover. rows must be one
// contiguous run within either half (render_mirrored_rows sees to it).
inline PixelRect mirror_rect(const Tile& canonical, unsigned m, int width_px, int height_px, const RowSet& rows) {
    const int c0 = canonical.cols().begin(), c1 = canonical.cols().end();
    const int r0 = canonical.rows().begin(), r1 = canonical.rows().end();
    PixelRect rect;
    rect.x0 = (m & 1u) ? std::max(width_px - c1, (width_px + 1) / 2) : c0;
    rect.x1 = (m & 1u) ? width_px - c0 : c1;
    const int y0 = (m & 2u) ? std::max(height_px - r1, (height_px + 1) / 2) : r0;
    const int y1 = (m & 2u) ? height_px - r0 : r1;
    rect.y0 = y1, rect.y1 = y0;  // empty until a covered row is found
    for (int y = y0; y < y1; ++y)
        if (rows.has(y)) rect.y0 = std::min(rect.y0, y), rect.y1 = std::max(rect.y1, y + 1);
    return rect;
}

// The pixel that mirror m makes of canonical pixel (x, y).
inline void mirror_pixel(unsigned m, int x, int y, int width_px, int height_px, int* mx, int* my) {
    *mx = (m & 1u) ? width_px - 1 - x : x;
    *my = (m & 2u) ? height_px - 1 - y : y;
}

// How a canonical tile renders: RGB (integrate_wavelengths for a spectral
// render whose wavelengths are integrated, render.h) or with drawn wavelengths.
enum class MirroredRender { Rgb, RgbIntegrated, Spectral };

// Renders the images of one canonical tile into rgb.
template <MirroredRender kind>
RenderStats render_mirrored_tile(const Scene& scene, const LensSystemCamera& camera, const RenderSettings& s,
                                 const Tile& canonical, const RowSet& rows, float* rgb) {
    constexpr bool spectral = kind == MirroredRender::Spectral;
    using Packet = std::conditional_t<spectral, SpectralRayPacket, RayPacket>;
    using Batcher = std::conditional_t<spectral, MirroredSpectralBatcher, MirroredBatcher>;
    const bool with_variance = s.variance_of_mean != nullptr;
    PixelRect rect[4];
    std::optional<TileAccumulator> sums[4];
    std::optional<Packet> packet_of[4];
    Packet* packets[4] = {};
    for (unsigned m = 0; m < 4; ++m) {
        if (m & ~camera.mirror_axes) continue;
        rect[m] = mirror_rect(canonical, m, s.width_px, s.height_px, rows);
        if (rect[m].empty()) continue;
        sums[m].emplace(Tile(rect[m].y0, rect[m].y1, rect[m].x0, rect[m].x1), with_variance);
        if constexpr (spectral) packets[m] = &packet_of[m].emplace(scene, *sums[m]);
        else packets[m] = &packet_of[m].emplace(scene, *sums[m], kind == MirroredRender::RgbIntegrated);
        packets[m]->set_stream(int(m));  // the four images' packets take turns: a cache each
    }
    Batcher batcher = [&] {
        if constexpr (spectral)
            return Batcher(camera, scene.motion(), *scene.spectral(),
                           spectral_path(camera, *scene.spectral()), packets);
        else return Batcher(camera, scene.motion(), packets);
    }();
    for (unsigned m = 0; m < 4 && !scene.motion().moves_camera(); ++m) {  // a moving camera's rays shift: no cull
        CameraPencil pencil;
        LensPencilCheck check;
        if (packets[m] &&
            camera.checked_pencil(rect[m].x0, rect[m].y0, rect[m].x1, rect[m].y1, &pencil, &check)) {
            packets[m]->cull_by(pencil);
            batcher.check_by(m, check);
        }
    }
    PixelSamples samples(s.spp, scene.motion().samples_time(), spectral);
    RenderStats stats;
    for (int y = canonical.rows().begin(); y < canonical.rows().end(); ++y) {
        for (int x = canonical.cols().begin(); x < canonical.cols().end(); ++x) {
            // Each image's samples [first, end), as its own pixel index asks.
            int first[4], end[4];
            size_t slot[4] = {};
            for (unsigned m = 0; m < 4; ++m) {
                first[m] = end[m] = 0;
                int mx, my;
                mirror_pixel(m, x, y, s.width_px, s.height_px, &mx, &my);
                if (!packets[m] || !rect[m].has(mx, my)) continue;
                const auto range = s.samples_of(uint64_t(my) * uint64_t(s.width_px) + uint64_t(mx));
                first[m] = range.first, end[m] = range.end;
                slot[m] = sums[m]->slot(mx, my);
                stats.samples += uint64_t(range.end - range.first);
            }
            // The canonical pixel's samples, drawn once per distinct count
            // (a sampler's first samples depend on how many it draws); one
            // draw for a uniform render.
            const uint64_t pixel_index = uint64_t(y) * uint64_t(s.width_px) + uint64_t(x);
            for (unsigned m = 0; m < 4; ++m) {
                if (end[m] <= first[m] || std::find(end, end + m, end[m]) != end + m) continue;
                int image_first[4], lowest = INT_MAX;
                for (unsigned k = 0; k < 4; ++k) {
                    const bool takes = end[k] == end[m] && end[k] > first[k];
                    image_first[k] = takes ? first[k] : INT_MAX;
                    lowest = std::min(lowest, image_first[k]);
                }
                samples.fill(s, pixel_index, end[m]);
                batcher.add_pixel(x, y, samples, lowest, end[m], slot, image_first);
            }
        }
    }
    batcher.flush();
    for (unsigned m = 0; m < 4; ++m) {
        if (!packets[m]) continue;
        packets[m]->flush();
        sums[m]->finish(s, rgb);
        if constexpr (spectral) stats.rays_passed += packets[m]->samples_shaded();
        else stats.rays_passed += packets[m]->rays_shaded();
    }
    return stats;
}

// Renders the rows of `rows` into rgb, tiles of canonical pixels in parallel.
template <MirroredRender kind>
RenderStats render_mirrored_rows(const Scene& scene, const LensSystemCamera& camera, const RenderSettings& s,
                                 const RowSet& rows, float* rgb) {
    const int width = s.width_px, height = s.height_px;
    if (!(camera.mirror_axes & 2u) && rows.mirrored) {
        // Rows are not mirrored: each run of rows is its own canonical rows.
        const RenderStats upper =
            render_mirrored_rows<kind>(scene, camera, s, {rows.begin, rows.end, false, height}, rgb);
        const auto [mirror_begin, mirror_end] = rows.mirror_run();
        RenderStats lower;
        if (mirror_begin < mirror_end)
            lower = render_mirrored_rows<kind>(scene, camera, s, {mirror_begin, mirror_end, false, height}, rgb);
        return {upper.samples + lower.samples, upper.rays_passed + lower.rays_passed};
    }
    // The canonical rows: those whose image (or themselves) the call covers.
    int row0 = height, row1 = 0;
    for (int y = 0; y < height; ++y) {
        if (!rows.has(y)) continue;
        const int canonical = (camera.mirror_axes & 2u) ? std::min(y, height - 1 - y) : y;
        row0 = std::min(row0, canonical), row1 = std::max(row1, canonical + 1);
    }
    const int cols = (camera.mirror_axes & 1u) ? (width + 1) / 2 : width;
    std::atomic<uint64_t> rays_passed{0}, samples_drawn{0};
    if (row0 < row1) {
        tbb::task_arena arena(s.threads > 0 ? s.threads : tbb::task_arena::automatic);
        arena.execute([&] {
            const Tile canonical_pixels(row0, row1, kMirroredTileSize, 0, cols, kMirroredTileSize);
            tbb::parallel_for(canonical_pixels, [&](const Tile& tile) {
                const RenderStats tile_stats = render_mirrored_tile<kind>(scene, camera, s, tile, rows, rgb);
                rays_passed += tile_stats.rays_passed;
                samples_drawn += tile_stats.samples;
            });
        });
    }
    RenderStats stats;
    stats.samples = samples_drawn.load();
    stats.rays_passed = rays_passed.load();
    return stats;
}

}  // namespace lc
