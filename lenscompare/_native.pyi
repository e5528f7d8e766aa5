"""lenscompare's native tracer (private: use the lenscompare package).

Type stub for the nanobind module built from native/src/bindings.cpp; the test
and benchmark hooks (native/src/bindings_diagnostics.cpp) are its submodule
``diagnostics``. Every array is a ``numpy.ndarray``, C-contiguous, of the dtype
and shape its comment gives (n: any length); the native code reads it or writes
it in place, never copies it. Python validates every argument before the call.
Lengths are metres unless a name says ``_mm`` or ``_px``.
"""

import types
from collections.abc import Sequence
from typing import TypeAlias

import numpy

Vec3: TypeAlias = Sequence[float]  # three numbers (x, y, z), world space

SAMPLER_RANDOM: int = 0
SAMPLER_JITTERED: int = 1
SAMPLER_REGULAR: int = 2
SAMPLER_POISSON: int = 3
SAMPLER_SOBOL: int = 4
DISK_POLAR: int = 0
DISK_CONCENTRIC: int = 1
MATERIAL_EMISSIVE: int = 0
MATERIAL_DIFFUSE: int = 1

class Scene:
    """The Embree scene with its materials, lights and background."""

    def __init__(
        self,
        spheres: numpy.ndarray,  # float32 (n, 4): centre x, y, z and radius
        sphere_material: numpy.ndarray,  # int32 (n,): material index of each sphere
        quads: numpy.ndarray,  # float32 (q, 4, 3): corners in order round each quad
        quad_material: numpy.ndarray,  # int32 (q,)
        material_kind: numpy.ndarray,  # int32 (m,): MATERIAL_EMISSIVE or MATERIAL_DIFFUSE
        material_color: numpy.ndarray,  # float32 (m, 3): emissive radiance or diffuse albedo
        material_emission: numpy.ndarray,  # float32 (m, 3): added to the lit diffuse result
        checker_color: numpy.ndarray,  # float32 (m, 3): albedo of the odd checker cubes
        checker_size_m: numpy.ndarray,  # float32 (m,): checker cube size, 0 for none
        light_position_m: numpy.ndarray,  # float32 (k, 3): point lights
        light_intensity: numpy.ndarray,  # float32 (k, 3): radiant intensity
        background: Vec3,  # linear RGB radiance of rays that hit nothing
        light_inverse_square: numpy.ndarray,  # int32 (k,): 1 = intensity / distance^2, 0 = no falloff
        triangle_vertices: numpy.ndarray,  # float32 (v, 3): every mesh's vertices, m
        triangles: numpy.ndarray,  # int32 (t, 3): vertex indices of each triangle
        triangle_material: numpy.ndarray,  # int32 (t,)
        sphere_velocity: numpy.ndarray | None = None,  # float32 (n, 3), m/s; None: nothing moves
        quad_velocity: numpy.ndarray | None = None,  # float32 (q, 3), m/s
        vertex_velocity: numpy.ndarray | None = None,  # float32 (v, 3), m/s: each mesh vertex's
        shutter_s: tuple[float, float] = (0.0, 0.0),  # open <= close, s
        camera_velocity: Vec3 = (0.0, 0.0, 0.0),  # m/s: every camera ray's origin moves by v t
    ) -> None:
        """Builds the BVH (moving primitives with two Embree time steps, open and close); the arrays are
        copied and may go once this returns."""

class PinholeCamera:
    """Pinhole camera: every ray through the origin."""

    def __init__(
        self,
        origin: Vec3,  # the camera position
        right: Vec3,  # unit vectors of the camera frame
        up: Vec3,
        forward: Vec3,
        width_px: int,
        height_px: int,
        screen_half_width: float,  # (film width / 2) / film distance
        screen_half_height: float,  # (film height / 2) / film distance
    ) -> None: ...

class ThinLensCamera:
    """Thin lens: a disk of lens_radius_m focused at focus_distance_m."""

    def __init__(
        self,
        origin: Vec3,  # the lens centre
        right: Vec3,
        up: Vec3,
        forward: Vec3,
        width_px: int,
        height_px: int,
        screen_half_width: float,  # (film width / 2) / film distance d'
        screen_half_height: float,
        lens_radius_m: float,  # f / (2 N)
        focus_distance_m: float,  # along the view axis
        disk_mapping: int,  # DISK_POLAR or DISK_CONCENTRIC
        aperture_blades: int = 0,  # 0: circular; 3..32: the regular polygon of the circle's area
        aperture_rotation_deg: float = 0.0,  # counter-clockwise seen from behind; vertex up at 0
    ) -> None: ...

class ThickLensCamera:
    """Thick lens: in object space the thin lens at its front principal plane H."""

    def __init__(self, at_front_principal_plane: ThinLensCamera) -> None:
        """The thin lens with its origin at H (the gap H -> H' moves no ray)."""

class LensSystemCamera:
    """Full lens system: film samples traced through every surface (lens frame in mm)."""

    def __init__(
        self,
        origin: Vec3,  # the entrance-pupil centre
        right: Vec3,
        up: Vec3,
        forward: Vec3,
        width_px: int,
        height_px: int,
        film_width_mm: float,
        film_height_mm: float,
        # One entry per surface, scene side first, in the lens frame (z = 0 at
        # the first vertex, +z toward the film):
        curvature_per_mm: numpy.ndarray,  # float64 (s,): 1/R; 0 for planes and the stop
        vertex_z_mm: numpy.ndarray,  # float64 (s,)
        semi_aperture_mm: numpy.ndarray,  # float64 (s,)
        n_scene_side: numpy.ndarray,  # float64 (s,): index in front of each surface
        n_film_side: numpy.ndarray,  # float64 (s,): index behind each surface
        is_stop: numpy.ndarray,  # bool (s,)
        stop_index: int,  # the aperture stop's surface
        film_z_mm: float,  # film plane, lens frame
        entrance_pupil_z_mm: float,  # lens-frame z of origin
        aperture_blades: int = 0,  # 0: round stop; 3..32: the regular polygon of the stop circle's area
        aperture_rotation_deg: float = 0.0,  # counter-clockwise seen from the film; vertex on +y at 0
    ) -> None:
        """Builds the exit-pupil tables and calibrates the centre irradiance (GIL released)."""

    @property
    def inverse_centre_irradiance(self) -> float:
        """The weight scale that makes a uniform scene of radiance 1 read 1 at the film centre."""

    def use_ray_table(self, radial_cells: int, around_cells: int, measure_pencils: bool = True) -> None:
        """The batch rays (every wavelength's, without dispersion) by table look-up over radial x around cells
        per exit-pupil ring (0: traced; around_cells even; a dispersive camera always traces); the tile pencils
        are measured again unless measure_pencils is False (a caller trying grids in turn measures once, for
        the one it keeps; GIL released)."""

    @property
    def uses_ray_table(self) -> bool: ...

    def set_band_rays(self, on: bool) -> None:
        """Spectral renders (wavelengths not drawn) give each sample one ray carrying every wavelength whose film
        point stays in its pixel (native/src/cameras/lens_system_bands.cpp). After set_dispersion."""

    def carries_bands(self) -> bool: ...

    @property
    def band_parameter(self) -> list[float]:
        """The band rays' dispersion parameter k at every nm from 380 to 780 (empty before set_band_rays)."""

    def check_band_model(self, film_cells: int = 32, samples_per_cell: int = 8) -> tuple[int, int, float, int, int]:
        """The band model against rays traced back at 400-780 nm: (rays x wavelengths passing, passing one way
        only, film point error p99 in pixels, rays, rays passing at some wavelength but not at d)."""

class CompositeCamera:
    """Composite: a thin lens at the entrance pupil with radial distortion and illumination tables traced
    once through a lens system."""

    def __init__(
        self,
        lens: ThinLensCamera,  # at the entrance pupil, screen extent from the paraxial image scale; radius 0: pinhole
        film_width_mm: float,
        film_height_mm: float,
        # Tables at film radii 0, step, 2 step, ... mm, read with linear interpolation (empty: none):
        screen_scale: numpy.ndarray,  # float64 (k,): real chief-ray tangent over the paraxial one (distortion)
        illumination: numpy.ndarray,  # float64 (k,): relative illumination, the ray weight (vignetting)
        radius_step_mm: float,
        max_radius_mm: float,  # no ray beyond this film radius (math.inf: none)
    ) -> None:
        """With both tables empty and max_radius_mm infinite, the thin lens bit for bit."""

    def set_lateral_color(
        self,
        wavelengths_nm: numpy.ndarray,  # float64 (k,), increasing
        screen_scale: numpy.ndarray,  # float64 (k, entries): the distortion table at each wavelength
        radius_step_mm: float,
    ) -> None:
        """Lateral colour (spectral renders): each ray's screen scale from its wavelength's row."""

    def set_dispersion(self, inverse_focus_per_m: numpy.ndarray) -> None:
        """Longitudinal colour (spectral renders): 1 / (plane of focus at λ), 1/m, every nm from 380 to 780."""

Camera: TypeAlias = PinholeCamera | ThinLensCamera | ThickLensCamera | LensSystemCamera | CompositeCamera

def render_rows(
    scene: Scene,
    camera: Camera,
    spp: int,
    sampler: int,  # a SAMPLER_* code
    seed: int,
    threads: int,  # 0: all cores
    row_begin: int,
    row_end: int,
    out: numpy.ndarray,  # float32 (height, width, 3), written: linear RGB, row 0 at the top
    variance_of_mean: numpy.ndarray | None = None,  # float32 (height, width), written: summed over R, G, B
) -> tuple[int, int]:
    """Renders rows [row_begin, row_end) into out with spp samples per pixel, and optionally each pixel
    mean's variance; (samples, rays passed)."""

def render_rows_adaptive(
    scene: Scene,
    camera: Camera,
    sample_end: numpy.ndarray,  # uint32 (height, width): each pixel's sample count, at most 2**20
    first_sample: int,  # each pixel takes samples [min(first_sample, end), end)
    sampler: int,
    seed: int,
    threads: int,
    row_begin: int,
    row_end: int,
    out: numpy.ndarray,  # float32 (height, width, 3), written: the mean of each pixel's samples
    variance_of_mean: numpy.ndarray,  # float32 (height, width), written: summed over R, G and B
) -> tuple[int, int]:
    """Renders rows with each pixel's own sample range, and its mean's variance; (samples, rays passed)."""

def generate_rays(
    camera: Camera,
    raster_px: numpy.ndarray,  # float32 (n, 2): film positions in pixels, y down
    lens_sample: numpy.ndarray,  # float32 (n, 2): points in [0, 1)^2
    origin: numpy.ndarray,  # float64 (n, 3), written
    direction: numpy.ndarray,  # float64 (n, 3), written: unit
    weight: numpy.ndarray,  # float32 (n,), written: 0 (and zero vectors) for a vignetted sample
) -> None:
    """The camera's ray for each (raster_px, lens_sample) row into origin, direction, weight (0: vignetted)."""

def render_depth(
    scene: Scene,
    camera: PinholeCamera,
    threads: int,  # 0: all cores; the buffer does not depend on it
    depth_m: numpy.ndarray,  # float32 (height, width), written: depth along the view axis, m; inf: nothing hit
    refine: numpy.ndarray | None = None,  # uint8 (height, width): pixels that take the 8x8 grid whatever their neighbours
) -> None:
    """Each pixel centre's first hit along the pinhole's ray, as depth along the view axis (m; inf: nothing)."""

def scatter_depth_of_field(
    rgb: numpy.ndarray,  # float32 (height, width, 3): the pinhole image
    coc_px: numpy.ndarray,  # float32 (height, width): signed blur diameter, px; > 0 behind the plane of focus
    layer: numpy.ndarray,  # int32 (height, width): 0 the farthest layer ... n_layers - 1 the nearest
    n_layers: int,
    aperture_blades: int,  # 0: circle; 3..32: regular N-gon of the circle's area
    aperture_rotation_deg: float,
    sub_rows: int,  # heights per output row at which the kernel is integrated, 1..64
    threads: int,  # 0: all cores; the image does not depend on it
    out: numpy.ndarray,  # float32 (height, width, 3), written
    coverage: numpy.ndarray,  # float32 (height, width), written: the composited weight before normalisation
) -> None:
    """Spreads each pixel over its signed blur diameter, layers composited back to front."""

class _Diagnostics(types.ModuleType):
    """Hooks for lenscompare's tests and benchmarks only.

    The submodule ``lenscompare._native.diagnostics`` (declared as a class so
    that this one stub holds both modules); import it with
    ``from lenscompare._native import diagnostics``.
    """

    SAMPLER_SOBOL_UNSCRAMBLED: int = 5  # the bare Sobol' points, same in every pixel: tests only
    SAMPLER_SOBOL_PADDED: int = 6  # film, lens and time each stratified alone, paired at random: the study only
    SAMPLER_SOBOL_TIME_NET: int = 7  # sobol with time i / spp: what the render draws for sobol in a whole-pixel pass
    @staticmethod
    def rng_kernels() -> list[str]:
        """The kernels that draw PCG32's outputs several at a time (rng_lanes.cpp) this CPU runs, slowest first."""

    @staticmethod
    def pcg32_draws(
        seed: int,
        stream: int,
        dimension: int,
        out: numpy.ndarray,  # uint32 (n,), written
        kernel: str,  # one of rng_kernels()
    ) -> None:
        """Fills out with the first outputs of the render's PCG32 stream (seed, stream, dimension), drawn by the
        named kernel (Pcg32::fill_u32)."""

    @staticmethod
    def pixel_samples(
        sampler: int,  # a SAMPLER_* code, or SAMPLER_SOBOL_UNSCRAMBLED
        seed: int,
        pixel_index: int,  # row-major over the image
        film: numpy.ndarray,  # float32 (spp, 2), written
        lens: numpy.ndarray | None,  # float32 (spp, 2), written; None: not drawn (the pinhole's render)
        time: numpy.ndarray | None = None,  # float32 (spp,), written: shutter times in [0, 1)
        wavelength: numpy.ndarray | None = None,  # float32 (spp,), written: wavelength samples in [0, 1)
        first_sample: int = 0,  # the pass takes samples [first_sample, spp); 0: the pixel whole
    ) -> None:
        """Fills film and lens (spp x 2), and time and wavelength (spp) when given, with one pixel's samples,
        as the render draws them in a pass starting at first_sample (sobol: time i / spp, Owen-scrambled, when
        0; dimension 6 when a pass continues the pixel)."""

    @staticmethod
    def map_to_disk(
        u: numpy.ndarray,  # float32 (n, 2): points in [0, 1)^2
        mapping: int,  # DISK_POLAR or DISK_CONCENTRIC
        out: numpy.ndarray,  # float32 (n, 2), written
    ) -> None:
        """Maps unit-square points u to the unit disk into out."""

    @staticmethod
    def map_to_aperture(
        u: numpy.ndarray,  # float32 (n, 2): points in [0, 1)^2
        mapping: int,  # DISK_POLAR or DISK_CONCENTRIC
        blades: int,  # 0: the unit circle; 3..32: the regular polygon of area pi
        rotation_deg: float,  # counter-clockwise; vertex 0 on +y at 0
        out: numpy.ndarray,  # float64 (n, 2), written
    ) -> None:
        """Maps unit-square points u to the aperture into out, as the thin lens samples it."""

    @staticmethod
    def count_lens_passes(
        camera: LensSystemCamera,
        raster_px: numpy.ndarray,  # float32 (n, 2)
        lens: numpy.ndarray,  # float32 (n, 2)
    ) -> tuple[int, int, int]:
        """(samples, traced, passed) for the given film and lens samples, traced one at a time."""

    @staticmethod
    def lens_stage_seconds(
        camera: LensSystemCamera,
        pinhole: PinholeCamera,
        raster_px: numpy.ndarray,  # float32 (n, 2)
        lens: numpy.ndarray,  # float32 (n, 2)
    ) -> tuple[float, float, float, float]:
        """(sample, trace, whole, pinhole) CPU seconds of this thread for the samples' camera rays in the
        render loop's batches: film points, pupil picks and aim; the batch trace alone; the lens camera's
        float rows whole; the pinhole's rows."""

    @staticmethod
    def measure_lens_throughput(camera: LensSystemCamera, n: int, threads: int) -> tuple[float, int, int, int]:
        """(seconds, samples, traced, passed) for n random samples through the lens alone, no scene."""

    @staticmethod
    def generate_lens_rays_batched(
        camera: LensSystemCamera,
        raster_px: numpy.ndarray,  # float32 (n, 2)
        lens: numpy.ndarray,  # float32 (n, 2)
        origin: numpy.ndarray,  # float64 (n, 3), written
        direction: numpy.ndarray,  # float64 (n, 3), written
        weight: numpy.ndarray,  # float32 (n,), written
    ) -> None:
        """generate_rays through the render loop's lockstep batch trace (in double precision the same bits as
        generate_rays; in single, the render's, the same rays to float rounding)."""

    @staticmethod
    def set_lens_pencils(camera: LensSystemCamera, mode: str) -> None:
        """The camera's per-tile pencils (lens_pencil.h): "measured" (the render's), "collapsed" (every screen
        range shrunk to a point, so the render's check falls back nearly everywhere) or "none"."""

    @staticmethod
    def generate_lens_ray_rows(
        camera: LensSystemCamera,
        raster_px: numpy.ndarray,  # float32 (n, 2)
        lens: numpy.ndarray,  # float32 (n, 2)
        origin: numpy.ndarray,  # float32 (n, 3), written
        direction: numpy.ndarray,  # float32 (n, 3), written
        weight: numpy.ndarray,  # float32 (n,), written
    ) -> None:
        """The render's own camera rays in float, as its packets take them (generate_weighted_ray_rows: from
        the lens-ray table where the camera has one); weight 0 and zeros where blocked."""

    @staticmethod
    def generate_rays_batched(
        camera: PinholeCamera | ThinLensCamera,
        raster_px: numpy.ndarray,  # float32 (n, 2)
        lens: numpy.ndarray,  # float32 (n, 2)
        origin: numpy.ndarray,  # float64 (n, 3), written
        direction: numpy.ndarray,  # float64 (n, 3), written
        weight: numpy.ndarray,  # float32 (n,), written
    ) -> None:
        """The render loop's batch of camera rays (kCameraBatch at a time; the same bits as generate_rays)."""

    @staticmethod
    def generate_lens_rays_at(
        camera: LensSystemCamera,
        raster_px: numpy.ndarray,  # float32 (n, 2)
        lens: numpy.ndarray,  # float32 (n, 2)
        nm: numpy.ndarray,  # float32 (n, 4)
        batched: bool,
        origin: numpy.ndarray,  # float64 (4 n, 3), written
        direction: numpy.ndarray,  # float64 (4 n, 3), written
        weight: numpy.ndarray,  # float32 (4 n,), written
    ) -> None:
        """Each sample's rays at its four wavelengths (row i * 4 + k: nm[i, k]), scalar or (batched) lockstep."""

    @staticmethod
    def with_brute_force_pupil(camera: LensSystemCamera) -> LensSystemCamera:
        """A copy of camera that aims at a disk 1.5x the rear element: the pupil sampler's reference."""

    @staticmethod
    def lens_trace_kernels() -> list[str]:
        """The batch lens-trace kernels this CPU runs, slowest first."""

    @staticmethod
    def lens_trace_kernel(camera: LensSystemCamera) -> str:
        """The batch lens-trace kernel camera runs (the fastest this CPU runs unless set)."""

    @staticmethod
    def set_lens_trace_kernel(camera: LensSystemCamera, kernel: str) -> None:
        """Makes camera run the named batch lens-trace kernel."""

    @staticmethod
    def lens_trace_precision(camera: LensSystemCamera) -> str:
        """The precision of camera's batch lens trace: "single" (the render's) or "double"."""

    @staticmethod
    def set_lens_trace_precision(camera: LensSystemCamera, precision: str) -> None:
        """Makes camera's batch lens trace run in "single" or "double" precision."""

    @staticmethod
    def shading_kernel() -> str:
        """The shading lanes' instruction set: 'default', 'avx2' or 'avx512' (LENSCOMPARE_SHADING_KERNEL picks one)."""

    @staticmethod
    def sphere_kernels() -> list[str]:
        """The own-sphere kernels this CPU runs, slowest first."""

    @staticmethod
    def own_spheres_closest(
        spheres: numpy.ndarray,  # float32 (k, 4): centre xyz, radius (m)
        origin: numpy.ndarray,  # float32 (n, 3)
        direction: numpy.ndarray,  # float32 (n, 3)
        t_far: numpy.ndarray,  # float32 (n,), read and written
        index: numpy.ndarray,  # int32 (n,), written (-1: no hit)
        normal: numpy.ndarray,  # float32 (n, 3), written
        kernel: str,
    ) -> None:
        """Closest hits at t in [0, t_far) as the render's camera rays get them, in place."""

    @staticmethod
    def own_spheres_occluded(
        spheres: numpy.ndarray,  # float32 (k, 4)
        origin: numpy.ndarray,  # float32 (n, 3)
        direction: numpy.ndarray,  # float32 (n, 3)
        t_far: numpy.ndarray,  # float32 (n,)
        start_sphere: numpy.ndarray,  # int32 (n,): the sphere the ray starts on, -1: none
        self_blocks: numpy.ndarray,  # bool (n,): that sphere blocks the ray
        out: numpy.ndarray,  # bool (n,), written
        kernel: str,
    ) -> None:
        """out[i]: whether segment i crosses a sphere's surface, as the render's shadow rays see it."""

    @staticmethod
    def own_quads_closest(
        corners: numpy.ndarray,  # float32 (k, 4, 3): parallelograms, corners in order round each
        origin: numpy.ndarray,  # float32 (n, 3)
        direction: numpy.ndarray,  # float32 (n, 3)
        t_far: numpy.ndarray,  # float32 (n,), read and written
        index: numpy.ndarray,  # int32 (n,), written (-1: no hit)
        kernel: str,
        first_quad: int = 0,  # tested first, then the one the last packet met (the same hits in any order)
    ) -> None:
        """Closest hits at t in [0, t_far) as the render's camera rays get them, in place."""

    @staticmethod
    def own_quads_occluded(
        corners: numpy.ndarray,  # float32 (k, 4, 3)
        origin: numpy.ndarray,  # float32 (n, 3)
        direction: numpy.ndarray,  # float32 (n, 3)
        t_far: numpy.ndarray,  # float32 (n,)
        out: numpy.ndarray,  # bool (n,), written
        kernel: str,
    ) -> None:
        """out[i]: whether segment i crosses a parallelogram, as the render's shadow rays see it."""

    @staticmethod
    def raw_primary_throughput(scene: Scene, camera: PinholeCamera, spp: int, threads: int) -> tuple[float, int, int]:
        """(seconds, rays, hits) of bare pinhole rays (Embree and the own sphere test), no shading: the ceiling of a render."""

diagnostics: _Diagnostics
