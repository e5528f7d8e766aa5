"""Run the real ``povray`` binary on an exported scene and read its EXR back.

What "samples per pixel" means for POV-Ray
------------------------------------------
``spp`` is always the number of camera rays per pixel, as for the native tracer.

- **Thin lens**: ``blur_samples spp, spp`` in the scene file and ``-A`` (no
  anti-aliasing) on the command line. Focal blur traces exactly ``spp`` rays per
  pixel; each picks its own film position, uniformly jittered over the pixel
  (a 16 x 16 grid cell plus jitter) — the box filter our jittered samples
  integrate — and a lens position from POV-Ray's fixed hexagonal-then-sub-random
  pattern over the disk, jittered per pixel. min = max, so the adaptive
  confidence test never stops a pixel early. (POV-Ray's film jitter is off
  centre by 1/32 px; the exported camera cancels it, see
  :mod:`lenscompare.povray.export`.)
- **Pinhole**: no focal blur, so pixels are sampled by anti-aliasing method 1
  (``+AM1 +A0.0 +J1.0 +R<n>``). Threshold 0 makes every pixel supersampled: a
  centre ray plus an n x n grid of jittered sub-pixel rays, all n² + 1
  averaged — a box filter over the pixel with its centre counted once more.
  n is the smallest with n² + 1 >= spp, at most 9 (POV-Ray's limit), so
  ``spp`` is rounded up to n² + 1 (2, 5, 10, 17, 26, ..., 82) and the metadata
  reports the rays actually traced. Point projections agree with the native
  pinhole within 0.05 px (tests/test_povray_agreement.py).

POV-Ray has no random seed: the same input gives the same image.

Motion blur: POV-Ray 3.7 has none, so a moving scene (``[render] shutter``
open over an interval, something with a velocity) is rendered as the average
of K sub-frames at the centres of K equal parts of the shutter
(``time_samples``), each with ceil(spp / K) rays per pixel, so that the whole
image still traces about spp rays per pixel. The K sub-frames are one POV-Ray
animation (frame k includes sub-frame k's file), not K processes: each POV-Ray
process spends about 0.65 s waiting in its own start-up and shut-down whatever
it renders (0.03 s of tracing in a 0.7 s run of a small frame), so 32
sub-frames took 22.7 s as processes and 7.8 s as one animation, the same
pixels bit for bit (session 40); each further frame still waits about 0.2 s.
A streak of L px is then K copies L / K px apart; with L / K at most about
1 px they merge into the continuous streak the native tracer integrates (the
agreement tests' scenes: see tests/test_povray_motion.py). So K is sized from
the scene (:func:`subframes_for`, since session 41): the longest streak any
object draws over the shutter (:func:`lenscompare.motion_path.longest_motion_path`,
the planner's ``motion_blur``) over :data:`MAX_SUBFRAME_SPACING_PX`, at most
:data:`MAX_AUTO_TIME_SAMPLES`; before, K was 32 whatever the streak, which
left copies 3 px apart on a 100 px streak and spent 32 frames on a 7 px one.

Environment: POV-Ray runs in a fresh private temporary folder (its cwd, which
its I/O restrictions allow it to write), with ``HOME`` pointing there and
``POVINI`` unset, so no user or stray ``povray.ini`` changes the render; Debian's
``/etc/povray/3.7/povray.ini`` is read but every setting it makes that matters
(size, display, anti-aliasing, output type) is overridden on the command line.
It may write only inside that folder, and no file larger than the image needs
(:mod:`lenscompare.povray.sandbox`, the second barrier behind the exporter's
escaping).

Bright scenes: POV-Ray writes half floats, which end at 65504. When a scene can
be brighter (:func:`~lenscompare.povray.export.radiance_bound`), every emitter
and light is exported scaled down by a power of two and the image scaled back
(exact in floating point; values below 6e-5 of the new scale lose relative
precision). A POV-Ray image with a non-finite pixel is refused (exit 1), never
handed on.
"""

from __future__ import annotations

import math
import os
import re
import shlex
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..cameras import CameraModel
from ..errors import ExternalError, InputError
from ..image import Image, read_exr
from ..limits import check_render_budget
from ..motion import geometry_at_s, samples_time, subframe_times_s
from ..motion_path import longest_motion_path
from ..scene import Scene
from .export import pov_camera, radiance_bound, scene_to_pov
from .sandbox import confined_writes

__all__ = ["render_povray", "povray_version", "pinhole_antialias_depth", "run_povray", "run_povray_frames",
           "subframes_for", "pinhole_subframes", "longest_streak_px", "MAX_ANTIALIAS_DEPTH", "MAX_POVRAY_SPP",
           "HALF_FLOAT_SAFE", "MAX_SUBFRAME_SPACING_PX", "MAX_AUTO_TIME_SAMPLES", "MAX_TIME_SAMPLES"]

MAX_SUBFRAME_SPACING_PX = 1.0
"""Largest gap between a streak's copies that :func:`subframes_for` leaves."""

MAX_AUTO_TIME_SAMPLES = 256
"""Most sub-frames :func:`subframes_for` chooses (each is a POV-Ray frame that
waits about 0.2 s); a longer streak keeps copies further apart, and the
image's metadata says how far (``subframe_spacing_px``)."""

MAX_TIME_SAMPLES = 4096
"""Sub-frames at most: each is a frame of one POV-Ray animation, with its own
parse and set-up (the frame files are numbered with four digits)."""

MAX_ANTIALIAS_DEPTH = 9
"""POV-Ray 3.7's largest ``+R`` (anti-aliasing depth)."""

MAX_POVRAY_SPP = 65_536
"""POV-Ray's focal-blur set-up grows faster than its sample count: 65,536
samples spend about 4 s before tracing, 2^20 samples 6.6 min (measured)."""

HALF_FLOAT_SAFE = 32_768.0
"""Brightest value exported unscaled (half floats end at 65504)."""

_STDERR_TAIL_LINES = 12
_TRACE_TIME = re.compile(r"Trace Time:.*\(([0-9.]+) seconds\)\s*using \d+ thread\(s\) with ([0-9.]+) CPU-seconds")
_VERSION = re.compile(r"POV-Ray\s+([0-9][0-9A-Za-z.\-+]*)")


def pinhole_antialias_depth(spp: int) -> int:
    """Anti-aliasing depth n for the pinhole: the smallest with n² + 1 >= spp (1..9).

    Examples
    --------
    >>> [pinhole_antialias_depth(s) for s in (1, 2, 5, 6, 64, 1000)]
    [1, 1, 2, 3, 8, 9]
    """
    n = max(1, math.ceil(math.sqrt(max(spp - 1, 1))))
    return min(n, MAX_ANTIALIAS_DEPTH)


def povray_version(povray: str = "povray") -> str:
    """The version line of ``povray --version`` (e.g. "POV-Ray 3.7.0.10.unofficial").

    Raises
    ------
    ExternalError
        The binary cannot be run.
    """
    try:
        result = subprocess.run([povray, "--version"], capture_output=True, text=True, timeout=30,
                                env=_clean_env(tempfile.gettempdir()), errors="replace")
    except (OSError, subprocess.TimeoutExpired) as error:
        raise ExternalError(_missing_message(povray, error)) from None
    for line in (result.stdout + "\n" + result.stderr).splitlines():
        if _VERSION.search(line) and "configuration" not in line:
            return line.strip()
    raise ExternalError(f"POV-Ray ({povray}) printed no version: {_tail(result.stderr or result.stdout)}")


def render_povray(scene: Scene, *, model: str | None = None, spp: int | None = None, threads: int | None = None,
                  povray: str = "povray", timeout_s: float | None = None,
                  blur_adaptive: tuple[int, float] | None = None, time_samples: int | None = None) -> Image:
    """Render ``scene`` with POV-Ray through the pinhole or the thin lens.

    Parameters
    ----------
    scene : Scene
        A loaded scene (:func:`lenscompare.scene.load_scene`).
    model : {'pinhole', 'thin'}, optional
        Camera model; default the scene's ``camera.model``.
    spp : int, optional
        Camera rays per pixel (default the scene's ``render.spp``): the thin
        lens's ``blur_samples``; for the pinhole rounded up to n² + 1 (see the
        module notes).
    threads : int, optional
        POV-Ray's worker threads (``+WT``); default: POV-Ray's own (all cores).
    povray : str, optional
        The POV-Ray binary (name on ``PATH`` or a path).
    timeout_s : float, optional
        Give up (and stop POV-Ray) after this many seconds.
    blur_adaptive : (int, float), optional
        Thin lens only: POV-Ray's adaptive focal blur, ``(min_samples,
        variance)``, with ``spp`` the most a pixel takes (see
        :func:`lenscompare.povray.export.scene_to_pov`). The metadata's
        ``spp`` is then that maximum, not the rays traced.
    time_samples : int, optional
        Sub-frames averaged for a moving scene (module notes; default
        :func:`subframes_for`'s, from the scene's longest streak); a still
        scene is one frame whatever this says.

    Returns
    -------
    Image
        Linear radiance, float32, row 0 at the top — like a native render.
        POV-Ray writes half floats, so values carry about 3 significant digits.
        Metadata: scene, model, spp, seconds (POV-Ray's own trace time),
        wall_seconds (the whole process), cpu_seconds (POV-Ray's CPU time
        for the trace, all threads), samples_per_second, threads,
        resolution, camera, renderer (POV-Ray's version line), command.

    Raises
    ------
    InputError
        A model POV-Ray cannot render (thick, lens) or a bad option.
    ExternalError
        POV-Ray is missing, fails, times out or writes no image; the message
        ends with POV-Ray's last lines of output.
    """
    model = model or scene.camera.model
    camera = pov_camera(scene, model)  # refuses thick / lens before anything runs
    spp = scene.render.spp if spp is None else int(spp)
    if not 1 <= spp <= MAX_POVRAY_SPP:
        raise InputError("--spp", f"expected an integer from 1 to {MAX_POVRAY_SPP:,} for POV-Ray, got {spp} "
                         "(its focal-blur set-up grows faster than the sample count)")
    if threads is not None and int(threads) < 1:
        raise InputError("--threads", f"expected a positive integer, got {threads}")
    if threads is not None:
        threads = min(int(threads), os.cpu_count() or 1)
    width, height = scene.camera.width_px, scene.camera.height_px
    check_render_budget(width, height, spp, source=scene.source)

    if blur_adaptive is not None and model != "thin":
        raise InputError("blur_adaptive", "POV-Ray's adaptive focal blur needs the thin-lens camera")
    if time_samples is not None and not 1 <= int(time_samples) <= MAX_TIME_SAMPLES:
        raise InputError("--time-samples", f"expected an integer from 1 to {MAX_TIME_SAMPLES:,}, got {time_samples}")
    # A moving scene: K sub-frames at evenly spaced times, each with its share of the rays.
    streak_px = None
    if not samples_time(scene):
        times = [scene.render.shutter_s[0]]
    else:
        streak_px = longest_streak_px(scene, camera.camera)
        count = int(time_samples) if time_samples is not None else subframes_for(streak_px)
        if time_samples is None and model != "thin":
            count = pinhole_subframes(count, spp)
        times = subframe_times_s(scene.render.shutter_s, count).tolist()
    frame_spp = max(1, math.ceil(spp / len(times)))
    if model == "thin":
        sampling = ["-A"]  # focal blur samples the pixel area itself
        rays_per_pixel = frame_spp
    else:
        depth = pinhole_antialias_depth(frame_spp)
        sampling = ["+A0.0", "+AM1", f"+R{depth}", "+J1.0"]
        rays_per_pixel = depth * depth + 1
    # The brightest any sub-frame can be (inverse-square lights count at the nearest surface then).
    bound = max(radiance_bound(geometry_at_s(scene, t)) for t in times)
    # A power of two: exact both ways, so scenes inside half floats' range are untouched.
    radiance_scale = 2.0 ** -math.ceil(math.log2(bound / HALF_FLOAT_SAFE)) if bound > HALF_FLOAT_SAFE else 1.0
    options = ["+FE", "-D", "-V", "+Q9", "-UA", f"+W{width}", f"+H{height}", *sampling]
    if threads is not None:
        options.append(f"+WT{int(threads)}")
    texts = [scene_to_pov(scene, model=model, spp=frame_spp, blur_adaptive=blur_adaptive,
                          radiance_scale=radiance_scale, time_s=time_s) for time_s in times]
    frames, result, wall_seconds, command = run_povray_frames(texts, options, povray=povray, timeout_s=timeout_s,
                                                              max_file_bytes=64 * 2**20 + 16 * width * height)
    total = np.zeros((height, width, 3), dtype=np.float64)
    for pixels in frames:
        if pixels is None:
            raise ExternalError(f"POV-Ray wrote no image (command: {shlex.join(command)}){_tail(result.stderr)}")
        if pixels.shape != (height, width, 3):
            raise ExternalError(f"POV-Ray wrote a {pixels.shape[1]}x{pixels.shape[0]} image, expected "
                                f"{width}x{height}")
        if not np.isfinite(pixels).all():
            raise ExternalError(f"POV-Ray's image of {scene.source} has non-finite pixels (its half-float EXR; "
                                f"radiance bound {bound:.3g}, exported at scale {radiance_scale:g})")
        total += pixels
    # Each frame's own trace time (and CPU time) from its statistics; a frame
    # without them (or under their 1 ms) counts its share of the process's wall time.
    traced = [(float(m.group(1)), float(m.group(2))) for m in _TRACE_TIME.finditer(result.stderr)]
    frame_share_s = wall_seconds / len(times)
    seconds = sum(s if s > 0 else frame_share_s for s, _ in traced) + frame_share_s * (len(times) - len(traced))
    cpu_seconds = sum(c for _, c in traced) if len(traced) == len(times) else None
    pixels = (total / len(times)).astype(np.float32)
    if radiance_scale != 1.0:
        pixels = pixels / np.float32(radiance_scale)
    rays_per_pixel *= len(times)

    samples = width * height * rays_per_pixel
    metadata = {
        "scene": scene.name,
        "model": model,
        "spp": rays_per_pixel,
        "spp_requested": spp,
        "seconds": seconds,
        "wall_seconds": wall_seconds,
        "cpu_seconds": cpu_seconds,
        "samples_per_second": samples / seconds if seconds > 0 else float("inf"),
        "threads": int(threads) if threads is not None else os.cpu_count(),
        "resolution": [width, height],
        "camera": camera.camera.to_json(),
        "povray_camera": camera.as_metadata(),
        "renderer": _version_from_banner(result.stderr) or "POV-Ray",
        "command": shlex.join(command),
        "pixel_sampling": ((f"adaptive focal blur: blur_samples {min(blur_adaptive[0], spp)}, N, "
                            f"variance {blur_adaptive[1]:g}, -A" if blur_adaptive else
                            "focal blur: blur_samples N, N, -A") if model == "thin"
                           else f"anti-aliasing method 1, threshold 0, depth {depth}: centre + {depth}x{depth} "
                                "jittered sub-pixel rays"),
        "lenscompare_version": __version__,
    }
    if streak_px is not None:
        metadata["time_samples"] = len(times)  # sub-frames averaged, each with spp / time_samples rays
        metadata["shutter_s"] = list(scene.render.shutter_s)
        metadata["streak_px"] = streak_px  # the longest streak (px), motion_path.longest_motion_path
        metadata["subframe_spacing_px"] = streak_px / len(times)  # between its copies
    if radiance_scale != 1.0:
        metadata["radiance_scale"] = radiance_scale  # what the exported scene was multiplied by
    return Image(pixels.astype("float32", copy=False), metadata, camera=camera.camera)


def longest_streak_px(scene: Scene, camera: CameraModel) -> float:
    """The longest streak (px) any object of ``scene`` draws on ``camera``'s
    film over the shutter (:func:`lenscompare.motion_path.longest_motion_path`);
    0 for a still scene."""
    path = longest_motion_path(scene, camera)
    return 0.0 if path is None else path.length_px


def subframes_for(streak_px: float) -> int:
    """Sub-frames a moving scene's POV-Ray reference takes by default: enough
    that a streak of ``streak_px`` (the scene's longest,
    :func:`lenscompare.motion_path.longest_motion_path`) has its copies at most
    :data:`MAX_SUBFRAME_SPACING_PX` apart, at least 1 and at most
    :data:`MAX_AUTO_TIME_SAMPLES`."""
    wanted = math.ceil(streak_px / MAX_SUBFRAME_SPACING_PX) if math.isfinite(streak_px) else MAX_AUTO_TIME_SAMPLES
    return int(min(MAX_AUTO_TIME_SAMPLES, max(1, wanted)))


def pinhole_subframes(least: int, spp: int) -> int:
    """The pinhole's sub-frames for ``spp`` rays a pixel: the smallest count
    from ``least`` to twice it (at most :data:`MAX_AUTO_TIME_SAMPLES`) whose
    frames trace at most an eighth more rays than spp in all, else the count
    there that traces the fewest. Each frame traces n² + 1 rays a pixel
    (:func:`pinhole_antialias_depth` of its share), so the count decides how
    many are wasted: 14 frames for 256 spp take 26 rays each (364 in all), 16
    take 17 (272); and each frame more costs POV-Ray about 0.2 s of waiting.

    Examples
    --------
    >>> pinhole_subframes(14, 256), pinhole_subframes(7, 256), pinhole_subframes(1, 4)
    (16, 7, 2)
    """

    def rays(k):
        return k * (pinhole_antialias_depth(math.ceil(spp / k)) ** 2 + 1)

    counts = range(least, max(least, min(2 * least, MAX_AUTO_TIME_SAMPLES)) + 1)
    return next((k for k in counts if 8 * rays(k) <= 9 * spp), min(counts, key=lambda k: (rays(k), k)))


def run_povray(text: str, options: list[str], *, povray: str = "povray", timeout_s: float | None = None,
               max_file_bytes: int = 2**30):
    """Run POV-Ray on SDL ``text`` in a private folder, confined to it.

    Returns ``(pixels or None, completed process, wall seconds, command)``:
    the pixels of ``out.exr`` when POV-Ray wrote one. ``options`` are POV-Ray
    command-line options beyond input and output.

    Raises
    ------
    ExternalError
        POV-Ray is missing, fails, times out, or its output cannot be read.
    """
    frames, result, wall_seconds, command = run_povray_frames([text], options, povray=povray, timeout_s=timeout_s,
                                                              max_file_bytes=max_file_bytes)
    return frames[0], result, wall_seconds, command


def run_povray_frames(texts: list[str], options: list[str], *, povray: str = "povray",
                      timeout_s: float | None = None, max_file_bytes: int = 2**30):
    """Run POV-Ray once on the SDL ``texts``, frame by frame, in a private
    folder, confined to it.

    One text is rendered as ``run_povray`` describes. Several are one
    animation (``+KFI1 +KFF<n>``): frame k's scene file includes
    ``frame<k>.pov``, which holds ``texts[k - 1]``, so each frame parses only
    its own text, and POV-Ray's fixed start-up and shut-down are paid once.

    Returns ``(frames, completed process, wall seconds, command)``: ``frames``
    holds each text's pixels in order (None where POV-Ray wrote no image);
    the process's standard error holds every frame's statistics in order.

    Raises
    ------
    ExternalError
        POV-Ray is missing, fails, times out, or its output cannot be read.
    """
    count = len(texts)
    if not 1 <= count <= MAX_TIME_SAMPLES:
        raise InputError("texts", f"expected 1 to {MAX_TIME_SAMPLES:,} scene texts, got {count}")
    with tempfile.TemporaryDirectory(prefix="lenscompare-povray-") as folder:
        work = Path(folder)
        if count == 1:
            (work / "scene.pov").write_text(texts[0], encoding="utf-8")
            frame_options, outputs = [], [work / "out.exr"]
        else:
            for k, text in enumerate(texts, start=1):
                (work / f"frame{k:04d}.pov").write_text(text, encoding="utf-8")
            (work / "scene.pov").write_text('#include concat("frame", str(frame_number, -4, 0), ".pov")\n',
                                            encoding="utf-8")
            # POV-Ray numbers an animation's outputs with as many digits as its last frame has.
            digits = len(str(count))
            frame_options, outputs = ["+KFI1", f"+KFF{count}"], [work / f"out{k:0{digits}d}.exr"
                                                                  for k in range(1, count + 1)]
        command = [povray, "+Iscene.pov", "+Oout.exr", *options, *frame_options]
        preexec, pass_fds, _ = confined_writes(work, max_file_bytes=max_file_bytes)
        start = time.perf_counter()
        try:
            result = subprocess.run(command, cwd=work, env=_clean_env(folder), capture_output=True, text=True,
                                    errors="replace", timeout=timeout_s, stdin=subprocess.DEVNULL,
                                    preexec_fn=preexec, pass_fds=pass_fds)
        except subprocess.TimeoutExpired as error:
            stderr = error.stderr.decode(errors="replace") if isinstance(error.stderr, bytes) else error.stderr
            raise ExternalError(f"POV-Ray did not finish within {timeout_s:g} s (command: {shlex.join(command)})"
                                f"{_tail(stderr or '')}") from None
        except (OSError, subprocess.SubprocessError) as error:
            raise ExternalError(_missing_message(povray, error)) from None
        finally:
            for fd in pass_fds:
                os.close(fd)
        wall_seconds = time.perf_counter() - start
        if result.returncode != 0:
            raise ExternalError(f"POV-Ray failed (exit status {result.returncode}; command: {shlex.join(command)})"
                                f"{_tail(result.stderr)}")
        frames = []
        for output in outputs:
            if not output.is_file():
                frames.append(None)
                continue
            try:
                frames.append(read_exr(output).pixels)
            except InputError as error:
                raise ExternalError(f"POV-Ray's output cannot be read ({error.problem})"
                                    f"{_tail(result.stderr)}") from None
    return frames, result, wall_seconds, command


def _clean_env(home: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "POVINI"}
    env["HOME"] = home
    return env


def _version_from_banner(stderr: str) -> str | None:
    for line in stderr.splitlines():
        if "Persistence of Vision" in line and "Version" in line:
            match = re.search(r"Version\s+(\S+)", line)
            if match:
                return f"POV-Ray {match.group(1)}"
    return None


def _missing_message(povray: str, error: BaseException) -> str:
    if isinstance(error, FileNotFoundError) or shutil.which(povray) is None:
        return (f"POV-Ray is not installed or not on PATH (tried {povray!r}); install Debian's 'povray' package "
                "(make install does) or pass the binary's path")
    return f"POV-Ray ({povray}) could not be run: {error}"


def _tail(stderr: str) -> str:
    """POV-Ray's last meaningful lines, to end an error message with."""
    lines = [line.rstrip() for line in (stderr or "").splitlines()
             if line.strip() and "cannot open the user configuration file" not in line]
    if not lines:
        return ""
    return "\nPOV-Ray said:\n  " + "\n  ".join(lines[-_STDERR_TAIL_LINES:])
