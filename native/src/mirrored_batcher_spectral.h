// The spectral form of mirrored_batcher.h: a lens system's canonical
// samples, each with its four wavelengths, traced once per traced wavelength
// and sent to each mirror image through its reflected frame. A lens of round
// surfaces is as symmetric at every wavelength as at one, so the mirrored
// rays of a dispersed trace are the dispersed rays of the mirrored samples.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>

#include "cameras/lens_system.h"
#include "mirrored_batcher.h"
#include "render_tile.h"
#include "render_tile_spectral.h"
#include "spectral.h"

namespace lc {

class MirroredSpectralBatcher {
  public:
    // packets[m]: mirror m's packet, or null when the tile has no image there.
    // path: OneRay (one ray per sample carries all four wavelengths) or
    // RayPerWavelength (a ray per traced wavelength), as spectral_path says.
    MirroredSpectralBatcher(const LensSystemCamera& camera, const SceneMotion& motion, const SpectralTables& spectra,
                            SpectralPath path, SpectralRayPacket* const* packets)
        : camera_(camera), motion_(motion), spectra_(spectra),
          dispersed_(path == SpectralPath::RayPerWavelength) {
        const LensToWorld to_world = camera.lens_to_world();
        for (unsigned m = 0; m < 4; ++m) frames_[m] = mirrored_frame(to_world, m);
        std::copy_n(packets, 4, packets_);
    }

    // As MirroredBatcher::check_by.
    void check_by(unsigned m, const LensPencilCheck& check) { check_[m].start(check); }

    // As MirroredBatcher::add_pixel; each sample draws its four wavelengths here.
    void add_pixel(int x, int y, const PixelSamples& samples, int first, int end, const size_t* slot,
                   const int* image_first) {
        for (int k = first; k < end; ++k) {
            if (pending_ == 0)
                for (SpectralRayPacket* packet : packets_)
                    if (packet) packet->release(wavelengths_, wavelengths_ + kCameraBatch);
            staged_.take(pending_, x, y, samples, k, 1, slot, image_first);
            sample_hero_wavelengths(spectra_, samples.wavelength[size_t(k)], &wavelengths_[pending_]);
            if (++pending_ == kCameraBatch) flush();
        }
    }

    // Aims the queued samples once, traces them once per traced wavelength,
    // and hands each mirror its rays, a sample's rays in wavelength order.
    void flush() {
        if (pending_ == 0) return;
        const int n = pending_;
        const int traced = dispersed_ ? spectra_.traced_wavelengths : 1, stride = kHeroWavelengths / traced;
        float nm[kCameraBatch][kHeroWavelengths];
        for (int i = 0; i < n; ++i)
            for (int k = 0; k < traced; ++k) nm[i][k] = wavelengths_[i].nm[k * stride];
        bool within[4] = {true, true, true, true}, any_taken[4];
        for (unsigned m = 0; m < 4; ++m)
            any_taken[m] = packets_[m] && std::any_of(staged_.taken[m], staged_.taken[m] + n, [](bool t) { return t; });
        camera_.trace_each_wavelength(
            staged_.raster_px, staged_.lens, nm, n, traced, nullptr,
            [&](int k, const LensRayBatch& batch, const double* cos_theta, const double* area_mm2) {
                // As MirroredBatcher::flush: each mirror's frame and check
                // window reflected, not its rays (the same bits), the four
                // checks in one pass.
                const LensPencilCheck* checks[4] = {};
                const bool* alive[4] = {};
                for (unsigned m = 0; m < 4; ++m) {
                    if (!any_taken[m]) continue;
                    mirrored_rows(frames_[m], motion_, batch, cos_theta, area_mm2, n, staged_.time,
                                  staged_.taken[m], &columns_, &rows_[m][k], weight_[m][k], alive_[m][k]);
                    checks[m] = within[m] ? check_[m].active() : nullptr;
                    alive[m] = alive_[m][k];
                }
                bool passed[4];
                lens_rays_within_mirrors(checks, batch, alive, passed);
                for (unsigned m = 0; m < 4; ++m) within[m] = within[m] && passed[m];
                return static_cast<const bool*>(nullptr);  // no check of its own (null above)
            });
        for (unsigned m = 0; m < 4; ++m) {
            if (!any_taken[m]) continue;
            if (check_[m].active()) check_[m].passed(within[m], *packets_[m]);
            const float* weight[kHeroWavelengths];
            const bool* alive[kHeroWavelengths];
            for (int k = 0; k < traced; ++k) weight[k] = weight_[m][k], alive[k] = alive_[m][k];
            packets_[m]->add_rows(rows_[m], weight, alive, traced, stride, !dispersed_, n, wavelengths_,
                                  staged_.time, staged_.slot[m]);
        }
        pending_ = 0;
        // The packets may hold rays of this batch still: the next one fills the other buffer.
        std::swap(wavelengths_, other_wavelengths_);
    }

  private:
    const LensSystemCamera& camera_;
    const SceneMotion& motion_;
    const SpectralTables& spectra_;
    bool dispersed_;
    LensToWorld frames_[4];  // the traced rays to the world, mirror by mirror (mirrored_frame)
    SpectralRayPacket* packets_[4];
    MirroredColumns staged_;
    CameraRayBatch columns_;  // mirrored_rows' scratch for a moving camera
    CameraRayRows rows_[4][kHeroWavelengths];
    float weight_[4][kHeroWavelengths][kCameraBatch];
    bool alive_[4][kHeroWavelengths][kCameraBatch];
    // Two buffers of the batch's wavelengths, swapped after each flush (SpectralRayPacket::release).
    HeroWavelengths wavelength_buffers_[2][kCameraBatch];
    HeroWavelengths* wavelengths_ = wavelength_buffers_[0];
    HeroWavelengths* other_wavelengths_ = wavelength_buffers_[1];
    TileCheck check_[4];
    int pending_ = 0;
};

}  // namespace lc
