"""Native renders: a scene, a camera model, settings in; an :class:`Image` out.

The image is rendered in bands of rows so that a progress bar can advance;
every pixel owns its random stream, so bands, tiles and thread counts do not
change a single bit of the result.
"""

from __future__ import annotations

import math
import os
import platform
import time

import numpy as np

from . import __version__, _native
from .adaptive import PREFIX_SAMPLERS, adaptive_base_spp, allocate_samples
from .cameras import CameraModel, camera_for, check_spectral_parts
from .cameras.lens_ray_table import use_ray_table
from .diffraction import diffract, diffraction_aperture
from .errors import ExternalError, InputError
from .image import Image
from .limits import MAX_SEED, MAX_SPP, check_render_budget
from .motion import moves, samples_time
from .native_scene import build_native_scene
from .postfilter import depth_buffer_m, pinhole_pass_spp, pinhole_sample_counts, signed_coc_px, spread
from .postfilter.refine import BASE_PINHOLE_SPP, RULE as REFINE_RULE, refine_pixels, silhouette_pixels
from .postfilter.samples import RULE as PINHOLE_RULE
from .progress import progress_bar
from .render_spectral import make_spectral
from .scene import LENS_RAYS, RENDER_MODELS, SAMPLERS, Scene

# Beyond the scene file's models: the composite of chosen effects (cameras/composite.py).
RENDERABLE_MODELS = RENDER_MODELS + ("composite",)

__all__ = ["render", "SAMPLER_CODES"]

SAMPLER_CODES = {"random": _native.SAMPLER_RANDOM, "jittered": _native.SAMPLER_JITTERED,
                 "regular": _native.SAMPLER_REGULAR, "poisson": _native.SAMPLER_POISSON,
                 "sobol": _native.SAMPLER_SOBOL}

# Rows per native call: enough samples (~2 M) that the worker threads all join
# in, few enough that the progress bar moves.
_BAND_SAMPLES = 2_000_000


def render(scene: Scene, *, model: str | None = None, spp: int | None = None, sampler: str | None = None,
           seed: int | None = None, threads: int | None = None, progress: bool | None = None,
           adaptive: bool | None = None, diffraction: bool | None = None,
           camera: CameraModel | None = None, effects=None, spectral: bool | None = None,
           traced_wavelengths: int | None = None, sample_wavelengths: bool = False,
           postfilter_per_pixel_spp: bool = False,
           postfilter_uniform_pass: bool = False, lens_mirrors: bool | None = None,
           lens_rays: str | None = None, lens_bands: bool = True, band_roulette: bool = True) -> Image:
    """Render ``scene`` with the native tracer.

    Parameters
    ----------
    scene : Scene
        A loaded scene (:func:`lenscompare.scene.load_scene`).
    model : {'pinhole', 'thin', 'thick', 'lens', 'composite', 'postfilter'}, optional
        Camera model; default the scene's ``camera.model``, or ``composite``
        when the scene has ``[render] effects``. (``--model auto`` is the
        planner's: :func:`lenscompare.plan.render_planned`.)
        ``postfilter`` renders the pinhole with at most
        :data:`~lenscompare.postfilter.MAX_PINHOLE_SPP` film samples per pixel,
        that many only where a first pass of a few shows an edge
        (:mod:`lenscompare.postfilter.refine`), and spreads it by its depth buffer into the thin lens's defocus
        (:mod:`lenscompare.postfilter`); ``seconds`` includes the depth
        buffer and the spread, ``metadata["postfilter"]`` says what was drawn
        and what the spread cost, and ``image.camera`` is the thin lens.
    effects : sequence of str, optional
        Render exactly these effects with a composite of cheap parts
        (:class:`lenscompare.cameras.CompositeCamera`; ``--effects``);
        ``diffraction`` among them turns the post-filter on. Default: the
        scene's ``[render] effects`` when it has them and no model is given.
    spp, sampler, seed, adaptive : optional
        Override the scene's ``[render]`` settings. With ``adaptive``, ``spp``
        is the mean over the image: a first pass measures each pixel's noise
        and the rest of the samples go where it is largest
        (:mod:`lenscompare.adaptive`).
    diffraction : bool, optional
        Override ``[render] diffraction``: convolve the image with the
        aperture's diffraction PSF (:mod:`lenscompare.diffraction`); its cost
        is in ``metadata["diffraction"]["seconds"]``, not in ``seconds``.
    threads : int, optional
        Worker threads; default all cores, and never more (TBB would only warn).
        The image does not depend on it.
    camera : CameraModel, optional
        The camera value, when the caller has built it already
        (:func:`lenscompare.cameras.camera_for`); its model wins over ``model``.
    progress : bool, optional
        Force the progress bar on or off (default: on for a terminal only).
    spectral : bool, optional
        Override ``[render] spectral`` (:mod:`lenscompare.spectral`).
    traced_wavelengths : {1, 2, 4}, optional
        Spectral renders through a dispersive camera: how many of each
        sample's four hero wavelengths get a ray of their own
        (:func:`lenscompare.render_spectral.traced_wavelengths_for`; default the
        count that reaches a given noise soonest for the model).
    sample_wavelengths : bool, optional
        Spectral renders through a camera that does not disperse, or through a
        dispersive thin or thick lens or lens system: draw hero wavelengths,
        instead of integrating the film's response over the wavelengths
        exactly (the default: over the whole spectrum, or over each ray's band
        of wavelengths for the dispersive cameras;
        :mod:`lenscompare.render_spectral`). For comparing the two.
    postfilter_per_pixel_spp : bool, optional
        ``postfilter`` (not adaptive) only: fewer pinhole samples where a
        pixel's blur averages it (:func:`~lenscompare.postfilter.pinhole_sample_counts`),
        the depth buffer first. Off by default: faster, but its error against
        the converged thin lens is measurably larger (bench/study_pinhole_counts.py).
    lens_mirrors : bool, optional
        ``lens`` only: a pixel and its mirror images across the film's centre
        lines take one traced set of samples, reflected (the lens is symmetric
        under those reflections; a bladed stop keeps only the mirrors its
        polygon has). About 1.5x the samples per second, each pixel as
        accurate as before, but the four pixels' errors are correlated: a
        measure that averages mirror-image pixels (a radial vignetting
        profile, a dot grid's distortion) gains nothing from averaging them
        (``bench/bench_lens_mirrors.py``). Overrides ``[render]
        lens_mirrors``; when neither says, off unless
        ``LENSCOMPARE_LENS_MIRRORS=1``.
    lens_rays : {'traced', 'table'}, optional
        Override ``[render] lens_rays``: ``lens`` renders only, each
        sample's ray traced through every surface (``traced``, the default
        and the reference) or interpolated from a table of rays traced once
        per camera (``table``; :mod:`lenscompare.cameras.lens_ray_table`,
        ``native/src/lens/lens_ray_table.h``): faster, with rays within
        a few hundredths of a pixel of the traced ones. The table is checked
        against the trace first and refined, or refused where it cannot meet
        :data:`lenscompare.cameras.lens_ray_table.TOLERANCE_PX`
        (``metadata["lens_rays"]`` says which and the measured error).
        Spectral renders through a lens with dispersion trace each
        wavelength through its glass whatever the setting.
    lens_bands : bool, optional
        Spectral renders through a dispersive ``lens``: each sample's ray
        carries every wavelength whose film point stays in its pixel (the
        default; ``native/src/cameras/lens_system_bands.cpp``), where the
        band model passes its per-camera check (``metadata["spectral"]
        ["lens_bands"]`` says whether, with the figures); False, or a
        refused check, draws hero wavelengths instead.
    band_roulette : bool, optional
        Spectral renders whose rays carry bands (a dispersive thin, thick or
        ``lens`` model): a sample whose wavelengths land in two pixels traces
        its ray from the other pixel only with a probability (Russian
        roulette on the difference that pixel makes, weighed to stay
        unbiased; ``native/src/spectral_bands.h``, ``BandRoulette``): faster
        for a few per cent more variance on ``showcase``. False traces every
        one (``metadata["spectral"]["band_roulette_gain"]`` is then None).
    postfilter_uniform_pass : bool, optional
        ``postfilter`` only: draw min(spp, 16) film samples in every pixel,
        as before the refined pass (a reference for bench/bench_postfilter.py).

    Returns
    -------
    Image
        Linear radiance, with the camera value (``image.camera``) and
        metadata: model, spp, sampler, seed, seconds, samples_per_second,
        threads, and the camera's derived quantities.
    """
    if camera is None and effects is not None:
        if model not in (None, "composite"):
            raise InputError("--effects", f"renders a composite of those effects; --model {model} cannot be "
                             "given with it")
        model = "composite"
    if camera is None and model is None and scene.render.effects is not None:
        model = "composite"
    model = camera.model if camera is not None else (model or scene.camera.model)
    if model not in RENDERABLE_MODELS:
        raise InputError("--model", f"expected one of {', '.join(RENDERABLE_MODELS)}, got {model!r}")
    scene = scene.with_render(spp=spp, sampler=sampler, seed=seed, adaptive=adaptive, diffraction=diffraction,
                              spectral=spectral, lens_rays=lens_rays, lens_mirrors=lens_mirrors)
    settings = scene.render
    if not 1 <= settings.spp <= MAX_SPP:
        raise InputError("--spp", f"expected an integer from 1 to {MAX_SPP:,}, got {settings.spp}")
    if settings.sampler not in SAMPLERS:
        raise InputError("--sampler", f"expected one of {', '.join(SAMPLERS)}, got {settings.sampler!r}")
    if settings.lens_rays not in (None, *LENS_RAYS):
        raise InputError("--lens-rays", f"expected one of {', '.join(LENS_RAYS)}, got {settings.lens_rays!r}")
    if not 0 <= settings.seed <= MAX_SEED:
        raise InputError("--seed", f"expected an integer from 0 to {MAX_SEED:,}, got {settings.seed}")
    threads = 0 if threads is None else int(threads)
    if threads < 0:
        raise InputError("--threads", f"expected a positive integer, got {threads}")
    threads = min(threads, os.cpu_count() or 1)
    height, width = scene.camera.height_px, scene.camera.width_px
    # Before anything is allocated: too many samples, or more memory than the machine has.
    check_render_budget(width, height, settings.spp, adaptive=settings.adaptive, source=scene.source)

    if model == "composite":  # before its maps are traced: colour needs wavelengths
        from_option = camera is None and effects is not None
        asked = camera.effects if camera is not None else (effects if from_option else scene.render.effects) or ()
        check_spectral_parts(asked, spectral=settings.spectral, source="--effects" if from_option else scene.source,
                             key=None if from_option else "render.effects")
    postfilter = model == "postfilter"
    # The postfilter imitates the thin lens (its image carries that camera) from a pinhole pass.
    camera = camera or camera_for(scene, "thin" if postfilter else model, effects=effects)
    if "diffraction" in getattr(camera, "effects", ()) and diffraction is None:  # the post-filter part
        scene = scene.with_render(diffraction=True)
        settings = scene.render
    # Before the render: a scene that cannot diffract is refused at once.
    aperture = diffraction_aperture(scene, camera) if settings.diffraction else None
    requested_spp = settings.spp
    if postfilter:
        settings = scene.with_render(spp=pinhole_pass_spp(settings.spp)).render
        pinhole = camera_for(scene, "pinhole")
    native_camera = (pinhole if postfilter else camera).native(disk_mapping=settings.disk_mapping)
    if settings.lens_mirrors is not None and hasattr(native_camera, "symmetric_mirror_axes"):
        # Said either way, it holds over LENSCOMPARE_LENS_MIRRORS (which set the camera's default).
        native_camera.mirror_axes = native_camera.symmetric_mirror_axes if settings.lens_mirrors else 0
    native_scene = build_native_scene(scene)
    spectral_info = (make_spectral(native_scene, native_camera, scene, pinhole if postfilter else camera,
                                   traced_wavelengths=traced_wavelengths, sample_wavelengths=sample_wavelengths,
                                   lens_bands=lens_bands, band_roulette=band_roulette)
                     if settings.spectral else None)
    lens_rays_info = None
    if settings.lens_rays == "table" and hasattr(native_camera, "use_ray_table"):
        if spectral_info is not None and spectral_info["camera_disperses"]:
            lens_rays_info = {"from": "traced", "reason": "the lens disperses: each wavelength is traced through "
                                                          "its glass"}
        else:  # refined, or refused (traced), by its measured error
            table_start = time.perf_counter()
            lens_rays_info = use_ray_table(camera, native_camera)
            # Outside `seconds`, as the camera's other set-up (the exit pupil) is.
            lens_rays_info["setup_seconds"] = time.perf_counter() - table_start

    # The poisson sampler's patterns for this spp are made once per process: made here, outside
    # the render's time, as Mitsuba's JIT warm-up is kept out of its (bench_peers.py).
    sampler_setup_seconds = _prepare_sampler(settings)
    start = time.perf_counter()
    pinhole_counts = depth = refined_info = None
    depth_seconds = 0.0
    if postfilter and not settings.adaptive and (postfilter_per_pixel_spp or not postfilter_uniform_pass):
        # the depth buffer first: its silhouettes and each pixel's blur set the pinhole samples
        depth = depth_buffer_m(scene, pinhole, threads=threads, native_scene=native_scene)
        coc = signed_coc_px(depth, camera)
        if postfilter_per_pixel_spp:
            pinhole_counts = pinhole_sample_counts(coc, depth, settings.spp)
        depth_seconds = time.perf_counter() - start
    if pinhole_counts is not None:
        pixels = np.zeros((height, width, 3), dtype=np.float32)
        variance = np.zeros((height, width), dtype=np.float32)
        with progress_bar(height, description=f"{model} {settings.spp} spp", enabled=progress) as bar:
            samples, rays_passed = _render_bands(
                lambda row, row_end: _native.render_rows_adaptive(native_scene, native_camera, pinhole_counts, 0,
                                                                  SAMPLER_CODES[settings.sampler], settings.seed,
                                                                  threads, row, row_end, pixels, variance,
                                                                  mirror_rows=True),
                height, width * float(pinhole_counts.mean()), bar)
        adaptive_info = None
    elif depth is not None:
        pixels, variance, samples, rays_passed, refined_info = _render_refined_pinhole(
            native_scene, native_camera, settings, threads, coc, silhouette_pixels(depth), model, progress)
        adaptive_info = None
    elif settings.adaptive:
        pixels, variance, samples, rays_passed, adaptive_info = _render_adaptive(
            native_scene, native_camera, settings, threads, width, height, model, progress)
    else:
        pixels = np.zeros((height, width, 3), dtype=np.float32)
        variance = np.zeros((height, width), dtype=np.float32)
        with progress_bar(height, description=f"{model} {settings.spp} spp", enabled=progress) as bar:
            samples, rays_passed = _render_bands(
                lambda row, row_end: _native.render_rows(native_scene, native_camera, settings.spp,
                                                         SAMPLER_CODES[settings.sampler], settings.seed, threads, row,
                                                         row_end, pixels, variance, mirror_rows=True),
                height, width * settings.spp, bar)
        adaptive_info = None
    if postfilter:
        pass_seconds = time.perf_counter() - start - depth_seconds
        if depth is None:
            depth = depth_buffer_m(scene, pinhole, threads=threads, native_scene=native_scene)
            depth_seconds = time.perf_counter() - start - pass_seconds
        pixels, _, postfilter_info = spread(pixels, depth, camera, threads=threads,
                                            coc_px=coc if refined_info is not None else None)
        postfilter_info = {"pinhole_spp": settings.spp, "pinhole_seconds": pass_seconds,
                           "depth_seconds": depth_seconds, "filter_seconds": postfilter_info.pop("seconds"),
                           **postfilter_info}
        if pinhole_counts is not None:
            postfilter_info.update(pinhole_mean_spp=float(pinhole_counts.mean()),
                                   pinhole_min_spp=int(pinhole_counts.min()), pinhole_rule=PINHOLE_RULE)
        elif refined_info is not None:
            postfilter_info.update(refined_info)
        variance = None  # the spread mixes pixels: no per-pixel variance of the mean
    seconds = time.perf_counter() - start
    if not np.isfinite(pixels).all():  # the schema's bounds promise a finite image; never hand on NaN
        raise ExternalError(f"the native render of {scene.source} gave non-finite pixels (a bug: please report it "
                            "with the scene file)")

    metadata = {
        "scene": scene.name,
        "model": model,
        "spp": requested_spp,
        "sampler": settings.sampler,
        "disk_mapping": settings.disk_mapping,
        "seed": settings.seed,
        "threads": threads or os.cpu_count(),
        "seconds": seconds,
        "sampler_setup_seconds": sampler_setup_seconds,
        "samples_per_second": samples / seconds if seconds > 0 else float("inf"),
        "ray_pass_fraction": rays_passed / samples,
        "resolution": [width, height],
        "camera": camera.to_json(),
        "renderer": f"lenscompare {__version__} native (Embree 3)",
        "machine": platform.machine(),
    }
    if moves(scene):  # what the image integrates over; a still scene's metadata stays as it was
        metadata["motion"] = {"shutter_s": list(settings.shutter_s), "samples_time": samples_time(scene),
                              "camera_velocity_m_per_s": list(scene.camera.velocity)}
    if lens_rays_info is not None:
        metadata["lens_rays"] = lens_rays_info
    if getattr(native_camera, "mirror_axes", 0):
        metadata["lens_mirror_axes"] = int(native_camera.mirror_axes)  # bit 0 x, bit 1 y (render's lens_mirrors)
    if spectral_info is not None:
        metadata["spectral"] = spectral_info
    if adaptive_info is not None:
        metadata["adaptive"] = adaptive_info
    if model == "composite":
        metadata["effects"] = list(camera.effects)
    if postfilter:
        metadata["postfilter"] = postfilter_info
    if aperture is not None:
        pixels, variance, metadata["diffraction"] = diffract(pixels, variance, aperture)
    return Image(pixels, metadata, camera=camera, variance=variance)


def _render_bands(render_rows, height: int, samples_per_row: float, bar) -> tuple[int, int]:
    """Calls ``render_rows(row, row_end)``, which renders rows [row, row_end)
    and their mirror images (rows height-1-y: a lens system traces them
    together), band by band down the top half, advancing the progress bar;
    returns the samples drawn and the rays that passed the lens."""
    samples = passed = 0
    band_rows = max(8, math.ceil(_BAND_SAMPLES / max(2.0 * samples_per_row, 1.0)))
    half = (height + 1) // 2
    for row in range(0, half, band_rows):
        row_end = min(row + band_rows, half)
        drawn, through = render_rows(row, row_end)
        samples, passed = samples + drawn, passed + through
        mirrored = (height - row) - max(height - row_end, row_end)
        bar.update(row_end - row + max(mirrored, 0))
    return samples, passed


def _render_refined_pinhole(native_scene, camera, settings, threads: int, coc_px: np.ndarray,
                            silhouettes: np.ndarray, model: str, progress: bool | None):
    """The postfilter's pinhole pass in two steps (:mod:`lenscompare.postfilter.refine`):
    ``BASE_PINHOLE_SPP`` film samples (n on silhouettes), then n, the same
    seed's, where the first pass shows an edge. Returns the image, the
    variance of each pixel's mean, the samples drawn, the rays that passed
    and what the pass did."""
    n = settings.spp
    base = min(BASE_PINHOLE_SPP, n)
    height, width = coc_px.shape
    sampler = SAMPLER_CODES[settings.sampler]

    def run_pass(counts: np.ndarray, bar):
        image = np.zeros((height, width, 3), dtype=np.float32)
        variance = np.zeros((height, width), dtype=np.float32)
        samples, passed = _render_bands(
            lambda row, row_end: _native.render_rows_adaptive(native_scene, camera, counts, 0, sampler, settings.seed,
                                                              threads, row, row_end, image, variance,
                                                              mirror_rows=True),
            height, width * float(counts.mean()), bar)
        return image, variance, samples, passed

    with progress_bar(2 * height, description=f"{model} {n} spp", enabled=progress) as bar:
        full = silhouettes if base < n else np.ones(coc_px.shape, dtype=bool)
        pixels, variance, samples, passed = run_pass(np.where(full, n, base).astype(np.uint32), bar)
        redraw = refine_pixels(pixels, variance, coc_px, full)
        if redraw.any():  # n afresh under the same seed: the uniform pass's pixel bit for bit
            second, second_variance, more, more_passed = run_pass(np.where(redraw, n, 0).astype(np.uint32), bar)
            pixels = np.where(redraw[..., None], second, pixels)
            variance = np.where(redraw, second_variance, variance)
            samples, passed = samples + more, passed + more_passed
    drawn = full | redraw
    info = {"pinhole_base_spp": base, "pinhole_mean_spp": samples / (width * height),
            "pinhole_full_fraction": float(drawn.mean()), "pinhole_rule": REFINE_RULE}
    return pixels, variance, samples, passed, info


def _second_pass_seed(seed: int) -> int:
    """Another seed, fixed by the first: a second, independent sample set."""
    return (seed * 0x9E3779B97F4A7C15 + 0x632BE59BD9B4E019) % 2**64


def _render_adaptive(native_scene, camera, settings, threads: int, width: int, height: int, model: str,
                     progress: bool | None):
    """The two passes of :mod:`lenscompare.adaptive`; returns the image, the
    variance of each pixel's mean, the samples drawn, the rays that passed the
    lens and what the passes did."""
    base_spp = adaptive_base_spp(settings.spp)
    sampler = SAMPLER_CODES[settings.sampler]

    def run_pass(sample_end: np.ndarray, first_sample: int, seed: int, bar) -> tuple[np.ndarray, np.ndarray, int, int]:
        image = np.zeros((height, width, 3), dtype=np.float32)
        variance = np.zeros((height, width), dtype=np.float32)
        samples, passed = _render_bands(
            lambda row, row_end: _native.render_rows_adaptive(native_scene, camera, sample_end, first_sample, sampler,
                                                              seed, threads, row, row_end, image, variance,
                                                              mirror_rows=True),
            height, width * float(sample_end.mean()), bar)
        return image, variance, samples, passed

    with progress_bar(2 * height, description=f"{model} adaptive {settings.spp} spp", enabled=progress) as bar:
        first_counts = np.full((height, width), base_spp, dtype=np.uint32)
        first, variance, samples, passed = run_pass(first_counts, 0, settings.seed, bar)
        counts = allocate_samples(variance, base_spp=base_spp, mean_spp=settings.spp)
        refined = counts > base_spp
        # Samplers whose prefixes are stable continue each pixel's sequence
        # (samples [base, n) of n); the others draw a fresh set of n - base
        # under a derived seed. Either way the pixel is the count-weighted
        # mean of both passes, and no sample is drawn twice.
        continues = settings.sampler in PREFIX_SAMPLERS
        if continues:
            second_counts, second_first, second_seed = np.where(refined, counts, base_spp), base_spp, settings.seed
        else:
            second_counts, second_first, second_seed = counts - base_spp, 0, _second_pass_seed(settings.seed)
        if refined.any():
            second, second_variance, more, more_passed = run_pass(second_counts.astype(np.uint32), second_first, second_seed, bar)
            samples, passed = samples + more, passed + more_passed
        else:
            second, second_variance = np.zeros_like(first), np.zeros_like(variance)
    n = counts.astype(np.float64)[..., None]
    pixels = (first.astype(np.float64) * base_spp + second.astype(np.float64) * (n - base_spp)) / n
    # The same weights on the two passes' variances of the mean (independent passes).
    weight_first, weight_second = base_spp / n[..., 0], (n[..., 0] - base_spp) / n[..., 0]
    variance_of_mean = weight_first ** 2 * variance + weight_second ** 2 * second_variance
    info = {"base_spp": base_spp, "mean_spp": samples / (width * height), "max_spp": int(counts.max()),
            "pixels_refined": int(refined.sum()), "continued_sequences": continues}
    return pixels.astype(np.float32), variance_of_mean.astype(np.float32), samples, passed, info


def _prepare_sampler(settings) -> float:
    """Seconds spent making the poisson sampler's patterns for a uniform render's spp (0 when
    they were made before in this process, or for any other sampler or an adaptive render)."""
    if settings.sampler != "poisson" or settings.adaptive:
        return 0.0
    start = time.perf_counter()
    _native.prepare_poisson_patterns(int(settings.spp))
    return time.perf_counter() - start
