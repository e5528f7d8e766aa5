// lenscompare._native.diagnostics: hooks for tests and benchmarks only (sample
// sets, disk mapping, lens pass rates and throughput, the trace-kernel choice,
// the brute-force pupil, raw Embree throughput). The render never needs them,
// so they stay out of the main module beside the cameras.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <iterator>
#include <optional>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "aperture.h"
#include "bindings_arrays.h"
#include "cameras/lens_system.h"
#include "cameras/pinhole.h"
#include "cameras/thin_lens.h"
#include "diagnostics/lens_passes.h"
#include "diagnostics/lens_stages.h"
#include "diagnostics/raw_throughput.h"
#include "motion.h"
#include "samplers.h"
#include "scene.h"
#include "quad_lanes.h"
#include "solid_faces.h"
#include "rng.h"
#include "shading_lanes.h"
#include "sphere_lanes.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace lc {

namespace {

const Point2f* points(const CArray<const float, -1, 2>& a) { return reinterpret_cast<const Point2f*>(a.data()); }

// A camera's band rays (render_tile_bands.h) in render order, for the
// diagnostics: each ray's sample, ray, band and (where weight is given) weight.
template <class Camera>
size_t write_band_rays(const Camera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
                       CArray<int, -1> sample, CArray<double, -1, 3> origin, CArray<double, -1, 3> direction,
                       CArray<double, -1> k_lo, CArray<double, -1> k_hi, CArray<bool, -1> whole, double* weight) {
    if (!camera.carries_bands()) throw std::invalid_argument("the camera carries no bands");
    const size_t count = raster_px.shape(0), room = sample.shape(0);
    if (lens.shape(0) != count || origin.shape(0) != room || direction.shape(0) != room || k_lo.shape(0) != room ||
        k_hi.shape(0) != room || whole.shape(0) != room)
        throw std::invalid_argument("one row per sample in, as many rows as room out");
    size_t written = 0;
    BandRays rays;
    for (size_t first = 0; first < count; first += kCameraBatch) {
        const int n = int(std::min<size_t>(kCameraBatch, count - first));
        rays.clear();
        camera.band_rays(points(raster_px) + first, points(lens) + first, n, &rays);
        if constexpr (std::is_same_v<Camera, LensSystemCamera>) camera.trace_split_rays(&rays);
        if (written + size_t(rays.whole_count + rays.size()) > room) throw std::invalid_argument("not enough room");
        CameraRayRows whole_rows, split_rows;
        BandRayWeights whole_weights, split_weights;
        camera.whole_ray_rows(rays, &whole_rows, &whole_weights);
        auto write = [&](const CameraRayRows& rows, const BandRayWeights& w, int r, int batch_sample, bool is_whole,
                         double lo, double hi) {
            sample(written) = int(first) + batch_sample;
            for (int a = 0; a < 3; ++a)
                origin(written, size_t(a)) = rows.origin[a][r], direction(written, size_t(a)) = rows.direction[a][r];
            whole(written) = is_whole, k_lo(written) = lo, k_hi(written) = hi;
            if (weight) weight[written] = !w.used ? 1.0 : w.alive[r] ? double(w.weight[r]) : 0.0;
            ++written;
        };
        // In sample order: a whole sample's one ray, or a split one's rays.
        int next_whole = 0, next_split = 0;
        for (int i = 0; i < n; ++i) {
            if (next_whole < rays.whole_count && rays.whole_sample[next_whole] == i) {
                write(whole_rows, whole_weights, next_whole++, i, true, camera.band_runs().lowest(),
                      camera.band_runs().highest());
                continue;
            }
            for (; next_split < rays.size() && rays.sample[size_t(next_split)] == i; ++next_split) {
                const int at = next_split % kCameraBatch;
                if (at == 0)
                    camera.band_ray_rows(rays, next_split, std::min(kCameraBatch, rays.size() - next_split),
                                         &split_rows, &split_weights);
                write(split_rows, split_weights, at, i, false, rays.k_lo[size_t(next_split)],
                      rays.k_hi[size_t(next_split)]);
            }
        }
    }
    return written;
}

// One family of kernels (lens trace, own primitives, random numbers): its
// kernels slowest first, and whether this CPU runs one and what it is called.
template <class Kernel, size_t N>
struct KernelFamily {
    const Kernel (&all)[N];
    bool (*available)(Kernel);
    const char* (*name)(Kernel);

    // The names of the kernels this CPU runs, slowest first.
    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (Kernel kernel : all)
            if (available(kernel)) out.push_back(name(kernel));
        return out;
    }

    // The kernel called wanted; else std::invalid_argument, "key: what"
    // naming a kernel this CPU cannot run or a name no kernel has.
    Kernel named(const std::string& wanted, const char* key, const char* family_name) const {
        for (Kernel kernel : all)
            if (wanted == name(kernel)) {
                if (!available(kernel))
                    throw std::invalid_argument(std::string(key) + ": this CPU cannot run " + wanted);
                return kernel;
            }
        throw std::invalid_argument(std::string(key) + ": no " + family_name + " named " + wanted);
    }
};

const KernelFamily<LensTraceKernel, std::size(kLensTraceKernels)> kLensTraceFamily{
    kLensTraceKernels, lens_trace_kernel_available, lens_trace_kernel_name};
const KernelFamily<SphereKernel, std::size(kSphereKernels)> kSphereFamily{kSphereKernels, sphere_kernel_available,
                                                                         sphere_kernel_name};
const KernelFamily<RngKernel, std::size(kRngKernels)> kRngFamily{kRngKernels, rng_kernel_available, rng_kernel_name};

void bind_samplers(nb::module_& m) {
    m.attr("SAMPLER_SOBOL_UNSCRAMBLED") = int(SamplerKind::SobolUnscrambled);

    m.attr("SAMPLER_SOBOL_PADDED") = int(SamplerKind::SobolPadded);
    m.attr("SAMPLER_SOBOL_TIME_NET") = int(SamplerKind::SobolTimeNet);

    m.def("rng_kernels", [] { return kRngFamily.names(); },
          "The kernels that draw PCG32's outputs several at a time (rng_lanes.cpp) this CPU runs, slowest first.");

    m.def("pcg32_draws",
          [](uint64_t seed, uint64_t stream, uint64_t dimension, CArray<uint32_t, -1> out, const std::string& kernel) {
              const RngKernel k = kRngFamily.named(kernel, "kernel", "random-number kernel");
              Pcg32 rng(seed, stream, dimension);
              rng.fill_u32(out.data(), int(out.shape(0)), k);
          },
          "seed"_a, "stream"_a, "dimension"_a, "out"_a, "kernel"_a,
          "Fills out with the first outputs of the render's PCG32 stream (seed, stream, dimension), drawn by the "
          "named kernel (Pcg32::fill_u32).");

    m.def("pixel_samples",
          [](int sampler, uint64_t seed, uint64_t pixel_index, CArray<float, -1, 2> film,
             std::optional<CArray<float, -1, 2>> lens, std::optional<CArray<float, -1>> time,
             std::optional<CArray<float, -1>> wavelength, int first_sample) {
              if ((lens && lens->shape(0) != film.shape(0)) || (time && time->shape(0) != film.shape(0)) ||
                  (wavelength && wavelength->shape(0) != film.shape(0)))
                  throw std::invalid_argument("film, lens, time and wavelength need one row per sample");
              if (first_sample < 0) throw std::invalid_argument("first_sample must be 0 or more");
              fill_pixel_samples(pass_sampler(SamplerKind(sampler), first_sample), seed, pixel_index, int(film.shape(0)),
                                 reinterpret_cast<Point2f*>(film.data()),
                                 lens ? reinterpret_cast<Point2f*>(lens->data()) : nullptr,
                                 time ? time->data() : nullptr, wavelength ? wavelength->data() : nullptr);
          },
          "sampler"_a, "seed"_a, "pixel_index"_a, "film"_a, "lens"_a.none(), "time"_a = nb::none(),
          "wavelength"_a = nb::none(), "first_sample"_a = 0,
          "Fills film and lens (spp x 2; lens None: not drawn, as for the pinhole), and time and wavelength (spp) "
          "when given, with one pixel's samples, as "
          "the render draws them in a pass that takes samples [first_sample, spp) (0: the pixel whole; sobol's time "
          "is then i / spp, Owen-scrambled, and dimension 6 otherwise).");

    m.def("map_to_disk",
          [](CArray<const float, -1, 2> u, int mapping, CArray<float, -1, 2> out) {
              for (size_t i = 0; i < u.shape(0); ++i) {
                  Point2f p = map_to_disk({u(i, 0), u(i, 1)}, DiskMapping(mapping));
                  out(i, 0) = p.x, out(i, 1) = p.y;
              }
          },
          "u"_a, "mapping"_a, "out"_a, "Maps unit-square points u to the unit disk into out.");

    m.def("map_to_aperture",
          [](CArray<const float, -1, 2> u, int mapping, int blades, double rotation_deg, CArray<double, -1, 2> out) {
              const ApertureShape shape = ApertureShape::of(blades, rotation_deg);
              for (size_t i = 0; i < u.shape(0); ++i) shape.sample({u(i, 0), u(i, 1)}, DiskMapping(mapping), &out(i, 0), &out(i, 1));
          },
          "u"_a, "mapping"_a, "blades"_a, "rotation_deg"_a, "out"_a,
          "Maps unit-square points u to the aperture (circle of radius 1, or the N-gon of its area) into out.");
}

// The render loop's batch of rays for a camera that makes them side by side
// (pinhole, thin lens, lens system): tests hold it to generate_ray.
template <class Camera>
void generate_rays_batched(const Camera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
                           CArray<double, -1, 3> origin, CArray<double, -1, 3> direction, CArray<float, -1> weight) {
    const Point2f* raster = points(raster_px);
    const Point2f* u = points(lens);
    for (size_t first = 0; first < raster_px.shape(0); first += kCameraBatch) {
        const int n = int(std::min<size_t>(kCameraBatch, raster_px.shape(0) - first));
        MaybeRay rays[kCameraBatch];
        camera_rays(camera, raster + first, u + first, n, rays);
        for (int i = 0; i < n; ++i) store_ray(rays[i], first + size_t(i), origin, direction, weight);
    }
}

// The lens camera's rays for samples [0, count) batch by batch, as the
// render's packets take them (generate_weighted_ray_rows, each batch checked
// against check when one is given): emit(first, n, rows, weight, alive,
// within) per batch.
template <class Emit>
void for_each_ray_rows_batch(const LensSystemCamera& camera, const Point2f* raster, const Point2f* u, size_t count,
                             const LensPencilCheck* check, Emit emit) {
    for (size_t first = 0; first < count; first += kCameraBatch) {
        const int n = int(std::min<size_t>(kCameraBatch, count - first));
        CameraRayRows rows;
        float weight[kCameraBatch];
        bool alive[kCameraBatch];
        const bool within = camera.generate_weighted_ray_rows(raster + first, u + first, n, &rows, weight, alive, check);
        emit(first, n, rows, weight, alive, within);
    }
}

void bind_lens(nb::module_& m) {
    m.def("count_lens_passes",
          [](const LensSystemCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens) {
              LensPassCounts c = count_lens_passes(camera, points(raster_px), points(lens), size_t(raster_px.shape(0)));
              return std::make_tuple(c.samples, c.traced, c.passed);
          },
          "camera"_a, "raster_px"_a, "lens"_a, nb::call_guard<nb::gil_scoped_release>(),
          "(samples, traced, passed) for the given film and lens samples, traced one at a time.");

    m.def("lens_stage_seconds",
          [](const LensSystemCamera& camera, const PinholeCamera& pinhole, CArray<const float, -1, 2> raster_px,
             CArray<const float, -1, 2> lens) {
              if (lens.shape(0) != raster_px.shape(0)) throw std::invalid_argument("one lens sample per film sample");
              const LensStageSeconds s =
                  lens_stage_seconds(camera, pinhole, points(raster_px), points(lens), size_t(raster_px.shape(0)));
              return std::make_tuple(s.sample, s.trace, s.whole, s.pinhole);
          },
          "camera"_a, "pinhole"_a, "raster_px"_a, "lens"_a, nb::call_guard<nb::gil_scoped_release>(),
          "(sample, trace, whole, pinhole) CPU seconds of this thread for the samples' camera rays in the render "
          "loop's batches: film points, pupil picks and aim; the batch trace alone; the lens camera's float rows "
          "whole; the pinhole's rows.");

    m.def("measure_lens_throughput",
          [](const LensSystemCamera& camera, uint64_t n, int threads) {
              LensPassCounts c;
              double seconds = measure_lens_throughput(camera, n, threads, &c);
              return std::make_tuple(seconds, c.samples, c.traced, c.passed);
          },
          "camera"_a, "n"_a, "threads"_a, nb::call_guard<nb::gil_scoped_release>(),
          "(seconds, samples, traced, passed) for n random samples through the lens alone, no scene.");

    m.def("generate_lens_rays_batched", &generate_rays_batched<LensSystemCamera>,
          "camera"_a, "raster_px"_a, "lens"_a, "origin"_a, "direction"_a, "weight"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "generate_rays through the render loop's lockstep batch trace (in double precision the same bits as "
          "generate_rays; in single, the render's, the same rays to float rounding).");

    m.def("generate_lens_ray_rows",
          [](const LensSystemCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             CArray<float, -1, 3> origin, CArray<float, -1, 3> direction, CArray<float, -1> weight) {
              const size_t count = raster_px.shape(0);
              if (lens.shape(0) != count || origin.shape(0) != count || direction.shape(0) != count ||
                  weight.shape(0) != count)
                  throw std::invalid_argument("one row per sample");
              for_each_ray_rows_batch(camera, points(raster_px), points(lens), count, nullptr,
                                      [&](size_t first, int n, const CameraRayRows& rows, const float* w,
                                          const bool* alive, bool) {
                                          for (int i = 0; i < n; ++i) {
                                              const size_t at = first + size_t(i);
                                              for (int a = 0; a < 3; ++a) {
                                                  origin(at, a) = alive[i] ? rows.origin[a][i] : 0.0f;
                                                  direction(at, a) = alive[i] ? rows.direction[a][i] : 0.0f;
                                              }
                                              weight(at) = alive[i] ? w[i] : 0.0f;
                                          }
                                      });
          },
          "camera"_a, "raster_px"_a, "lens"_a, "origin"_a, "direction"_a, "weight"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "The render's own camera rays in float, as its packets take them (generate_weighted_ray_rows: "
          "from the lens-ray table where the camera has one); weight 0 and zeros where blocked.");

    m.def("generate_lens_rays_at",
          [](const LensSystemCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             CArray<const float, -1, kHeroWavelengths> nm, bool batched, CArray<double, -1, 3> origin,
             CArray<double, -1, 3> direction, CArray<float, -1> weight) {
              const size_t count = raster_px.shape(0);
              if (lens.shape(0) != count || nm.shape(0) != count || origin.shape(0) != count * kHeroWavelengths ||
                  direction.shape(0) != count * kHeroWavelengths || weight.shape(0) != count * kHeroWavelengths)
                  throw std::invalid_argument("one row per sample, kHeroWavelengths rays per sample");
              const Point2f* raster = points(raster_px);
              const Point2f* u = points(lens);
              const auto* wavelengths = reinterpret_cast<const float(*)[kHeroWavelengths]>(nm.data());
              for (size_t first = 0; first < count; first += kLensBatch) {
                  const int n = int(std::min<size_t>(kLensBatch, count - first));
                  MaybeRay rays[kLensBatch][kHeroWavelengths];
                  if (batched)
                      camera.generate_rays_at_batch(raster + first, u + first, wavelengths + first, n,
                                                    kHeroWavelengths, rays);
                  else
                      for (int i = 0; i < n; ++i)
                          camera.generate_rays_at(raster[first + i], u[first + i], wavelengths[first + i],
                                                  kHeroWavelengths, rays[i]);
                  for (int i = 0; i < n; ++i)
                      for (int k = 0; k < kHeroWavelengths; ++k)
                          store_ray(rays[i][k], (first + size_t(i)) * kHeroWavelengths + size_t(k), origin,
                                    direction, weight);
              }
          },
          "camera"_a, "raster_px"_a, "lens"_a, "nm"_a, "batched"_a, "origin"_a, "direction"_a, "weight"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "Each sample's rays at its four wavelengths (row i * 4 + k: nm[i, k]), by the scalar per-wavelength "
          "trace or (batched) the lockstep trace of spectral renders.");

    m.def("lens_film_points_from",
          [](const LensSystemCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             CArray<const float, -1> nm, CArray<const float, -1> back_nm, CArray<double, -1, 3> origin_mm,
             CArray<double, -1, 3> direction, CArray<double, -1, 2> film_mm, CArray<bool, -1> alive) {
              const size_t count = raster_px.shape(0);
              if (lens.shape(0) != count || nm.shape(0) != count || back_nm.shape(0) != count ||
                  origin_mm.shape(0) != count || direction.shape(0) != count || film_mm.shape(0) != count ||
                  alive.shape(0) != count)
                  throw std::invalid_argument("one row per sample");
              if (!camera.disperses()) throw std::invalid_argument("the camera does not disperse: set_dispersion first");
              const Point2f* raster = points(raster_px);
              const Point2f* u = points(lens);
              for (size_t first = 0; first < count; first += kLensBatch) {
                  const int n = int(std::min<size_t>(kLensBatch, count - first));
                  float wavelengths[kLensBatch][kHeroWavelengths] = {};
                  int32_t back_row[kLensBatch] = {};
                  for (int i = 0; i < n; ++i) {
                      wavelengths[i][0] = nm(first + size_t(i));
                      back_row[i] = camera.glass_row(back_nm(first + size_t(i)));
                  }
                  // Toward the scene as a spectral render traces (one traced wavelength), then back.
                  camera.trace_each_wavelength(
                      raster + first, u + first, wavelengths, n, 1, nullptr,
                      [&](int, const LensRayBatch& leaving, const double*, const double*) {
                          double x[kLensBatch], y[kLensBatch];
                          bool back_alive[kLensBatch];
                          camera.film_points_from(leaving, back_row, x, y, back_alive);
                          for (int i = 0; i < n; ++i) {
                              const size_t r = first + size_t(i);
                              const bool passed = leaving.alive[i];
                              origin_mm(r, 0) = passed ? leaving.ox[i] : 0.0;
                              origin_mm(r, 1) = passed ? leaving.oy[i] : 0.0;
                              origin_mm(r, 2) = passed ? leaving.oz[i] : 0.0;
                              direction(r, 0) = passed ? leaving.dx[i] : 0.0;
                              direction(r, 1) = passed ? leaving.dy[i] : 0.0;
                              direction(r, 2) = passed ? leaving.dz[i] : 0.0;
                              alive(r) = passed && back_alive[i];
                              film_mm(r, 0) = alive(r) ? x[i] : 0.0, film_mm(r, 1) = alive(r) ? y[i] : 0.0;
                          }
                          return static_cast<const bool*>(leaving.alive);
                      });
              }
          },
          "camera"_a, "raster_px"_a, "lens"_a, "nm"_a, "back_nm"_a, "origin_mm"_a, "direction"_a, "film_mm"_a,
          "alive"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Each sample traced toward the scene at nm (the ray leaving the lens, lens frame: origin_mm, direction; "
          "0 when blocked), then traced back through the glass at back_nm to the film (film_mm, lens frame), "
          "alive where both traces pass: LensSystemCamera::film_points_from.");

    m.def("thin_band_rays",
          [](const ThinLensCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             CArray<int, -1> sample, CArray<double, -1, 3> origin, CArray<double, -1, 3> direction,
             CArray<double, -1> k_lo, CArray<double, -1> k_hi, CArray<bool, -1> whole) {
              return write_band_rays(camera, raster_px, lens, sample, origin, direction, k_lo, k_hi, whole, nullptr);
          },
          "camera"_a, "raster_px"_a, "lens"_a, "sample"_a, "origin"_a, "direction"_a, "k_lo"_a, "k_hi"_a,
          "whole"_a, nb::call_guard<nb::gil_scoped_release>(),
          "A dispersive thin lens's rays in a spectral render whose rays carry bands (cameras/thin_lens_bands.h): "
          "each ray's sample, ray (float, widened), and band of 1 / focus [k_lo, k_hi); returns the ray count.");

    m.def("lens_band_rays",
          [](const LensSystemCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             CArray<int, -1> sample, CArray<double, -1, 3> origin, CArray<double, -1, 3> direction,
             CArray<double, -1> k_lo, CArray<double, -1> k_hi, CArray<bool, -1> whole, CArray<double, -1> weight) {
              if (weight.shape(0) != sample.shape(0)) throw std::invalid_argument("as many weights as room out");
              return write_band_rays(camera, raster_px, lens, sample, origin, direction, k_lo, k_hi, whole,
                                     weight.data());
          },
          "camera"_a, "raster_px"_a, "lens"_a, "sample"_a, "origin"_a, "direction"_a, "k_lo"_a, "k_hi"_a,
          "whole"_a, "weight"_a, nb::call_guard<nb::gil_scoped_release>(),
          "A dispersive lens system's rays in a spectral render whose rays carry bands "
          "(cameras/lens_system_bands.cpp): each ray's sample, ray (float, widened), band of the dispersion "
          "parameter [k_lo, k_hi) and weight (0: vignetted); returns the ray count.");

    m.def("lens_band_shifts",
          [](const LensSystemCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             bool from_table, CArray<double, -1, 3> out, CArray<bool, -1> known) {
              if (!camera.carries_bands()) throw std::invalid_argument("the camera carries no bands");
              const size_t count = raster_px.shape(0);
              if (lens.shape(0) != count || out.shape(0) != count || known.shape(0) != count)
                  throw std::invalid_argument("as many lens samples and rows out as film points");
              for (size_t first = 0; first < count; first += kLensBatch) {
                  const int n = int(std::min<size_t>(kLensBatch, count - first));
                  double sx[kLensBatch], sy[kLensBatch], slope[kLensBatch];
                  bool ok[kLensBatch];
                  camera.band_shifts(points(raster_px) + first, points(lens) + first, n, from_table, sx, sy, slope, ok);
                  for (int i = 0; i < n; ++i) {
                      const size_t r = first + size_t(i);
                      out(r, 0) = sx[i], out(r, 1) = sy[i], out(r, 2) = slope[i], known(r) = ok[i];
                  }
              }
          },
          "camera"_a, "raster_px"_a, "lens"_a, "from_table"_a, "out"_a, "known"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "A dispersive lens system's band rays' film shift per unit of the dispersion parameter (mm, lens frame) "
          "and clearance slope, per sample (out: x, y, slope), from the band table or traced back at 380 nm; "
          "known false where that source cannot answer or the ray is blocked at d.");

    m.def("focus_band_map",
          [](CArray<const double, -1, 3> basis, CArray<const double, -1, 3> film,
             std::vector<std::array<float, 3>> light_intensities, std::vector<double> inverse_focus_per_m_by_nm,
             int table, double k_lo, double k_hi) {
              if (basis.shape(0) != film.shape(0) || basis.shape(0) < 2)
                  throw std::invalid_argument("basis and film: one row per nm from 380 nm, alike");
              if (table < 0 || table > int(light_intensities.size()))
                  throw std::invalid_argument("table: 0 (the basis) or 1 + a light's index");
              SpectralTables spectra;
              for (size_t j = 0; j < basis.shape(0); ++j) {
                  spectra.basis.push_back({float(basis(j, 0)), float(basis(j, 1)), float(basis(j, 2))});
                  spectra.film.push_back({float(film(j, 0)), float(film(j, 1)), float(film(j, 2))});
              }
              std::vector<Vec3f> intensities;
              for (const auto& i : light_intensities) intensities.push_back({i[0], i[1], i[2]});
              const FocusBandIntegrals integrals(spectra, intensities, inverse_focus_per_m_by_nm);
              const FocusBandIntegrals::End lo = integrals.end_at(k_lo), hi = integrals.end_at(k_hi);
              std::array<std::array<float, 3>, 3> map{};  // [k][c]
              for (int c = 0; c < 3; ++c) {
                  float colour[3] = {0.0f, 0.0f, 0.0f}, out[3];
                  colour[c] = 1.0f;
                  integrals.apply(table, lo, hi, colour[0], colour[1], colour[2], out);
                  for (int k = 0; k < 3; ++k) map[size_t(k)][size_t(c)] = out[k];
              }
              return map;
          },
          "basis"_a, "film"_a, "light_intensities"_a, "inverse_focus_per_m_by_nm"_a, "table"_a, "k_lo"_a, "k_hi"_a,
          "The film's reading over the wavelengths whose 1 / focus lies in [k_lo, k_hi) (spectral_bands.h's "
          "FocusBandIntegrals): map[k][c] of basis colour c, table 0, or lit by light table - 1.");

    m.def("dispersion_band",
          [](const ThinLensCamera& camera, double k_lo, double k_hi) {
              if (!camera.carries_bands()) throw std::invalid_argument("the camera carries no bands");
              WavelengthBand band;
              camera.band_runs().band_of(k_lo, k_hi, &band);
              std::vector<std::pair<float, float>> out;
              for (int r = 0; r < band.count; ++r) out.emplace_back(band.from_nm[r], band.to_nm[r]);
              return out;
          },
          "camera"_a, "k_lo"_a, "k_hi"_a,
          "The wavelength intervals (nm) whose 1 / focus lies in [k_lo, k_hi) (DispersionRuns::band_of).");

    m.def("generate_thin_rays_sharing",
          [](const ThinLensCamera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens,
             CArray<const float, -1, kHeroWavelengths> nm, bool batched, CArray<double, -1, 3> origin,
             CArray<double, -1, 3> direction, CArray<bool, -1> own) {
              const size_t count = raster_px.shape(0);
              if (!camera.disperses())
                  throw std::invalid_argument("the camera does not disperse: set_dispersion first");
              if (lens.shape(0) != count || nm.shape(0) != count || origin.shape(0) != count * kHeroWavelengths ||
                  direction.shape(0) != count * kHeroWavelengths || own.shape(0) != count * kHeroWavelengths)
                  throw std::invalid_argument("one row per sample, kHeroWavelengths rays per sample");
              const Point2f* raster = points(raster_px);
              const Point2f* u = points(lens);
              for (size_t first = 0; first < count; first += kCameraBatch) {
                  const int n = int(std::min<size_t>(kCameraBatch, count - first));
                  HeroWavelengths w[kCameraBatch] = {};
                  for (int i = 0; i < n; ++i)
                      for (int k = 0; k < kHeroWavelengths; ++k) w[i].nm[k] = nm(first + size_t(i), size_t(k));
                  MaybeRay rays[kCameraBatch][kHeroWavelengths];
                  bool owns[kHeroWavelengths][kCameraBatch];
                  if (batched) {
                      CameraRayRows rows[kHeroWavelengths];
                      camera.generate_shared_ray_rows(raster + first, u + first, w, n, rows, owns);
                      for (int k = 0; k < kHeroWavelengths; ++k)
                          for (int i = 0; i < n; ++i) {
                              const CameraRayRows& r = rows[owns[k][i] ? k : 0];
                              rays[i][k] = CameraRay{{r.origin[0][i], r.origin[1][i], r.origin[2][i]},
                                                     {r.direction[0][i], r.direction[1][i], r.direction[2][i]},
                                                     1.0f};
                          }
                  } else {
                      for (int i = 0; i < n; ++i) {
                          bool shares[kHeroWavelengths];
                          camera.generate_rays_sharing(raster[first + i], u[first + i], w[i].nm, rays[i], shares);
                          for (int k = 0; k < kHeroWavelengths; ++k) owns[k][i] = k == 0 || !shares[k];
                      }
                  }
                  for (int i = 0; i < n; ++i)
                      for (int k = 0; k < kHeroWavelengths; ++k) {
                          const size_t row = (first + size_t(i)) * kHeroWavelengths + size_t(k);
                          // (a thin lens's rays are never vignetted)
                          const Vec3d o = rays[i][k]->origin, d = rays[i][k]->direction;
                          origin(row, 0) = o.x, origin(row, 1) = o.y, origin(row, 2) = o.z;
                          direction(row, 0) = d.x, direction(row, 1) = d.y, direction(row, 2) = d.z;
                          own(row) = owns[k][i];
                      }
              }
          },
          "camera"_a, "raster_px"_a, "lens"_a, "nm"_a, "batched"_a, "origin"_a, "direction"_a, "own"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "A dispersive thin lens's rays at each sample's four wavelengths (row i * 4 + k: nm[i, k], k = 0 the "
          "hero), by the one-sample generate_rays_sharing or (batched) the spectral render's "
          "generate_shared_ray_rows; own: the sample traces that ray (the hero's always, a secondary's where it "
          "does not share the hero's).");

    m.def("lens_pencil",
          [](const LensSystemCamera& camera, double x0_px, double y0_px, double x1_px, double y1_px)
              -> std::optional<std::tuple<std::array<double, 2>, std::array<double, 2>, double, double>> {
              CameraPencil pencil;
              LensPencilCheck check;
              if (!camera.checked_pencil(x0_px, y0_px, x1_px, y1_px, &pencil, &check)) return std::nullopt;
              return std::make_tuple(std::array<double, 2>{pencil.screen_lo[0], pencil.screen_lo[1]},
                                     std::array<double, 2>{pencil.screen_hi[0], pencil.screen_hi[1]},
                                     pencil.lens_radius_m, pencil.inverse_focus_per_m);
          },
          "camera"_a, "x0_px"_a, "y0_px"_a, "x1_px"_a, "y1_px"_a,
          "The measured pencil of the rays through a raster rectangle (lens_pencil.h) as (screen_lo, screen_hi, "
          "lens_radius_m, inverse_focus_per_m), or None where the camera has none.");

    m.def("set_lens_pencils",
          [](LensSystemCamera& camera, const std::string& mode) {
              if (mode != "none" && mode != "measured" && mode != "collapsed")
                  throw std::invalid_argument("pencils: \"measured\", \"collapsed\" or \"none\", not " + mode);
              // The band rays' (open trace) alike, where the camera carries bands.
              camera.pencils = camera.band_pencils = nullptr;
              if (mode == "none") return;
              camera.pencils = LensPencils::of(camera);
              if (camera.carries_bands()) camera.band_pencils = LensPencils::of(camera, true);
              if (mode == "collapsed") {
                  camera.pencils = camera.pencils->collapsed();
                  if (camera.band_pencils) camera.band_pencils = camera.band_pencils->collapsed();
              }
          },
          "camera"_a, "mode"_a,
          "The camera's per-tile pencils (lens_pencil.h), and its band rays' where it carries bands: "
          "\"measured\" (the render's), \"collapsed\" (every screen range shrunk to a point, so the render's "
          "check falls back nearly everywhere) or \"none\".");

    m.def("lens_rays_within_pencil",
          [](const LensSystemCamera& camera, double x0_px, double y0_px, double x1_px, double y1_px,
             CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens) {
              CameraPencil pencil;
              LensPencilCheck check;
              if (!camera.checked_pencil(x0_px, y0_px, x1_px, y1_px, &pencil, &check))
                  throw std::invalid_argument("no pencil for this rectangle");
              const size_t count = raster_px.shape(0);
              if (lens.shape(0) != count) throw std::invalid_argument("one lens sample per raster sample");
              // Batch by batch, as the render checks them: the batches whose rays all lie within.
              size_t within = 0, batches = 0;
              if (camera.carries_bands()) {  // each batch's own rays and its split rays (render_tile_bands.h)
                  for (size_t first = 0; first < count; first += kCameraBatch) {
                      const int n = int(std::min<size_t>(kCameraBatch, count - first));
                      BandRays rays;
                      const bool own = camera.band_rays(points(raster_px) + first, points(lens) + first, n, &rays,
                                                        &check);
                      within += own && camera.trace_split_rays(&rays, &check), ++batches;
                  }
                  return std::make_tuple(within, batches);
              }
              for_each_ray_rows_batch(camera, points(raster_px), points(lens), count, &check,
                                      [&](size_t, int, const CameraRayRows&, const float*, const bool*,
                                          bool batch_within) { within += batch_within, ++batches; });
              return std::make_tuple(within, batches);
          },
          "camera"_a, "x0_px"_a, "y0_px"_a, "x1_px"_a, "y1_px"_a, "raster_px"_a, "lens"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "(batches whose rays all lie within the rectangle's pencil, batches) for these samples, "
          "kLensBatch at a time, as the render checks them.");

    m.def("with_brute_force_pupil", &with_brute_force_pupil, "camera"_a, nb::call_guard<nb::gil_scoped_release>(),
          "A copy of camera that aims at a disk 1.5x the rear element: the pupil sampler's reference.");
}

// Which batch lens trace a camera runs: all give the same bits; tests and benchmarks compare them.
void bind_trace_kernels(nb::module_& m) {
    m.def("lens_trace_kernels", [] { return kLensTraceFamily.names(); },
          "The batch lens-trace kernels this CPU runs, slowest first.");

    m.def("lens_trace_kernel",
          [](const LensSystemCamera& camera) { return std::string(lens_trace_kernel_name(camera.trace_kernel)); },
          "camera"_a, "The batch lens-trace kernel camera runs (the fastest this CPU runs unless set).");

    m.def("set_lens_trace_kernel",
          [](LensSystemCamera& camera, const std::string& name) {
              camera.trace_kernel = kLensTraceFamily.named(name, "trace_kernel", "kernel");
          },
          "camera"_a, "kernel"_a, "Makes camera run the named batch lens-trace kernel.");

    m.def("lens_trace_precision",
          [](const LensSystemCamera& camera) {
              return std::string(camera.trace_precision == LensTracePrecision::Single ? "single" : "double");
          },
          "camera"_a, "The precision of camera's batch lens trace: \"single\" (the render's) or \"double\".");

    m.def("set_lens_trace_precision",
          [](LensSystemCamera& camera, const std::string& precision) {
              if (precision != "single" && precision != "double")
                  throw std::invalid_argument("trace_precision: \"single\" or \"double\", not " + precision);
              camera.trace_precision = precision == "single" ? LensTracePrecision::Single : LensTracePrecision::Double;
          },
          "camera"_a, "precision"_a, "Makes camera's batch lens trace run in \"single\" or \"double\" precision.");
}

void bind_raw_throughput(nb::module_& m) {
    m.def("raw_primary_throughput",
          [](const Scene& scene, const PinholeCamera& camera, int spp, int threads) {
              RawThroughput r = measure_raw_primary_throughput(scene, camera, spp, threads);
              return std::make_tuple(r.seconds, r.rays, r.hits);
          },
          "scene"_a, "camera"_a, "spp"_a, "threads"_a, nb::call_guard<nb::gil_scoped_release>(),
          "(seconds, rays, hits) of bare pinhole rays (Embree and the own sphere test), no shading: the ceiling of a render.");
}

// The render's culling test for moving geometry, on rays in groups of one packet.
void bind_motion_culling(nb::module_& m) {
    m.def("moving_spheres_may_hit",
          [](CArray<const float, -1, 7> spheres, CArray<const float, -1, 3> origin,
             CArray<const float, -1, 3> direction, CArray<const float, -1> t_max, CArray<const float, -1> time,
             CArray<bool, -1> out) {
              constexpr int N = SweptBounds::kLanes;
              const size_t n = origin.shape(0);
              if (direction.shape(0) != n || t_max.shape(0) != n || time.shape(0) != n || out.shape(0) != n)
                  throw std::invalid_argument("origin, direction, t_max, time and out need one row per ray");
              for (size_t first = 0; first < n; first += N) {
                  float lanes[7][N];
                  int active[N], hit[N];
                  for (int i = 0; i < N; ++i) {
                      const size_t r = std::min(first + size_t(i), n - 1);
                      for (int a = 0; a < 3; ++a) lanes[a][i] = origin(r, a), lanes[3 + a][i] = direction(r, a);
                      lanes[6][i] = t_max(r);
                      active[i] = first + size_t(i) < n;
                  }
                  float times[N];
                  for (int i = 0; i < N; ++i) times[i] = time(std::min(first + size_t(i), n - 1));
                  const float* o[3] = {lanes[0], lanes[1], lanes[2]};
                  const float* d[3] = {lanes[3], lanes[4], lanes[5]};
                  moving_spheres_met(spheres.data(), int(spheres.shape(0)), o, d, lanes[6], times, active, hit);
                  for (int i = 0; i < N && first + size_t(i) < n; ++i) out(first + size_t(i)) = hit[i] != 0;
              }
          },
          "spheres"_a, "origin"_a, "direction"_a, "t_max"_a, "time"_a, "out"_a,
          "out[i]: whether ray i (segment origin + t direction, t in [0, t_max], at shutter time time[i] in [0, 1)) "
          "may meet a sphere (rows: centre at open xyz, centre at close xyz, radius, m) by the render's culling "
          "test; False means the render does not ask Embree.");
}

// The render's own sphere test (sphere_lanes.h), on rays in groups of one packet, by any kernel.
SphereKernel sphere_kernel_named(const std::string& name) {
    return kSphereFamily.named(name, "kernel", "sphere kernel");
}

// Rays [first, first + kSphereLanes) of origin, direction and t_far as one
// packet's lanes, as the own-primitive tests take them: past the last row the
// last ray again, inactive.
struct RayLanes {
    float xyz[6][kSphereLanes], t_far[kSphereLanes];
    int active[kSphereLanes];
    const float* origin[3] = {xyz[0], xyz[1], xyz[2]};
    const float* direction[3] = {xyz[3], xyz[4], xyz[5]};
    RayLanes(const RayLanes&) = delete;
    RayLanes(CArray<const float, -1, 3> o, CArray<const float, -1, 3> d, const float* t, size_t first) {
        const size_t n = o.shape(0);
        for (int i = 0; i < kSphereLanes; ++i) {
            const size_t r = std::min(first + size_t(i), n - 1);
            for (int a = 0; a < 3; ++a) xyz[a][i] = o(r, a), xyz[3 + a][i] = d(r, a);
            t_far[i] = t[r];
            active[i] = first + size_t(i) < n;
        }
    }
};

void bind_own_spheres(nb::module_& m) {
    m.def("shading_kernel", [] { return std::string(shading_kernel_name(shading_kernel())); },
          "The instruction set the render's shading lanes run with (shading_lanes.h): the CPU's best, or "
          "LENSCOMPARE_SHADING_KERNEL's choice when this CPU can run it.");

    m.def("sphere_kernels", [] { return kSphereFamily.names(); },
          "The own-sphere kernels this CPU runs, slowest first.");

    m.def("own_spheres_closest",
          [](CArray<const float, -1, 4> spheres, CArray<const float, -1, 3> origin, CArray<const float, -1, 3> direction,
             CArray<float, -1> t_far, CArray<int32_t, -1> index, CArray<float, -1, 3> normal, const std::string& kernel) {
              constexpr int N = kSphereLanes;
              const SphereKernel k = sphere_kernel_named(kernel);
              const size_t n = origin.shape(0);
              if (direction.shape(0) != n || t_far.shape(0) != n || index.shape(0) != n || normal.shape(0) != n)
                  throw std::invalid_argument("origin, direction, t_far, index and normal need one row per ray");
              for (size_t first = 0; first < n; first += N) {
                  RayLanes lanes(origin, direction, t_far.data(), first);
                  float nrm[3][N];
                  int idx[N];
                  float* const nn[3] = {nrm[0], nrm[1], nrm[2]};
                  spheres_closest(k, spheres.data(), int(spheres.shape(0)), lanes.origin, lanes.direction,
                                  lanes.active, lanes.t_far, idx, nn);
                  for (int i = 0; i < N && first + size_t(i) < n; ++i) {
                      const size_t r = first + size_t(i);
                      t_far(r) = lanes.t_far[i], index(r) = idx[i];
                      for (int a = 0; a < 3; ++a) normal(r, a) = idx[i] < 0 ? 0.0f : nrm[a][i];
                  }
              }
          },
          "spheres"_a, "origin"_a, "direction"_a, "t_far"_a, "index"_a, "normal"_a, "kernel"_a,
          "Closest hits at t in [0, t_far) with spheres (rows: centre xyz, radius, m): t_far, index (-1: none) "
          "and the outward unit normal, in place, as the render's camera rays get them.");

    m.def("own_spheres_occluded",
          [](CArray<const float, -1, 4> spheres, CArray<const float, -1, 3> origin, CArray<const float, -1, 3> direction,
             CArray<const float, -1> t_far, CArray<const int32_t, -1> start_sphere, CArray<const bool, -1> self_blocks,
             CArray<bool, -1> out, const std::string& kernel) {
              constexpr int N = kSphereLanes;
              const SphereKernel k = sphere_kernel_named(kernel);
              const size_t n = origin.shape(0);
              if (direction.shape(0) != n || t_far.shape(0) != n || start_sphere.shape(0) != n ||
                  self_blocks.shape(0) != n || out.shape(0) != n)
                  throw std::invalid_argument("origin, direction, t_far, start_sphere, self_blocks and out need one row per ray");
              for (size_t first = 0; first < n; first += N) {
                  RayLanes lanes(origin, direction, t_far.data(), first);
                  int start[N], self[N], blocked[N];
                  for (int i = 0; i < N; ++i) {
                      const size_t r = std::min(first + size_t(i), n - 1);
                      start[i] = start_sphere(r), self[i] = self_blocks(r);
                  }
                  spheres_occluded(k, spheres.data(), int(spheres.shape(0)), lanes.origin, lanes.direction,
                                   lanes.t_far, start, self, lanes.active, blocked);
                  for (int i = 0; i < N && first + size_t(i) < n; ++i) out(first + size_t(i)) = blocked[i] != 0;
              }
          },
          "spheres"_a, "origin"_a, "direction"_a, "t_far"_a, "start_sphere"_a, "self_blocks"_a, "out"_a, "kernel"_a,
          "out[i]: whether segment i (t in [0, t_far]) crosses a sphere's surface, as the render's shadow rays "
          "see it; a ray starting on sphere start_sphere[i] (-1: none) is blocked by it only if self_blocks[i].");
}

std::vector<OwnQuad> own_quads_from(CArray<const float, -1, 4, 3> corners) {
    std::vector<OwnQuad> quads(corners.shape(0));
    for (size_t k = 0; k < quads.size(); ++k)
        if (!make_own_quad(corners.data() + 12 * k, &quads[k]))
            throw std::invalid_argument("quads: quad " + std::to_string(k) + " is not a parallelogram with area");
    widen_shared_sides(corners.data(), int(quads.size()), quads.data());
    return quads;
}

void bind_own_quads(nb::module_& m) {
    m.def("own_quads_closest",
          [](CArray<const float, -1, 4, 3> corners, CArray<const float, -1, 3> origin,
             CArray<const float, -1, 3> direction, CArray<float, -1> t_far, CArray<int32_t, -1> index,
             const std::string& kernel, int first_quad) {
              constexpr int N = kSphereLanes;
              const SphereKernel k = sphere_kernel_named(kernel);
              const std::vector<OwnQuad> quads = own_quads_from(corners);
              if (first_quad < 0 || (first_quad > 0 && size_t(first_quad) >= quads.size()))
                  throw std::invalid_argument("first_quad: " + std::to_string(first_quad) + " is not a quad");
              int tested_first = first_quad;  // then the quad the last packet met, as in a render
              const size_t n = origin.shape(0);
              if (direction.shape(0) != n || t_far.shape(0) != n || index.shape(0) != n)
                  throw std::invalid_argument("origin, direction, t_far and index need one row per ray");
              for (size_t first = 0; first < n; first += N) {
                  RayLanes lanes(origin, direction, t_far.data(), first);
                  float nrm[3][N];
                  int idx[N];
                  float* const nn[3] = {nrm[0], nrm[1], nrm[2]};
                  quads_closest(k, quads.data(), int(quads.size()), lanes.origin, lanes.direction, lanes.active,
                                lanes.t_far, idx, nn, &tested_first);
                  for (int i = 0; i < N && first + size_t(i) < n; ++i)
                      t_far(first + size_t(i)) = lanes.t_far[i], index(first + size_t(i)) = idx[i];
              }
          },
          "corners"_a, "origin"_a, "direction"_a, "t_far"_a, "index"_a, "kernel"_a, "first_quad"_a = 0,
          "Closest hits at t in [0, t_far) with parallelograms (corners in order round each, xyz): t_far and "
          "index (-1: none), in place, as the render's camera rays get them; first_quad is tested first.");

    m.def("solid_faces_first_hits",
          [](CArray<const float, -1, 4, 3> corners, CArray<const int32_t, -1> solid,
             CArray<const float, -1, 3> origin) {
              if (solid.shape(0) != corners.shape(0)) throw std::invalid_argument("one solid id per quad expected");
              const size_t n = origin.shape(0);
              if (n == 0 || n > size_t(kSphereLanes))
                  throw std::invalid_argument("1 to " + std::to_string(kSphereLanes) + " origins (one packet)");
              const SolidFaces faces(corners.data(), solid.data(), int(corners.shape(0)));
              float rows[3][kSphereLanes] = {};
              int active[kSphereLanes] = {};
              for (size_t i = 0; i < n; ++i) {
                  for (int a = 0; a < 3; ++a) rows[a][i] = origin(i, size_t(a));
                  active[i] = -1;
              }
              const float* const o[3] = {rows[0], rows[1], rows[2]};
              OriginRegion region;  // fresh: the packet's own box
              return faces.first_hits_from(o, active, &region);
          },
          "corners"_a, "solid"_a, "origin"_a,
          "Bit k set: quad k (a face of closed convex solid solid[k], or -1 alone) may be the first hit of a ray "
          "from one of the origins (one packet); the render's camera-ray cull.");

    m.def("solid_faces_blocking",
          [](CArray<const float, -1, 4, 3> corners, CArray<const int32_t, -1> solid,
             const std::array<double, 3>& light_m) {
              if (solid.shape(0) != corners.shape(0)) throw std::invalid_argument("one solid id per quad expected");
              const SolidFaces faces(corners.data(), solid.data(), int(corners.shape(0)));
              const float light[3] = {float(light_m[0]), float(light_m[1]), float(light_m[2])};
              return faces.blocking_toward(light);
          },
          "corners"_a, "solid"_a, "light_m"_a,
          "Bit k set: quad k may block a segment that ends at light_m; the render's shadow-ray cull.");

    m.def("own_quads_occluded",
          [](CArray<const float, -1, 4, 3> corners, CArray<const float, -1, 3> origin,
             CArray<const float, -1, 3> direction, CArray<const float, -1> t_far, CArray<bool, -1> out,
             const std::string& kernel) {
              constexpr int N = kSphereLanes;
              const SphereKernel k = sphere_kernel_named(kernel);
              const std::vector<OwnQuad> quads = own_quads_from(corners);
              const size_t n = origin.shape(0);
              if (direction.shape(0) != n || t_far.shape(0) != n || out.shape(0) != n)
                  throw std::invalid_argument("origin, direction, t_far and out need one row per ray");
              for (size_t first = 0; first < n; first += N) {
                  RayLanes lanes(origin, direction, t_far.data(), first);
                  int blocked[N];
                  quads_occluded(k, quads.data(), int(quads.size()), lanes.origin, lanes.direction, lanes.t_far,
                                 lanes.active, blocked);
                  for (int i = 0; i < N && first + size_t(i) < n; ++i) out(first + size_t(i)) = blocked[i] != 0;
              }
          },
          "corners"_a, "origin"_a, "direction"_a, "t_far"_a, "out"_a, "kernel"_a,
          "out[i]: whether segment i (t in [0, t_far]) crosses a parallelogram, as the render's shadow rays see it.");
}

// Whether each ball (rows: centre xyz, radius, m) may meet a ray the camera
// sends through raster rectangle [x0, x1] x [y0, y1]: the render's per-tile cull.
template <class Camera>
void pencil_may_meet(const Camera& camera, double x0_px, double y0_px, double x1_px, double y1_px,
                     CArray<const float, -1, 4> balls, CArray<bool, -1> out) {
    if (out.shape(0) != balls.shape(0)) throw std::invalid_argument("out needs one entry per ball");
    CameraPencil pencil;
    const bool bounded = camera.pencil(x0_px, y0_px, x1_px, y1_px, &pencil);
    for (size_t k = 0; k < balls.shape(0); ++k)
        out(k) = !bounded || pencil.may_meet_ball(balls.data() + 4 * k, balls(k, 3));
}

void bind_batched_cameras(nb::module_& m) {
    const char* pencil_doc = "Whether each ball may meet a camera ray through a raster rectangle (the per-tile cull).";
    m.def("pencil_may_meet", &pencil_may_meet<PinholeCamera>, "camera"_a, "x0_px"_a, "y0_px"_a, "x1_px"_a,
          "y1_px"_a, "balls"_a, "out"_a, pencil_doc);
    m.def("pencil_may_meet", &pencil_may_meet<ThinLensCamera>, "camera"_a, "x0_px"_a, "y0_px"_a, "x1_px"_a,
          "y1_px"_a, "balls"_a, "out"_a, pencil_doc);
    const char* doc = "The render loop's batch of camera rays (kCameraBatch at a time; the same bits as generate_rays).";
    m.def("generate_rays_batched", &generate_rays_batched<PinholeCamera>, "camera"_a, "raster_px"_a, "lens"_a,
          "origin"_a, "direction"_a, "weight"_a, nb::call_guard<nb::gil_scoped_release>(), doc);
    m.def("generate_rays_batched", &generate_rays_batched<ThinLensCamera>, "camera"_a, "raster_px"_a, "lens"_a,
          "origin"_a, "direction"_a, "weight"_a, nb::call_guard<nb::gil_scoped_release>(), doc);
}

}  // namespace

void bind_diagnostics(nb::module_& m) {
    bind_batched_cameras(m);
    bind_own_spheres(m);
    bind_own_quads(m);
    bind_motion_culling(m);
    bind_samplers(m);
    bind_lens(m);
    bind_trace_kernels(m);
    bind_raw_throughput(m);
}

}  // namespace lc
