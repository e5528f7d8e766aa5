"""The planner's predicted effect sizes against sizes measured on full
lens-system renders (issue 14's prediction study).

Each effect is measured with the project's own metric on a lens-system render
through the scene's camera (lens, f-number, focus distance and focus mode,
pixel pitch) looking at a *probe*: content that metric can read, since a lit
scene offers no isolated point or flat field. The probes:

==============  ======================================================  ==========================
effect          probe (camera space: x right, y up, z along the view)   measured
==============  ======================================================  ==========================
defocus         an emissive point on the axis at the nearest and at     largest blur-disk diameter
                the farthest visible depth (one render each)            (second moment, eq.-5 window),
                                                                        less the focus spot (quadrature)
aberrations     points on the plane of focus, on the axis and at the    largest spot diameter, in
                field imaged at the film corner (one render each)       the window of spot_window
distortion      a point on the plane of focus at the paraxial corner    its centroid's radial shift
                field                                                   from the paraxial image
vignetting      a uniform emitter (background radiance 1)               falloff at the corner radius
==============  ======================================================  ==========================

The film is widened by :data:`MARGIN_PX` pixels on every side (same pixel
pitch, same pixel grid), so that a spot at the film corner lies whole inside
the image; the lens system's image of the original frame is unchanged by it.
A point's emissive sphere is sized so that its sharp image on the axis is
:data:`SOURCE_PX` scene pixels wide; off the axis its sharp image is an
ellipse (:func:`source_image_diameter_px`), and that ellipse is what is taken
out of the measured second moment. Spots near focus are measured on a
:data:`SUBPIXELS`-times finer film (see :class:`_Probe`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..cameras import camera_for
from ..errors import InputError
from ..lenses import chief_ray_film_height_mm
from ..metrics import find_point_sources, measure_blur_disk, relative_illumination_at
from ..optics import circle_of_confusion_mm
from ..render import render
from ..scene import EmissiveMaterial, Scene, Sphere
from ..units import mm_from_m
from .effects import corner_field_deg, ideal_camera
from .spot_window import settled_window_px
from .visible_depth import visible_depth_range_m

__all__ = ["Comparison", "compare_predictions", "source_image_diameter_px", "STUDIED_EFFECTS", "MARGIN_PX", "SUBPIXELS", "SOURCE_PX", "RELATIVE_AGREEMENT"]

STUDIED_EFFECTS = ("defocus", "aberrations", "distortion", "vignetting")
MARGIN_PX = 40
SUBPIXELS = 4
SOURCE_PX = 2.5
"""Sharp image of a probe point, in the scene's pixels. Wide enough that the
point is hit often (hits per render ~ spp x its image area in rendered pixels)
and that box pixels sample it smoothly; its variance is taken out. On the
finer film of spots near focus the source is SOURCE_PX of *those* pixels wide
(1/SUBPIXELS of a scene pixel): a sub-pixel spot is then not swamped by the
source's own second moment, which is only known to the Monte Carlo noise of
the hits (a 0.3 px spot under a 3.3 px source image: 0.8 % of the measured
variance, below that noise at 4096 spp)."""
FINE_RAYS = 4
"""Rays per spot on the finer film, against the scene's spp on its own film:
its source is SUBPIXELS^2 times smaller in area, so hit that much less often."""
RELATIVE_AGREEMENT = 0.15
"""Done-when of issue 14: predicted within 15 % of measured, or both under tolerance."""


@dataclass(frozen=True)
class Comparison:
    """One scene's one effect: predicted from the scene alone, measured on a render."""

    scene: str
    effect: str
    unit: str
    predicted: float
    measured: float | None   # None: the probe shows nothing to measure (detail says why)
    within: bool | None
    detail: str

    def to_json(self) -> dict:
        return {"scene": self.scene, "effect": self.effect, "unit": self.unit, "predicted": self.predicted,
                "measured": self.measured, "within": self.within, "detail": self.detail}


def agrees(predicted: float, measured: float, tolerance: float) -> bool:
    """Within :data:`RELATIVE_AGREEMENT` of the measured size, or both under ``tolerance``."""
    if predicted <= tolerance and measured <= tolerance:
        return True
    return abs(predicted - measured) <= RELATIVE_AGREEMENT * measured


def compare_predictions(scene: Scene, plan, *, spp: int = 256, threads: int | None = None,
                        effects=STUDIED_EFFECTS) -> list[Comparison]:
    """Each studied effect of ``plan`` (a :class:`lenscompare.plan.Plan` of
    ``scene``) against its size measured on lens-system renders of probes."""
    tolerance = {"px": plan.tolerance_px, "%": plan.tolerance_percent}
    probe = _Probe(scene, spp=spp, threads=threads)
    out = []
    for name in effects:
        effect = plan.effects[name]
        measured, detail = getattr(probe, name)()
        within = None if measured is None else agrees(effect.magnitude, measured, tolerance[effect.unit])
        out.append(Comparison(scene.name, name, effect.unit, effect.magnitude, measured, within, detail))
    return out


def source_image_diameter_px(film_height_mm, camera_xyz_m, radius_m: float, *, pixel_pitch_mm: float) -> float:
    """Diameter (px) of the round disk whose second moment is that of the
    sharp image of an emissive sphere, for a lens whose chief rays land at
    ``film_height_mm(field_deg)`` (mm; a perfect rectilinear lens: ``f tan``).

    Off the axis a sphere's image is an ellipse, not the disk it is on the
    axis: across the field it spans 2 alpha r / sin(theta) (alpha: the
    sphere's angular radius, r: its film height), along it 2 alpha dr/dtheta.
    For a rectilinear lens that is 1/cos(theta) longer radially than
    on the axis (the sphere stands obliquely to the film); a lens whose
    distortion changes fast with the field stretches it further (wide.22mm at
    its 44 deg corner: 11 % more than f tan). Taking out a round disk there
    instead leaves the source's own shape in the measured spot, read as
    aberration (wide_stopped_down, 0.3 px spot: 2.1 px measured).

    Parameters
    ----------
    film_height_mm : callable
        Film height (mm, either sign) of the chief ray at a field angle (deg).
    camera_xyz_m : (float, float, float)
        The sphere's centre in camera space (from the entrance pupil), m.
    radius_m : float
        The sphere's radius, m.
    pixel_pitch_mm : float
        The film's pixel pitch, mm.
    """
    x, y, z = (float(c) for c in camera_xyz_m)
    theta = math.atan2(math.hypot(x, y), z)
    alpha = math.asin(min(1.0, radius_m / math.sqrt(x * x + y * y + z * z)))
    step = math.radians(0.05)
    height = lambda t: abs(film_height_mm(math.degrees(t)))  # noqa: E731
    if theta < step:  # at the axis both spans are the scale r / theta
        across = along = height(step) / step
    else:
        across = height(theta) / math.sin(theta)
        along = (height(theta + step) - height(theta - step)) / (2.0 * step)
    a, b = 2.0 * alpha * along / pixel_pitch_mm, 2.0 * alpha * across / pixel_pitch_mm
    return math.sqrt(0.5 * (a * a + b * b))  # a uniform ellipse's second moment, as a disk's diameter


class _Probe:
    """Renders of probe content through one scene's lens-system camera.

    Spots at the plane of focus are often smaller than a pixel, which box
    pixels cannot measure (a point on a pixel corner reads as a 1.3 px disk).
    Those probes are rendered on a film :data:`SUBPIXELS` times finer (same
    film, same lens and film position; spp / SUBPIXELS^2, so the same rays per
    spot) and converted back to the scene's pixels.
    """

    def __init__(self, scene: Scene, *, spp: int, threads: int | None):
        self.scene, self.spp, self.threads = scene, spp, threads
        w, h = scene.camera.resolution
        self.pitch_mm = scene.camera.film_mm[0] / w
        self.half_diagonal_px = 0.5 * math.hypot(w, h)
        self.wide = self._widened(1)
        self.fine = self._widened(SUBPIXELS)
        self.system = camera_for(self.wide)
        self._corners = {}

    def _widened(self, subpixels: int) -> Scene:
        w, h = self.scene.camera.resolution
        wide_px = ((w + 2 * MARGIN_PX) * subpixels, (h + 2 * MARGIN_PX) * subpixels)
        return self.scene.with_camera(model="lens", resolution=wide_px,
                                      film_mm=(wide_px[0] * self.pitch_mm / subpixels,
                                               wide_px[1] * self.pitch_mm / subpixels))

    # --- one method per studied effect: (measured size or None, detail) ---

    def defocus(self):
        """The largest blur on the axis at a visible depth, less the lens's own
        spot at the plane of focus: second moments of independent blurs add
        (variances of a convolution), and the planner sizes that spot
        separately as ``aberrations``; the detail keeps the raw blur."""
        ideal = ideal_camera(self.scene)
        tan_w, tan_h = ideal.screen_half_extent
        depth = visible_depth_range_m(self.scene, tan_half_w=tan_w, tan_half_h=tan_h)
        if depth is None:
            return None, "nothing in the frame"
        sizes = []
        for z in sorted(set(depth)):
            coc_px = circle_of_confusion_mm(mm_from_m(z), focus_distance_mm=self.system.focus_distance_mm,
                                            focal_length_mm=self.system.focal_length_mm,
                                            aperture_diameter_mm=self.system.aperture_diameter_mm) / self.pitch_mm
            # Disks of a few pixels and more: the scene's own pixels and
            # measure.py's window (eq. 5 + source + 4 px); smaller ones finer.
            spot = self._point_spot((0.0, 0.0, z), window_px=coc_px + SOURCE_PX + 4.0, fine=coc_px < 4.0)
            sizes.append((0.0 if spot is None else spot[0], z))
        raw, z = max(sizes)
        focus = self._axis_spot()
        size = math.sqrt(max(0.0, raw * raw - focus * focus))
        return size, (f"blur {raw:.3g} px on axis at {z:.4g} m less the {focus:.3g} px focus spot "
                      f"(visible {depth[0]:.3g}-{depth[1]:.3g} m)")

    def _axis_spot(self) -> float:
        if not hasattr(self, "_axis"):
            spot = self._point_spot((0.0, 0.0, self.system.focus_distance_m), window_px=None, fine=True)
            self._axis = 0.0 if spot is None else spot[0]
        return self._axis

    def aberrations(self):
        axis_px = self._axis_spot()
        corner, where = self._corner_spot(real=True)
        if corner is None:
            return axis_px, f"spot {axis_px:.3g} px on axis; {where}"
        return max(axis_px, corner[0]), f"spot {axis_px:.3g} px on axis, {corner[0]:.3g} px at the corner ({where})"

    def distortion(self):
        corner, where = self._corner_spot(real=False)
        if corner is None:
            return None, where
        shift = corner[1] - self.half_diagonal_px  # the probe sits at the ideal (paraxial) corner
        return abs(shift), f"corner point {shift:+.3g} px from its paraxial image ({where})"

    def vignetting(self):
        flat = replace(self.wide, objects=(), lights=(), background=(1.0, 1.0, 1.0))
        pixels = render(flat, spp=self.spp, threads=self.threads, progress=False).pixels
        ri = float(relative_illumination_at(pixels, self.half_diagonal_px, n_bins=int(self.half_diagonal_px // 4)))
        return 100.0 * (1.0 - ri), f"flat field: relative illumination {ri:.3f} at the corner radius"

    # --- probes ---

    def _corner_spot(self, *, real: bool):
        """(spot diameter px, centroid radius px) of a point on the focus plane
        toward the upper-right film corner, or None; and a note. ``real``: at
        the field whose real chief ray lands on the corner (where the
        aberrations are sized); else at the paraxial corner field (the ideal
        image point distortion is measured from)."""
        if real not in self._corners:
            w, h = self.scene.camera.resolution
            scale, focus_m = self.system.image_scale_mm, self.system.focus_distance_m
            tan_x, tan_y = 0.5 * w * self.pitch_mm / scale, 0.5 * h * self.pitch_mm / scale
            field = math.degrees(math.atan(math.hypot(tan_x, tan_y)))
            if real:
                field_real = corner_field_deg(self.scene, camera_for(self.scene, "lens"))
                stretch = math.tan(math.radians(field_real)) / math.tan(math.radians(field))
                tan_x, tan_y, field = tan_x * stretch, tan_y * stretch, field_real
            spot = self._point_spot((tan_x * focus_m, tan_y * focus_m, focus_m), window_px=None, fine=True)
            self._corners[real] = (spot, f"corner field {field:.3g} deg" if spot else
                                   f"no light at the film corner ({field:.3g} deg field): outside the image circle")
        return self._corners[real]

    def _film_height_mm(self, field_deg: float) -> float:
        """The lens system's chief-ray film height at a field angle (mm); a
        perfect lens's when no chief ray gets through there."""
        try:
            return chief_ray_film_height_mm(self.system.prescription, field_deg,
                                            focus_distance_m=self.system.focus_distance_m)
        except InputError:
            return self.system.image_scale_mm * math.tan(math.radians(field_deg))

    def _point_spot(self, camera_xyz_m, *, window_px, fine: bool):
        """Render one emissive point; (blur-disk diameter, centroid distance
        from the image centre), both in the scene's pixels, measured in
        ``window_px`` about the source (None: the rule of :mod:`.spot_window`);
        None when the point is dark."""
        k = SUBPIXELS if fine else 1
        base = self.fine if fine else self.wide
        x, y, z = camera_xyz_m
        origin, right, up, forward = (np.asarray(v) for v in self.system.frame)
        centre = origin + x * right + y * up + z * forward
        radius_m = 0.5 * SOURCE_PX / k * self.pitch_mm * z / self.system.image_scale_mm
        probe = replace(base, materials={"glow": EmissiveMaterial("glow", (1.0, 1.0, 1.0))},
                        objects=(Sphere(tuple(float(c) for c in centre), radius_m, "glow"),), lights=(),
                        background=(0.0, 0.0, 0.0))
        pixels = render(probe, spp=max(4, self.spp * (FINE_RAYS if fine else 1) // (k * k)), threads=self.threads, progress=False).pixels
        source_px = source_image_diameter_px(self._film_height_mm, (x, y, z), radius_m, pixel_pitch_mm=self.pitch_mm)
        found = find_point_sources(pixels)
        if not found:
            return None
        expected = camera_for(probe).project_px(np.array([x, y, z]))
        source = min(found, key=lambda s: math.dist(s.centroid_px, expected))

        def measured(window):  # in the scene's pixels
            return measure_blur_disk(pixels, center_px=source.centroid_px, window_radius_px=window * k,
                                     source_diameter_px=source_px * k)

        if window_px is None:
            start = MARGIN_PX - 2.0
            window_px, _ = settled_window_px(lambda r: measured(min(r, start)).second_moment_diameter_px / k,
                                             start_px=start)
            window_px = min(window_px, start)
        disk = measured(window_px)
        radius = math.dist(disk.centroid_px, (pixels.shape[1] / 2.0, pixels.shape[0] / 2.0))
        return disk.second_moment_diameter_px / k, radius / k
