// Python bindings for the private module lenscompare._native. Only hot loops
// live here; Python validates every argument before it reaches this file.
// Hooks for tests and benchmarks live in the submodule
// lenscompare._native.diagnostics (bindings_diagnostics.cpp).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <array>
#include <cmath>
#include <optional>
#include <algorithm>
#include <memory>
#include <type_traits>
#include <utility>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <stdexcept>
#include <vector>

#include "aperture.h"
#include "bindings_arrays.h"
#include "cameras/composite.h"
#include "cameras/lens_system.h"
#include "cameras/pinhole.h"
#include "cameras/thick_lens.h"
#include "cameras/thin_lens.h"
#include "depth.h"
#include "postfilter.h"
#include "render.h"
#include "samplers.h"
#include "scene.h"

namespace nb = nanobind;
using namespace nb::literals;
using namespace lc;

namespace {

using Triple = std::array<double, 3>;
using Pair = std::array<double, 2>;

Vec3d vec(const Triple& t) { return {t[0], t[1], t[2]}; }
Vec3f vecf(const float* p) { return {p[0], p[1], p[2]}; }

Frame make_frame(const Triple& origin, const Triple& right, const Triple& up, const Triple& forward) {
    return Frame{vec(origin), vec(right), vec(up), vec(forward)};
}

// LENSCOMPARE_LENS_MIRRORS=1: new lens systems mirror their rays wherever
// their stop is symmetric (render_mirrored.h); otherwise only when asked.
bool mirrors_enabled() {
    const char* text = std::getenv("LENSCOMPARE_LENS_MIRRORS");
    return text && std::string(text) == "1";
}

FilmToScreen make_film(int width_px, int height_px, double screen_half_width, double screen_half_height) {
    return FilmToScreen{width_px, height_px, screen_half_width, screen_half_height};
}

SceneArrays scene_arrays(CArray<const float, -1, 4> spheres, CArray<const int32_t, -1> sphere_material,
                  CArray<const float, -1, 4, 3> quads, CArray<const int32_t, -1> quad_material,
                  CArray<const int32_t, -1> material_kind, CArray<const float, -1, 3> material_color,
                  CArray<const float, -1, 3> material_emission, CArray<const float, -1, 3> checker_color,
                  CArray<const float, -1> checker_size_m, CArray<const float, -1, 3> light_position_m,
                  CArray<const float, -1, 3> light_intensity, const Triple& background,
                  CArray<const int32_t, -1> light_inverse_square, CArray<const float, -1, 3> triangle_vertices,
                  CArray<const int32_t, -1, 3> triangles, CArray<const int32_t, -1> triangle_material,
                  const std::optional<CArray<const float, -1, 3>>& sphere_velocity,
                  const std::optional<CArray<const float, -1, 3>>& quad_velocity,
                  const std::optional<CArray<const float, -1, 3>>& vertex_velocity, const Pair& shutter_s,
                  const Triple& camera_velocity, const std::optional<CArray<const int32_t, -1>>& quad_solid) {
    SceneArrays a;
    a.spheres = spheres.data();
    a.sphere_material = sphere_material.data();
    a.n_spheres = int(spheres.shape(0));
    a.quads = quads.data();
    a.quad_material = quad_material.data();
    a.n_quads = int(quads.shape(0));
    for (size_t i = 0; i < material_kind.shape(0); ++i) {
        a.materials.push_back(Material{MaterialKind(material_kind(i)), vecf(&material_color(i, 0)),
                                       vecf(&material_emission(i, 0)), vecf(&checker_color(i, 0)), checker_size_m(i)});
    }
    for (size_t i = 0; i < light_position_m.shape(0); ++i)
        a.lights.push_back(PointLight{vecf(&light_position_m(i, 0)), vecf(&light_intensity(i, 0)),
                                      light_inverse_square(i) != 0});
    a.triangle_vertices = triangle_vertices.data();
    a.n_vertices = int(triangle_vertices.shape(0));
    a.triangles = triangles.data();
    a.triangle_material = triangle_material.data();
    a.n_triangles = int(triangles.shape(0));
    a.background = Vec3f(vec(background));
    // Motion: velocities must match their primitives (Python checks; this guards the pointers).
    auto velocities = [](const std::optional<CArray<const float, -1, 3>>& v, size_t n) -> const float* {
        if (!v) return nullptr;
        if (v->shape(0) != n) throw std::invalid_argument("one velocity per primitive expected");
        return v->data();
    };
    a.sphere_velocity = velocities(sphere_velocity, size_t(a.n_spheres));
    a.quad_velocity = velocities(quad_velocity, size_t(a.n_quads));
    if (quad_solid) {
        if (quad_solid->shape(0) != size_t(a.n_quads)) throw std::invalid_argument("one solid id per quad expected");
        a.quad_solid = quad_solid->data();
    }
    a.vertex_velocity = velocities(vertex_velocity, size_t(a.n_vertices));
    if (!(shutter_s[1] >= shutter_s[0])) throw std::invalid_argument("shutter closes before it opens");
    a.motion.open_s = shutter_s[0];
    a.motion.close_s = shutter_s[1];
    a.motion.camera_velocity_m_per_s = vec(camera_velocity);
    a.motion.anything_moves = a.motion.moves_camera() || a.sphere_velocity || a.quad_velocity || a.vertex_velocity;
    return a;
}

template <class Camera>
std::pair<int, int> resolution_px(const Camera& camera) {
    if constexpr (std::is_same_v<Camera, LensSystemCamera>)
        return {camera.width_px, camera.height_px};
    else if constexpr (std::is_same_v<Camera, ThickLensCamera>)
        return resolution_px(camera.at_front_principal_plane);
    else if constexpr (std::is_same_v<Camera, CompositeCamera>)
        return resolution_px(camera.lens);
    else
        return {camera.film.width_px, camera.film.height_px};
}

// Settings for rendering rows [row_begin, row_end) of out, checked against the camera.
template <class Camera>
RenderSettings checked_settings(const Camera& camera, const CArray<float, -1, -1, 3>& out, int sampler, uint64_t seed,
                                int threads, int row_begin, int row_end) {
    RenderSettings s;
    s.width_px = int(out.shape(1));
    s.height_px = int(out.shape(0));
    s.sampler = SamplerKind(sampler);
    s.seed = seed;
    s.threads = threads;
    if (std::make_pair(s.width_px, s.height_px) != resolution_px(camera))
        throw std::invalid_argument("output array does not match the camera's resolution");
    if (row_begin < 0 || row_end > s.height_px || row_begin > row_end) throw std::invalid_argument("bad row range");
    return s;
}

template <class Camera>
std::tuple<uint64_t, uint64_t> render_rows_py(const Scene& scene, const Camera& camera, int spp, int sampler,
                                              uint64_t seed, int threads, int row_begin, int row_end,
                                              CArray<float, -1, -1, 3> out,
                                              std::optional<CArray<float, -1, -1>> variance_of_mean,
                                              bool mirror_rows) {
    RenderSettings s = checked_settings(camera, out, sampler, seed, threads, row_begin, row_end);
    s.spp = spp;
    if (variance_of_mean) {
        if (variance_of_mean->shape(0) != out.shape(0) || variance_of_mean->shape(1) != out.shape(1))
            throw std::invalid_argument("variances must have the image's shape");
        s.variance_of_mean = variance_of_mean->data();
    }
    RenderStats stats = render_rows(scene, camera, s, row_begin, row_end, out.data(), mirror_rows);
    return {stats.samples, stats.rays_passed};
}

// The adaptive passes: per-pixel sample counts (samples [first_sample, end)
// of each pixel), and the variance of each pixel's mean as a second output.
template <class Camera>
std::tuple<uint64_t, uint64_t> render_rows_adaptive_py(const Scene& scene, const Camera& camera,
                                                       CArray<const uint32_t, -1, -1> sample_end, int first_sample,
                                                       int sampler, uint64_t seed, int threads, int row_begin,
                                                       int row_end, CArray<float, -1, -1, 3> out,
                                                       CArray<float, -1, -1> variance_of_mean,
                                                       bool mirror_rows) {
    RenderSettings s = checked_settings(camera, out, sampler, seed, threads, row_begin, row_end);
    if (sample_end.shape(0) != out.shape(0) || sample_end.shape(1) != out.shape(1) ||
        variance_of_mean.shape(0) != out.shape(0) || variance_of_mean.shape(1) != out.shape(1))
        throw std::invalid_argument("sample counts and variances must have the image's shape");
    for (size_t i = 0; i < sample_end.shape(0) * sample_end.shape(1); ++i)
        if (sample_end.data()[i] > (1u << 20)) throw std::invalid_argument("more than 2^20 samples for one pixel");
    s.first_sample = std::max(first_sample, 0);
    s.sample_end = sample_end.data();
    s.variance_of_mean = variance_of_mean.data();
    s.spp = 1;  // unused with sample_end; the per-tile sample buffers grow as needed
    RenderStats stats = render_rows(scene, camera, s, row_begin, row_end, out.data(), mirror_rows);
    return {stats.samples, stats.rays_passed};
}

// Rays for explicit samples, for geometric tests of a camera from Python.
template <class Camera>
void generate_rays_py(const Camera& camera, CArray<const float, -1, 2> raster_px, CArray<const float, -1, 2> lens_sample,
                      CArray<double, -1, 3> origin, CArray<double, -1, 3> direction, CArray<float, -1> weight) {
    for (size_t i = 0; i < raster_px.shape(0); ++i)
        store_ray(camera.generate_ray({raster_px(i, 0), raster_px(i, 1)}, {lens_sample(i, 0), lens_sample(i, 1)}), i,
                  origin, direction, weight);
}

template <class Camera>
void bind_camera_functions(nb::module_& m) {
    m.def("render_rows", &render_rows_py<Camera>, "scene"_a, "camera"_a, "spp"_a, "sampler"_a, "seed"_a, "threads"_a,
          "row_begin"_a, "row_end"_a, "out"_a, "variance_of_mean"_a = nb::none(), "mirror_rows"_a = false,
          nb::call_guard<nb::gil_scoped_release>(),
          "Renders rows [row_begin, row_end) (and with mirror_rows their mirror images, rows height-1-y) into "
          "out with spp samples per pixel, and optionally each pixel mean's variance; (samples, rays passed).");
    m.def("render_rows_adaptive", &render_rows_adaptive_py<Camera>, "scene"_a, "camera"_a, "sample_end"_a,
          "first_sample"_a, "sampler"_a, "seed"_a, "threads"_a, "row_begin"_a, "row_end"_a, "out"_a,
          "variance_of_mean"_a, "mirror_rows"_a = false, nb::call_guard<nb::gil_scoped_release>(),
          "Renders rows (as render_rows) with each pixel's samples [first_sample, sample_end), and its mean's "
          "variance; (samples, rays passed).");
    m.def("generate_rays", &generate_rays_py<Camera>, "camera"_a, "raster_px"_a, "lens_sample"_a, "origin"_a,
          "direction"_a, "weight"_a, nb::call_guard<nb::gil_scoped_release>(),
          "The camera's ray for each (raster_px, lens_sample) row into origin, direction, weight (0: vignetted).");
}

// A radial table from Python: empty, or at least two finite values >= 0.
RadialTable radial_table(CArray<const double, -1> values, double radius_step_mm, const char* name) {
    RadialTable table;
    table.radius_step_mm = radius_step_mm;
    if (values.shape(0) == 0) return table;
    if (values.shape(0) < 2) throw std::invalid_argument(std::string(name) + ": a table needs two values or none");
    for (size_t i = 0; i < values.shape(0); ++i) {
        if (!(std::isfinite(values(i)) && values(i) >= 0.0))
            throw std::invalid_argument(std::string(name) + ": values must be finite and >= 0");
        table.values.push_back(values(i));
    }
    return table;
}

void render_depth_py(const Scene& scene, const PinholeCamera& camera, int threads, CArray<float, -1, -1> depth_m,
                     std::optional<CArray<const uint8_t, -1, -1>> refine) {
    if (int(depth_m.shape(1)) != camera.film.width_px || int(depth_m.shape(0)) != camera.film.height_px)
        throw std::invalid_argument("depth array does not match the camera's resolution");
    if (refine && (refine->shape(0) != depth_m.shape(0) || refine->shape(1) != depth_m.shape(1)))
        throw std::invalid_argument("refine must have the depth array's shape");
    render_depth(scene, camera, threads, depth_m.data(), refine ? refine->data() : nullptr);
}

void scatter_py(CArray<const float, -1, -1, 3> rgb, CArray<const float, -1, -1> coc_px,
                CArray<const int32_t, -1, -1> layer, int n_layers, int aperture_blades, double aperture_rotation_deg,
                int sub_rows, int threads, CArray<float, -1, -1, 3> out, CArray<float, -1, -1> coverage) {
    const size_t h = rgb.shape(0), w = rgb.shape(1);
    for (size_t dim = 0; dim < 2; ++dim) {
        const size_t n = dim == 0 ? h : w;
        if (coc_px.shape(dim) != n || layer.shape(dim) != n || out.shape(dim) != n || coverage.shape(dim) != n)
            throw std::invalid_argument("blur diameters, layers and outputs must have the image's shape");
    }
    if (n_layers < 1 || sub_rows < 1 || sub_rows > 64) throw std::invalid_argument("n_layers or sub_rows out of range");
    for (size_t i = 0; i < h * w; ++i) {
        if (layer.data()[i] < 0 || layer.data()[i] >= n_layers) throw std::invalid_argument("layer out of range");
        if (!std::isfinite(coc_px.data()[i])) throw std::invalid_argument("blur diameters must be finite");
    }
    ScatterInput in;
    in.width_px = int(w), in.height_px = int(h);
    in.rgb = rgb.data(), in.coc_px = coc_px.data(), in.layer = layer.data(), in.n_layers = n_layers;
    in.aperture = ApertureShape::of(aperture_blades, aperture_rotation_deg);
    in.sub_rows = sub_rows, in.threads = threads;
    scatter_depth_of_field(in, out.data(), coverage.data());
}

// The spectral tables of lenscompare/spectral.py, checked for shape.
std::shared_ptr<const SpectralTables> spectral_tables(CArray<const double, -1, 3> basis, CArray<const double, -1, 3> film,
                                                     CArray<const double, -1> edges_nm,
                                                     CArray<const double, -1> probabilities,
                                                     CArray<const double, -1> line_nm,
                                                     CArray<const double, -1> line_radiance, double line_width_nm,
                                                     int traced_wavelengths, bool sample_still) {
    const size_t n_nm = size_t(SpectralTables::kMaxNm - SpectralTables::kMinNm) + 1;
    if (basis.shape(0) != n_nm || film.shape(0) != n_nm)
        throw std::invalid_argument("spectral tables need one row per nm from 380 to 780");
    if (edges_nm.shape(0) != probabilities.shape(0) + 1 || probabilities.shape(0) < 1)
        throw std::invalid_argument("wavelength density: one more edge than segments");
    if (line_nm.shape(0) != line_radiance.shape(0)) throw std::invalid_argument("one line per material");
    if (traced_wavelengths != 1 && traced_wavelengths != 2 && traced_wavelengths != kHeroWavelengths)
        throw std::invalid_argument("traced_wavelengths: 1, 2 or 4");
    auto t = std::make_shared<SpectralTables>();
    for (size_t i = 0; i < n_nm; ++i) {
        t->basis.push_back(Vec3f{float(basis(i, 0)), float(basis(i, 1)), float(basis(i, 2))});
        t->film.push_back(Vec3f{float(film(i, 0)), float(film(i, 1)), float(film(i, 2))});
    }
    double cdf = 0.0;
    t->cdf.push_back(0.0f);
    for (size_t i = 0; i < probabilities.shape(0); ++i) {
        cdf += probabilities(i);
        t->cdf.push_back(i + 1 == probabilities.shape(0) ? 1.0f : float(cdf));
    }
    for (size_t i = 0; i < edges_nm.shape(0); ++i) t->edges_nm.push_back(float(edges_nm(i)));
    t->build_sampling_tables();
    for (size_t i = 0; i < line_nm.shape(0); ++i) {
        t->line_nm.push_back(float(line_nm(i)));
        t->line_radiance.push_back(float(line_radiance(i)));
    }
    t->line_half_width_nm = float(0.5 * line_width_nm);
    t->traced_wavelengths = traced_wavelengths;
    t->integrate_still = !sample_still;
    t->build_wavelength_integrals();
    return t;
}

// 1 / (plane of focus) per nm for a thin lens with dispersion.
std::vector<double> inverse_focus_table(CArray<const double, -1> inverse_focus_per_m) {
    const size_t n_nm = size_t(SpectralTables::kMaxNm - SpectralTables::kMinNm) + 1;
    if (inverse_focus_per_m.shape(0) != n_nm) throw std::invalid_argument("one value per nm from 380 to 780");
    return std::vector<double>(inverse_focus_per_m.data(), inverse_focus_per_m.data() + n_nm);
}

}  // namespace

NB_MODULE(_native, m) {
    m.doc() = "lenscompare's native tracer (private: use the lenscompare package).";

    m.attr("SAMPLER_RANDOM") = int(SamplerKind::Random);
    m.attr("SAMPLER_JITTERED") = int(SamplerKind::Jittered);
    m.attr("SAMPLER_REGULAR") = int(SamplerKind::Regular);
    m.attr("SAMPLER_POISSON") = int(SamplerKind::Poisson);
    m.attr("SAMPLER_SOBOL") = int(SamplerKind::Sobol);
    m.attr("BAND_ROULETTE_GAIN") = BandRoulette::kGain;
    m.def("prepare_poisson_patterns", &prepare_poisson_patterns, "spp"_a, nb::call_guard<nb::gil_scoped_release>(),
          "Make the poisson sampler's patterns for spp now, kept for the process (otherwise on first use).");
    m.attr("DISK_POLAR") = int(DiskMapping::Polar);
    m.attr("DISK_CONCENTRIC") = int(DiskMapping::Concentric);
    m.attr("MATERIAL_EMISSIVE") = int(MaterialKind::Emissive);
    m.attr("MATERIAL_DIFFUSE") = int(MaterialKind::Diffuse);

    nb::class_<Scene>(m, "Scene", "The Embree scene with its materials, lights and background.")
        .def("__init__",
             [](Scene* self, CArray<const float, -1, 4> spheres, CArray<const int32_t, -1> sphere_material,
                CArray<const float, -1, 4, 3> quads, CArray<const int32_t, -1> quad_material,
                CArray<const int32_t, -1> material_kind, CArray<const float, -1, 3> material_color,
                CArray<const float, -1, 3> material_emission, CArray<const float, -1, 3> checker_color,
                CArray<const float, -1> checker_size_m, CArray<const float, -1, 3> light_position_m,
                CArray<const float, -1, 3> light_intensity, const Triple& background,
                CArray<const int32_t, -1> light_inverse_square, CArray<const float, -1, 3> triangle_vertices,
                CArray<const int32_t, -1, 3> triangles, CArray<const int32_t, -1> triangle_material,
                std::optional<CArray<const float, -1, 3>> sphere_velocity,
                std::optional<CArray<const float, -1, 3>> quad_velocity,
                std::optional<CArray<const float, -1, 3>> vertex_velocity, const Pair& shutter_s,
                const Triple& camera_velocity, std::optional<CArray<const int32_t, -1>> quad_solid) {
                 // Python has checked the shapes and indices (native_scene.py); the arrays are
                 // copied, so they may go once this returns.
                 new (self) Scene(scene_arrays(spheres, sphere_material, quads, quad_material, material_kind,
                                               material_color, material_emission, checker_color, checker_size_m,
                                               light_position_m, light_intensity, background, light_inverse_square,
                                               triangle_vertices, triangles, triangle_material, sphere_velocity,
                                               quad_velocity, vertex_velocity, shutter_s, camera_velocity,
                                               quad_solid));
             },
             "spheres"_a, "sphere_material"_a, "quads"_a, "quad_material"_a, "material_kind"_a, "material_color"_a,
             "material_emission"_a, "checker_color"_a, "checker_size_m"_a, "light_position_m"_a, "light_intensity"_a,
             "background"_a, "light_inverse_square"_a, "triangle_vertices"_a, "triangles"_a, "triangle_material"_a,
             "sphere_velocity"_a = nb::none(), "quad_velocity"_a = nb::none(), "vertex_velocity"_a = nb::none(),
             "shutter_s"_a = Pair{0.0, 0.0}, "camera_velocity"_a = Triple{0.0, 0.0, 0.0},
             "quad_solid"_a = nb::none())
        .def("set_spectral",
             [](Scene& self, CArray<const double, -1, 3> basis, CArray<const double, -1, 3> film,
                CArray<const double, -1> edges_nm, CArray<const double, -1> probabilities,
                CArray<const double, -1> line_nm, CArray<const double, -1> line_radiance, double line_width_nm,
                int traced_wavelengths, bool sample_still) {
                 if (line_nm.shape(0) != self.material_count()) throw std::invalid_argument("one line per material");
                 self.set_spectral(spectral_tables(basis, film, edges_nm, probabilities, line_nm, line_radiance,
                                                   line_width_nm, traced_wavelengths, sample_still));
             },
             "basis"_a, "film"_a, "edges_nm"_a, "probabilities"_a, "line_nm"_a, "line_radiance"_a, "line_width_nm"_a,
             "traced_wavelengths"_a = 4, "sample_still"_a = false,
             "Renders spectrally from now on (lenscompare/spectral.py's tables). sample_still: draw wavelengths "
             "even through a camera that does not disperse (else their integral is exact, spectral.h).");

    nb::class_<PinholeCamera>(m, "PinholeCamera", "Pinhole camera: every ray through the origin.")
        .def("__init__",
             [](PinholeCamera* self, const Triple& origin, const Triple& right, const Triple& up, const Triple& forward,
                int width_px, int height_px, double screen_half_width, double screen_half_height) {
                 new (self) PinholeCamera{make_frame(origin, right, up, forward),
                                          make_film(width_px, height_px, screen_half_width, screen_half_height)};
             },
             "origin"_a, "right"_a, "up"_a, "forward"_a, "width_px"_a, "height_px"_a, "screen_half_width"_a,
             "screen_half_height"_a);

    nb::class_<ThinLensCamera>(m, "ThinLensCamera", "Thin lens: a disk of lens_radius_m focused at focus_distance_m.")
        .def("__init__",
             [](ThinLensCamera* self, const Triple& origin, const Triple& right, const Triple& up,
                const Triple& forward, int width_px, int height_px, double screen_half_width,
                double screen_half_height, double lens_radius_m, double focus_distance_m, int disk_mapping,
                int aperture_blades, double aperture_rotation_deg) {
                 new (self) ThinLensCamera{make_frame(origin, right, up, forward),
                                           make_film(width_px, height_px, screen_half_width, screen_half_height),
                                           lens_radius_m, focus_distance_m, DiskMapping(disk_mapping),
                                           ApertureShape::of(aperture_blades, aperture_rotation_deg)};
             },
             "origin"_a, "right"_a, "up"_a, "forward"_a, "width_px"_a, "height_px"_a, "screen_half_width"_a,
             "screen_half_height"_a, "lens_radius_m"_a, "focus_distance_m"_a, "disk_mapping"_a,
             "aperture_blades"_a = 0, "aperture_rotation_deg"_a = 0.0)
        .def("set_dispersion",
             [](ThinLensCamera& self, CArray<const double, -1> inverse_focus_per_m) {
                 self.set_dispersion(inverse_focus_table(inverse_focus_per_m));
             },
             "inverse_focus_per_m"_a, "1 / (plane of focus at λ), 1/m, every nm from 380 to 780.")
        .def("carries_bands", &ThinLensCamera::carries_bands,
             "Whether a spectral render's rays each carry a band of wavelengths, integrated (a lens that "
             "disperses, its plane of focus turning back at most 3 times).")
        .def_rw("band_roulette", &ThinLensCamera::band_roulette_on,
                "Whether a band render's split samples trace their ray a pixel away only with a probability "
                "(Russian roulette: BandRoulette in spectral_bands.h; on by default).");

    nb::class_<ThickLensCamera>(m, "ThickLensCamera",
                                "Thick lens: in object space the thin lens at its front principal plane H.")
        .def("__init__",
             [](ThickLensCamera* self, const ThinLensCamera& at_front_principal_plane) {
                 new (self) ThickLensCamera{at_front_principal_plane};
             },
             "at_front_principal_plane"_a)
        .def("set_dispersion",
             [](ThickLensCamera& self, CArray<const double, -1> inverse_focus_per_m) {
                 self.at_front_principal_plane.set_dispersion(inverse_focus_table(inverse_focus_per_m));
             },
             "inverse_focus_per_m"_a, "1 / (plane of focus at λ from H), 1/m, every nm from 380 to 780.")
        .def("carries_bands", &ThickLensCamera::carries_bands, "As the thin lens's at H.")
        .def_prop_rw(
            "band_roulette", [](const ThickLensCamera& c) { return c.band_roulette(); },
            [](ThickLensCamera& c, bool on) { c.at_front_principal_plane.band_roulette_on = on; },
            "As the thin lens's at H.");

    nb::class_<LensSystemCamera>(m, "LensSystemCamera",
                                 "Full lens system: film samples traced through every surface (lens frame in mm).")
        .def("__init__",
             [](LensSystemCamera* self, const Triple& origin, const Triple& right, const Triple& up,
                const Triple& forward, int width_px, int height_px, double film_width_mm, double film_height_mm,
                CArray<const double, -1> curvature_per_mm, CArray<const double, -1> vertex_z_mm,
                CArray<const double, -1> semi_aperture_mm, CArray<const double, -1> n_scene_side,
                CArray<const double, -1> n_film_side, CArray<const bool, -1> is_stop, int stop_index,
                double film_z_mm, double entrance_pupil_z_mm, int aperture_blades, double aperture_rotation_deg) {
                 std::vector<LensElement> elements;
                 for (size_t i = 0; i < curvature_per_mm.shape(0); ++i)
                     elements.push_back(LensElement{curvature_per_mm(i), vertex_z_mm(i), semi_aperture_mm(i),
                                                    n_scene_side(i), n_film_side(i), is_stop(i)});
                 if (elements.empty()) throw std::invalid_argument("a lens system needs surfaces");
                 if (stop_index < 0 || size_t(stop_index) >= elements.size())
                     throw std::invalid_argument("stop_index out of range");
                 set_polygon_stop(&elements[size_t(stop_index)], aperture_blades, aperture_rotation_deg);
                 // The pupil polygons assume a round stop (rotational symmetry): built
                 // through the bladed stop's circumscribed circle, they hold every
                 // ray the polygon passes, and the trace then tests the blades.
                 auto pupil = std::make_shared<const ExitPupil>(without_blades(elements), stop_index, film_z_mm,
                                                                film_corner_radius_mm(film_width_mm, film_height_mm));
                 new (self) LensSystemCamera{make_frame(origin, right, up, forward), std::move(elements), film_z_mm,
                                             entrance_pupil_z_mm, film_width_mm, film_height_mm, width_px,
                                             height_px, std::move(pupil)};
                 calibrate_centre_irradiance(self);
                 self->pencils = LensPencils::of(*self);
                 self->mirror_axes = mirrors_enabled() ? lens_mirror_axes(self->elements) : 0u;
             },
             "origin"_a, "right"_a, "up"_a, "forward"_a, "width_px"_a, "height_px"_a, "film_width_mm"_a,
             "film_height_mm"_a, "curvature_per_mm"_a, "vertex_z_mm"_a, "semi_aperture_mm"_a, "n_scene_side"_a,
             "n_film_side"_a, "is_stop"_a, "stop_index"_a, "film_z_mm"_a, "entrance_pupil_z_mm"_a,
             "aperture_blades"_a = 0, "aperture_rotation_deg"_a = 0.0, nb::call_guard<nb::gil_scoped_release>())
        .def("set_dispersion",
             [](LensSystemCamera& self, CArray<const double, -1, -1> n_scene_side,
                CArray<const double, -1, -1> n_film_side) {
                 const size_t n_nm = size_t(SpectralTables::kMaxNm - SpectralTables::kMinNm) + 1;
                 if (n_scene_side.shape(0) != n_nm || n_film_side.shape(0) != n_nm ||
                     n_scene_side.shape(1) != self.elements.size() || n_film_side.shape(1) != self.elements.size())
                     throw std::invalid_argument("indices: one row per nm from 380 to 780, one column per surface");
                 std::vector<std::vector<LensElement>> by_nm(n_nm, self.elements);
                 for (size_t w = 0; w < n_nm; ++w)
                     for (size_t i = 0; i < self.elements.size(); ++i) {
                         if (!(n_scene_side(w, i) >= 1.0 && n_film_side(w, i) >= 1.0))
                             throw std::invalid_argument("indices must be >= 1");
                         by_nm[w][i].n_scene_side = n_scene_side(w, i);
                         by_nm[w][i].n_film_side = n_film_side(w, i);
                     }
                 self.set_dispersion(std::move(by_nm));
                 self.ray_table = nullptr;  // the spectral trace goes through the glass per wavelength
                 // The pupil polygons hold the pupils at 380 and 780 nm too: behind a
                 // small stop lateral colour moves them apart (at f/1000 the corner's
                 // blue pupil lay outside the 587 nm one, and blue read a tenth).
                 int stop_index = 0;
                 for (size_t i = 0; i < self.elements.size(); ++i)
                     if (self.elements[i].is_stop) stop_index = int(i);
                 const std::vector<std::vector<LensElement>> glasses{without_blades(self.elements),
                                                                     without_blades(self.elements_by_nm.front()),
                                                                     without_blades(self.elements_by_nm.back())};
                 self.pupil = std::make_shared<const ExitPupil>(
                     glasses, stop_index, self.film_z_mm, film_corner_radius_mm(self.film_width_mm, self.film_height_mm));
             },
             "n_scene_side"_a, "n_film_side"_a, "Each surface's indices at every nm from 380 to 780 (rows).",
             nb::call_guard<nb::gil_scoped_release>())
        .def("set_band_rays", &LensSystemCamera::set_band_rays, "on"_a,
             "Whether spectral renders (wavelengths not drawn) give each sample one ray carrying every wavelength "
             "whose film point stays in its pixel (cameras/lens_system_bands.cpp), instead of a ray per traced "
             "hero wavelength. After set_dispersion.")
        .def_rw("band_roulette", &LensSystemCamera::band_roulette_on, "As ThinLensCamera's.")
        .def_prop_ro("band_parameter",
                     [](const LensSystemCamera& c) { return c.band_parameter_by_nm; },
                     "The band rays' dispersion parameter k at every nm from 380 (empty before set_band_rays).")
        .def("check_band_model",
             [](const LensSystemCamera& c, int film_cells, int samples_per_cell) {
                 if (!c.carries_bands()) throw std::invalid_argument("the camera carries no bands");
                 if (film_cells < 1 || samples_per_cell < 1) throw std::invalid_argument("at least one sample");
                 const BandModelCheck r = c.check_band_model(film_cells, samples_per_cell);
                 return std::make_tuple(r.passing, r.one_way, r.film_p99_px, r.rays, r.elsewhere);
             },
             "film_cells"_a = 32, "samples_per_cell"_a = 8, nb::call_guard<nb::gil_scoped_release>(),
             "The band rays' model against the trace at 400-780 nm: (rays x wavelengths passing, of those and "
             "the rest the model passes one way only, film point error p99 in pixels, rays, rays passing at "
             "some test wavelength but not at d).")
        .def("carries_bands", &LensSystemCamera::carries_bands,
             "Whether spectral renders take band rays: set_band_rays(True) on a lens with dispersion.")
        .def("use_ray_table",
             [](LensSystemCamera& self, int radial_cells, int around_cells, bool measure_pencils) {
                 // 256 x 1024 cells per ring is already 1.1 GB.
                 if (radial_cells < 0 || around_cells < 0 || radial_cells > 256 || around_cells > 1024 ||
                     around_cells % 2 != 0)
                     throw std::invalid_argument("ray table cells: radial 0 to 256, around 0 to 1024 and even");
                 // A bladed stop is not round: a film point's rays are not the rotated rays of
                 // one on +x, which is what the table holds.
                 const bool round = std::none_of(self.elements.begin(), self.elements.end(),
                                                 [](const LensElement& e) { return e.blades > 0; });
                 self.ray_table = radial_cells > 0 && around_cells > 0 && !self.disperses() && round
                                      ? build_lens_ray_table(self.elements, *self.pupil, self.film_z_mm, radial_cells,
                                                             around_cells)
                                      : nullptr;
                 // The pencils hold the rays the render sends (a caller trying grids in turn
                 // measures them once, for the one it keeps).
                 if (measure_pencils) self.pencils = LensPencils::of(self);
             },
             "radial_cells"_a, "around_cells"_a, "measure_pencils"_a = true,
             "The batch rays (those of every wavelength, without dispersion) by table look-up over radial x around cells per pupil ring (0: traced); measure_pencils=False leaves the tile pencils as they were (measure them before rendering).",
             nb::call_guard<nb::gil_scoped_release>())
        .def_prop_ro("uses_ray_table", [](const LensSystemCamera& c) { return bool(c.ray_table); })
        .def_rw("mirror_axes", &LensSystemCamera::mirror_axes,
                "Film mirrors whose rays the render reflects from traced ones: bit 0 x, bit 1 y (0, the default: "
                "none; LENSCOMPARE_LENS_MIRRORS=1 sets symmetric_mirror_axes for new cameras).")
        .def_prop_ro("symmetric_mirror_axes",
                     [](const LensSystemCamera& c) { return lens_mirror_axes(c.elements); },
                     "The film mirrors the lens is symmetric under (bit 0 x, bit 1 y): its stop's polygon's.")
        .def_prop_ro("inverse_centre_irradiance", [](const LensSystemCamera& c) { return c.inverse_centre_irradiance; },
                     "The weight scale that makes a uniform scene of radiance 1 read 1 at the film centre.");

    nb::class_<CompositeCamera>(m, "CompositeCamera",
                                "Composite: a thin lens at the entrance pupil with radial distortion and "
                                "illumination tables traced once through a lens system.")
        .def("__init__",
             [](CompositeCamera* self, const ThinLensCamera& lens, double film_width_mm, double film_height_mm,
                CArray<const double, -1> screen_scale, CArray<const double, -1> illumination, double radius_step_mm,
                double max_radius_mm) {
                 if (!(radius_step_mm > 0.0 && std::isfinite(radius_step_mm)))
                     throw std::invalid_argument("radius_step_mm must be finite and > 0");
                 if (!(max_radius_mm > 0.0)) throw std::invalid_argument("max_radius_mm must be > 0 (or infinity)");
                 new (self) CompositeCamera{lens, film_width_mm, film_height_mm,
                                            radial_table(screen_scale, radius_step_mm, "screen_scale"),
                                            radial_table(illumination, radius_step_mm, "illumination"),
                                            max_radius_mm};
             },
             "lens"_a, "film_width_mm"_a, "film_height_mm"_a, "screen_scale"_a, "illumination"_a, "radius_step_mm"_a,
             "max_radius_mm"_a)
        .def("set_lateral_color",
             [](CompositeCamera& self, CArray<const double, -1> wavelengths_nm, CArray<const double, -1, -1> scale,
                double radius_step_mm) {
                 const size_t rows = wavelengths_nm.shape(0);
                 if (rows < 2 || scale.shape(0) != rows || scale.shape(1) < 2)
                     throw std::invalid_argument("lateral colour: two wavelengths or more, a row of two values or "
                                                 "more for each");
                 if (!(radius_step_mm > 0.0 && std::isfinite(radius_step_mm)))
                     throw std::invalid_argument("radius_step_mm must be finite and > 0");
                 std::vector<double> nm;
                 std::vector<RadialTable> tables;
                 for (size_t j = 0; j < rows; ++j) {
                     if (!(std::isfinite(wavelengths_nm(j)) && (j == 0 || wavelengths_nm(j) > nm.back())))
                         throw std::invalid_argument("lateral colour: wavelengths must be finite and increasing");
                     nm.push_back(wavelengths_nm(j));
                     RadialTable table;
                     table.radius_step_mm = radius_step_mm;
                     for (size_t i = 0; i < scale.shape(1); ++i) {
                         if (!(std::isfinite(scale(j, i)) && scale(j, i) >= 0.0))
                             throw std::invalid_argument("lateral colour: values must be finite and >= 0");
                         table.values.push_back(scale(j, i));
                     }
                     tables.push_back(std::move(table));
                 }
                 self.color_nm = std::move(nm);
                 self.screen_scale_by_color = std::move(tables);
             },
             "wavelengths_nm"_a, "screen_scale"_a, "radius_step_mm"_a,
             "Lateral colour: the screen-scale table (rows) at each wavelength (increasing), read linearly in "
             "wavelength and film radius.")
        .def("set_dispersion",
             [](CompositeCamera& self, CArray<const double, -1> inverse_focus_per_m) {
                 self.lens.set_dispersion(inverse_focus_table(inverse_focus_per_m));
             },
             "inverse_focus_per_m"_a,
             "Longitudinal colour: 1 / (plane of focus at λ), 1/m, every nm from 380 to 780.");

    bind_camera_functions<PinholeCamera>(m);
    bind_camera_functions<ThinLensCamera>(m);
    bind_camera_functions<ThickLensCamera>(m);
    bind_camera_functions<LensSystemCamera>(m);
    bind_camera_functions<CompositeCamera>(m);

    m.def("render_depth", &render_depth_py, "scene"_a, "camera"_a, "threads"_a, "depth_m"_a, "refine"_a = nb::none(),
          nb::call_guard<nb::gil_scoped_release>(),
          "Each pixel centre's first hit along the pinhole's ray, as depth along the view axis (m; inf: nothing).");
    m.def("scatter_depth_of_field", &scatter_py, "rgb"_a, "coc_px"_a, "layer"_a, "n_layers"_a, "aperture_blades"_a,
          "aperture_rotation_deg"_a, "sub_rows"_a, "threads"_a, "out"_a, "coverage"_a,
          nb::call_guard<nb::gil_scoped_release>(),
          "Spreads each pixel over its signed blur diameter (px, > 0 behind focus), layers composited back to "
          "front (0 the farthest); the image into out, the composited weight into coverage.");

    nb::module_ diagnostics = m.def_submodule("diagnostics", "Hooks for lenscompare's tests and benchmarks only.");
    bind_diagnostics(diagnostics);
}
