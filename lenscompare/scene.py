"""Scene files (TOML, the contract of DESIGN.md) loaded into frozen, typed values.

Parse at the edge, typed values inside: :func:`load_scene` is the only place a
scene file is read, and it rejects anything outside the schema — unknown key,
wrong type, missing material, non-positive size, NaN — with one
:class:`~lenscompare.errors.InputError` naming the file, the key and what was
expected.  Scene lengths are metres; camera lengths are millimetres and say so.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Union

import numpy as np

from ._schema import Table, parse_toml, read_toml_text
from .errors import InputError
from .lenses import Prescription, resolve_lens
from .limits import (
    MAX_COLOR,
    MAX_F_NUMBER,
    MAX_FILM_MM,
    MAX_FOCAL_LENGTH_MM,
    MAX_LENGTH_M,
    MAX_LIGHTS,
    MAX_NAME_CHARS,
    MAX_PIXELS,
    MAX_SEED,
    MAX_SHUTTER_S,
    MAX_SIDE_PX,
    MAX_SPEED_M_PER_S,
    MAX_SPP,
    MIN_CHECKER_M,
    MIN_F_NUMBER,
    MIN_FILM_MM,
    MIN_FOCAL_LENGTH_MM,
)
from .meshes import read_mesh
from .spectral import MAX_NM, MIN_NM
from .units import mm_from_m

__all__ = [
    "MODELS", "RENDER_MODELS", "EFFECT_NAMES", "FOCUS_MODES", "FALLOFFS", "MEASUREMENTS", "SAMPLERS",
    "DISK_MAPPINGS", "MAX_APERTURE_BLADES", "Camera",
    "RenderSettings", "EmissiveMaterial", "DiffuseMaterial", "Checker", "Sphere", "Box", "Rectangle", "Mesh",
    "PointLight", "Scene",
    "load_scene", "parse_scene",
]

Vec3 = tuple[float, float, float]

MODELS = ("pinhole", "thin", "thick", "lens")  # the camera models (what reports, costs and sweeps compare)
# What the native renderer takes: the camera models, and the image-based depth of
# field (lenscompare.postfilter: a pinhole pass spread by its depth buffer).
RENDER_MODELS = MODELS + ("postfilter",)
# The effects of DESIGN.md's table, in its order: `[render] effects` and `--effects` name them.
EFFECT_NAMES = ("defocus", "aberrations", "distortion", "vignetting", "lateral_color", "longitudinal_color",
                "motion_blur", "diffraction")
FOCUS_MODES = ("paraxial", "best")  # lens system: film at the paraxial image, or at the smallest on-axis spot
FALLOFFS = ("none", "inverse_square")
MEASUREMENTS = ("similarity", "blur_disks", "distortion", "vignetting")
SAMPLERS = ("random", "jittered", "regular", "poisson", "sobol")
DISK_MAPPINGS = ("concentric", "polar")
# How the lens system makes its rays: each traced through every surface, or
# looked up in a table traced once per camera (lenscompare.cameras.lens).
LENS_RAYS = ("traced", "table")
MAX_APERTURE_BLADES = 32  # the native aperture's limit (native/src/aperture.h)


@dataclass(frozen=True)
class Camera:
    """The ``[camera]`` table. Positions in metres, lens quantities in mm."""

    model: str
    position: Vec3
    look_at: Vec3
    up: Vec3
    focus_distance_m: float
    resolution: tuple[int, int]
    film_mm: tuple[float, float] = (36.0, 24.0)
    focal_length_mm: float | None = None
    f_number: float | None = None
    lens: Prescription | None = None  # resolved once, when the scene is loaded (lenses.resolve_lens)
    principal_plane_gap_mm: float | None = None
    aperture_blades: int = 0            # 0: circular; N >= 3: regular N-gon of the circle's area
    aperture_rotation_deg: float = 0.0  # counter-clockwise seen from behind the lens; a vertex up at 0
    velocity: Vec3 = (0.0, 0.0, 0.0)    # m/s: the whole camera moves by velocity * t during the shutter
    focus_mode: str = "paraxial"        # lens system only: "paraxial" or "best" (lenses.best_focus)

    @property
    def focus_distance_mm(self) -> float:
        return mm_from_m(self.focus_distance_m)

    @property
    def width_px(self) -> int:
        return self.resolution[0]

    @property
    def height_px(self) -> int:
        return self.resolution[1]


@dataclass(frozen=True)
class RenderSettings:
    """The ``[render]`` table; command-line flags override it."""

    spp: int = 64
    sampler: str = "jittered"
    seed: int = 0
    disk_mapping: str = "concentric"
    adaptive: bool = False  # spp is then the image's mean (lenscompare.adaptive)
    diffraction: bool = False  # the aperture's diffraction PSF applied to the image (lenscompare.diffraction)
    effects: tuple[str, ...] | None = None  # a composite render of exactly these (lenscompare.cameras.composite)
    shutter_s: tuple[float, float] = (0.0, 0.0)  # open, close (s); equal: no motion blur (lenscompare.motion)
    spectral: bool = False  # wavelengths sampled over 380-780 nm, dispersion from the lens (lenscompare.spectral)
    # The lens system's rays: "traced" or "table" (not a dispersive lens's spectral renders; LENS_RAYS); None, not given:
    # traced, but --model auto may take the table when its check is within the plan's tolerance.
    lens_rays: str | None = None
    # The lens system's mirror-image pixels take one traced set of samples, reflected (render's
    # lens_mirrors); None, not given: off, but --model auto may turn it on for a lens-system plan.
    lens_mirrors: bool | None = None


@dataclass(frozen=True)
class EmissiveMaterial:
    name: str
    color: Vec3  # radiance
    wavelength_nm: float | None = None  # a monochromatic emitter in spectral renders (lenscompare.spectral)


@dataclass(frozen=True)
class Checker:
    color: Vec3     # albedo of the odd cubes
    size_m: float   # cube edge


@dataclass(frozen=True)
class DiffuseMaterial:
    name: str
    color: Vec3  # albedo (of the even checker cubes)
    checker: Checker | None = None
    emission: Vec3 = (0.0, 0.0, 0.0)


Material = Union[EmissiveMaterial, DiffuseMaterial]


@dataclass(frozen=True)
class Sphere:
    center: Vec3
    radius: float
    material: str
    velocity: Vec3 = (0.0, 0.0, 0.0)  # m/s, from the position at t = 0


@dataclass(frozen=True)
class Box:
    min: Vec3
    max: Vec3
    material: str
    velocity: Vec3 = (0.0, 0.0, 0.0)  # m/s, from the position at t = 0


@dataclass(frozen=True)
class Rectangle:
    corner: Vec3
    edge1: Vec3
    edge2: Vec3
    material: str
    velocity: Vec3 = (0.0, 0.0, 0.0)  # m/s, from the position at t = 0


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh from an OBJ or PLY file, scaled then translated into the scene (m).

    ``vertices_m`` (n, 3) are the file's vertices * ``scale`` + ``translate``;
    ``triangles`` (t, 3) index them. Both are read once, when the scene loads.
    """

    file: Path
    scale: float
    translate: Vec3
    material: str
    vertices_m: np.ndarray = field(compare=False, repr=False)
    triangles: np.ndarray = field(compare=False, repr=False)
    velocity: Vec3 = (0.0, 0.0, 0.0)  # m/s, the whole mesh

    @property
    def polygons(self) -> np.ndarray:
        """The triangles' corners, (t, 3, 3), m."""
        return self.vertices_m[self.triangles]


SceneObject = Union[Sphere, Box, Rectangle, Mesh]


@dataclass(frozen=True)
class PointLight:
    position: Vec3
    color: Vec3  # radiant intensity
    falloff: str = "none"  # or "inverse_square": lit radiance albedo * color * cos / distance^2 (m^2)


@dataclass(frozen=True)
class Scene:
    """A whole scene file. ``source`` is the file it came from (for messages)."""

    camera: Camera
    render: RenderSettings
    background: Vec3
    materials: dict[str, Material]
    objects: tuple[SceneObject, ...]
    lights: tuple[PointLight, ...]
    name: str = ""
    description: str = ""
    measure: tuple[str, ...] = ("similarity",)  # what the report measures on this scene
    source: str = "<scene>"
    base_dir: Path = field(default_factory=Path.cwd)

    def with_camera(self, **changes) -> "Scene":
        """A copy with some camera fields replaced (e.g. ``model="pinhole"``).

        ``lens`` may be a :class:`~lenscompare.lenses.Prescription` or a name
        or path, resolved as the scene file's own ``camera.lens`` would be.
        """
        lens = changes.get("lens")
        if lens is not None and not isinstance(lens, Prescription):
            changes["lens"] = resolve_lens(lens, base_dir=self.base_dir, source=self.source)
        return replace(self, camera=replace(self.camera, **changes))

    def with_render(self, **changes) -> "Scene":
        """A copy with some render settings replaced; ``None`` values keep the file's."""
        changes = {k: v for k, v in changes.items() if v is not None}
        return replace(self, render=replace(self.render, **changes))


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or os.PathLike
        A TOML scene file following DESIGN.md.

    Returns
    -------
    Scene

    Raises
    ------
    InputError
        The file is unreadable or breaks the schema; the message names the
        file, the key and what was expected.
    """
    source = os.fspath(path)
    text = read_toml_text(source, what="scene file")  # capped: /dev/zero is refused, not read
    return parse_scene(text, source=source, base_dir=Path(source).resolve().parent)


def parse_scene(text: str, *, source: str = "<scene>", base_dir: Path | None = None) -> Scene:
    """Validate scene TOML text; see :func:`load_scene`."""
    data = parse_toml(text, source=source)
    # Every number of a scene is bounded (limits.py): Embree computes in float32.
    root = Table(data, source=source, max_abs=MAX_LENGTH_M)
    root.check_keys(["name", "description", "measure", "camera", "render", "background", "materials", "objects",
                     "lights"])

    materials = _read_materials(root.table("materials"))
    render = _read_render(root.table("render"))
    objects = tuple(_read_object(t, materials, base_dir=base_dir, shutter_s=render.shutter_s)
                    for t in root.tables("objects"))
    lights = tuple(_read_light(t) for t in root.tables("lights"))
    if len(lights) > MAX_LIGHTS:
        raise root.error("lights", f"{len(lights)} lights, more than the limit {MAX_LIGHTS:,}")
    background = root.table("background")
    background.check_keys(["color"])
    return Scene(
        camera=_read_camera(root.table("camera", required=True), base_dir=base_dir, shutter_s=render.shutter_s),
        render=render,
        background=background.vector("color", 3, default=(0.0, 0.0, 0.0), non_negative=True, maximum=MAX_COLOR),
        materials=materials,
        objects=objects,
        lights=lights,
        name=root.string("name", default=Path(source).stem, max_chars=MAX_NAME_CHARS),
        description=root.string("description", default=""),
        measure=_read_measure(root),
        source=source,
        base_dir=base_dir or Path.cwd(),
    )


def _read_measure(root: Table) -> tuple[str, ...]:
    value = root.data.get("measure", ["similarity"])
    if not isinstance(value, list) or not all(isinstance(v, str) and v in MEASUREMENTS for v in value):
        raise root.error("measure", f"expected an array of names from {', '.join(MEASUREMENTS)}, got {value!r}")
    return tuple(dict.fromkeys(value))


def _read_velocity(t: Table, points_max_abs_m: float, shutter_s: tuple[float, float]) -> Vec3:
    """``velocity`` (m/s), bounded so that what moves stays inside the scene's
    bounds (float32 for Embree) at every time of the shutter."""
    velocity = t.vector("velocity", 3, default=(0.0, 0.0, 0.0), max_abs=MAX_SPEED_M_PER_S)
    reach_m = points_max_abs_m + max(abs(v) for v in velocity) * max(abs(s) for s in shutter_s)
    if not reach_m <= MAX_LENGTH_M:
        raise t.error("velocity", f"{list(velocity)} m/s over the shutter {list(shutter_s)} s moves it "
                      f"{reach_m:.3g} m from the origin, beyond the limit {MAX_LENGTH_M:g} m")
    return velocity


def _read_shutter(t: Table) -> tuple[float, float]:
    shutter = t.vector("shutter", 2, default=(0.0, 0.0), non_negative=True, maximum=MAX_SHUTTER_S)
    if shutter[1] < shutter[0]:
        raise t.error("shutter", f"closes at {shutter[1]:g} s before it opens at {shutter[0]:g} s "
                      "(expected [open, close] with open <= close)")
    return shutter


def _read_camera(t: Table, *, base_dir: Path | None, shutter_s: tuple[float, float] = (0.0, 0.0)) -> Camera:
    t.check_keys(["model", "position", "look_at", "up", "focal_length_mm", "f_number", "focus_distance",
                  "film_mm", "resolution", "lens", "principal_plane_gap_mm", "aperture_blades",
                  "aperture_rotation_deg", "velocity", "focus_mode"])
    position = t.vector("position", 3)
    look_at = t.vector("look_at", 3)
    up = t.vector("up", 3, default=(0.0, 1.0, 0.0))
    view = [b - a for a, b in zip(position, look_at)]
    view_length = math.sqrt(sum(v * v for v in view))
    if view_length == 0.0:
        raise t.error("look_at", "equals camera.position (expected a point the camera looks toward)")
    up_length = math.sqrt(sum(u * u for u in up))
    cross = (view[1] * up[2] - view[2] * up[1], view[2] * up[0] - view[0] * up[2], view[0] * up[1] - view[1] * up[0])
    if up_length == 0.0 or math.sqrt(sum(c * c for c in cross)) <= 1e-9 * view_length * up_length:
        raise t.error("up", "is zero or parallel to the view direction (expected a vector across it)")

    film_mm = t.vector("film_mm", 2, default=(36.0, 24.0), minimum=MIN_FILM_MM, maximum=MAX_FILM_MM)
    resolution = t.vector("resolution", 2, integer=True, positive=True, maximum=MAX_SIDE_PX)
    if resolution[0] * resolution[1] > MAX_PIXELS:
        raise t.error("resolution", f"{resolution[0]}x{resolution[1]} = {resolution[0] * resolution[1]:,} pixels, "
                      f"more than the limit {MAX_PIXELS:,}")
    film_aspect, pixel_aspect = film_mm[0] / film_mm[1], resolution[0] / resolution[1]
    if abs(film_aspect / pixel_aspect - 1.0) > 1e-6:
        raise t.error("resolution", f"aspect {resolution[0]}x{resolution[1]} = {pixel_aspect:.6g} differs from "
                      f"camera.film_mm aspect {film_mm[0]:g}x{film_mm[1]:g} = {film_aspect:.6g} "
                      "(pixels must be square)")

    focal_length_mm = t.number("focal_length_mm", default=None, minimum=MIN_FOCAL_LENGTH_MM,
                               maximum=MAX_FOCAL_LENGTH_MM)
    focus_distance_m = t.number("focus_distance", positive=True, max_abs=math.inf)  # any finite distance
    if focal_length_mm is not None and not mm_from_m(focus_distance_m) > focal_length_mm:
        raise t.error("focus_distance", f"{focus_distance_m:g} m is not beyond the focal length "
                      f"{focal_length_mm:g} mm (nothing can be focused there)")
    return Camera(
        model=t.string("model", choices=RENDER_MODELS),
        position=position,
        look_at=look_at,
        up=up,
        focus_distance_m=focus_distance_m,
        resolution=resolution,
        film_mm=film_mm,
        focal_length_mm=focal_length_mm,
        f_number=t.number("f_number", default=None, minimum=MIN_F_NUMBER, maximum=MAX_F_NUMBER),
        lens=_read_lens(t, base_dir),
        principal_plane_gap_mm=t.number("principal_plane_gap_mm", default=None, max_abs=MAX_FOCAL_LENGTH_MM),
        aperture_blades=_read_aperture_blades(t),
        aperture_rotation_deg=t.number("aperture_rotation_deg", default=0.0, max_abs=1e6),
        velocity=_read_velocity(t, max(abs(c) for c in position), shutter_s),
        focus_mode=t.string("focus_mode", default="paraxial", choices=FOCUS_MODES),
    )


def _read_aperture_blades(t: Table) -> int:
    blades = t.integer("aperture_blades", default=0, minimum=0)
    if blades in (1, 2) or blades > MAX_APERTURE_BLADES:
        raise t.error("aperture_blades", f"expected 0 (circular) or 3 to {MAX_APERTURE_BLADES} blades, got {blades}")
    return blades


def _read_lens(t: Table, base_dir: Path | None) -> Prescription | None:
    """The prescription ``camera.lens`` names, resolved here once (shipped name,
    else beside the scene file, else as given)."""
    name = t.string("lens", default=None)
    if name is None:
        return None
    return resolve_lens(name, base_dir=base_dir, source=t.source, key=t.path("lens"))


def _read_render(t: Table) -> RenderSettings:
    t.check_keys(["spp", "sampler", "seed", "disk_mapping", "adaptive", "diffraction", "effects", "shutter",
                  "spectral", "lens_rays", "lens_mirrors"])
    defaults = RenderSettings()
    return RenderSettings(
        spp=t.integer("spp", default=defaults.spp, minimum=1, maximum=MAX_SPP),
        sampler=t.string("sampler", default=defaults.sampler, choices=SAMPLERS),
        seed=t.integer("seed", default=defaults.seed, minimum=0, maximum=MAX_SEED),
        disk_mapping=t.string("disk_mapping", default=defaults.disk_mapping, choices=DISK_MAPPINGS),
        adaptive=t.boolean("adaptive", default=defaults.adaptive),
        diffraction=t.boolean("diffraction", default=defaults.diffraction),
        effects=_read_effects(t),
        shutter_s=_read_shutter(t),
        spectral=t.boolean("spectral", default=defaults.spectral),
        lens_rays=t.string("lens_rays", default=defaults.lens_rays, choices=LENS_RAYS),
        lens_mirrors=t.boolean("lens_mirrors", default=defaults.lens_mirrors),
    )


def _read_effects(t: Table) -> tuple[str, ...] | None:
    """``[render] effects``: an array of effect names (DESIGN.md's table), or None when absent."""
    if not t.has("effects"):
        return None
    value = t.data["effects"]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise t.error("effects", f"expected an array of effect names from {', '.join(EFFECT_NAMES)}, got {value!r}"[:300])
    unknown = [v for v in value if v not in EFFECT_NAMES]
    if unknown:
        raise t.error("effects", f"unknown effect {unknown[0][:40]!r} (expected names from {', '.join(EFFECT_NAMES)})")
    return tuple(dict.fromkeys(value))


def _read_materials(t: Table) -> dict[str, Material]:
    materials: dict[str, Material] = {}
    for name in t.data:
        m = t.table(name)
        kind = m.string("type", choices=("emissive", "diffuse"))
        if kind == "emissive":
            m.check_keys(["type", "color", "wavelength_nm"])
            materials[name] = EmissiveMaterial(
                name, m.vector("color", 3, non_negative=True, maximum=MAX_COLOR),
                wavelength_nm=m.number("wavelength_nm", default=None, minimum=MIN_NM, maximum=MAX_NM))
            continue
        m.check_keys(["type", "color", "checker", "emission"])
        checker = None
        if m.has("checker"):
            c = m.table("checker")
            c.check_keys(["color", "size"])
            checker = Checker(color=c.vector("color", 3, non_negative=True, maximum=MAX_COLOR),
                              size_m=c.number("size", minimum=MIN_CHECKER_M))
        materials[name] = DiffuseMaterial(
            name,
            color=m.vector("color", 3, non_negative=True, maximum=MAX_COLOR),
            checker=checker,
            emission=m.vector("emission", 3, default=(0.0, 0.0, 0.0), non_negative=True, maximum=MAX_COLOR),
        )
    return materials


def _material_name(t: Table, materials: dict[str, Material]) -> str:
    name = t.string("material")
    if name not in materials:
        known = ", ".join(sorted(materials)) or "none defined"
        raise t.error("material", f"no material named {name!r} (defined: {known})")
    return name


def _read_mesh(t: Table, materials: dict[str, Material], base_dir: Path | None,
               shutter_s: tuple[float, float]) -> Mesh:
    """A ``type = "mesh"`` object: its file beside the scene (or absolute), read now."""
    t.check_keys(["type", "file", "scale", "translate", "material", "velocity"])
    name = t.string("file")
    path = Path(name) if Path(name).is_absolute() else (base_dir or Path.cwd()) / name
    if not path.is_file():
        raise t.error("file", f"no mesh file {str(path)!r} (a path beside the scene file, or absolute)")
    scale = t.number("scale", default=1.0, positive=True)
    translate = t.vector("translate", 3, default=(0.0, 0.0, 0.0))
    material = _material_name(t, materials)
    vertices, triangles = read_mesh(path)
    vertices_m = vertices * scale + np.asarray(translate, dtype=float)
    if not np.all(np.abs(vertices_m) <= MAX_LENGTH_M):  # NaN too: Embree computes in float32
        raise t.error("scale", f"puts vertices of {str(path)!r} beyond {MAX_LENGTH_M:g} m (or the file holds "
                      "non-finite coordinates)")
    velocity = _read_velocity(t, float(np.abs(vertices_m).max(initial=0.0)), shutter_s)
    vertices_m.flags.writeable = False
    triangles.flags.writeable = False
    return Mesh(path, scale, translate, material, vertices_m, triangles, velocity)


def _read_object(t: Table, materials: dict[str, Material], *, base_dir: Path | None = None,
                 shutter_s: tuple[float, float] = (0.0, 0.0)) -> SceneObject:
    kind = t.string("type", choices=("sphere", "box", "rectangle", "mesh"))
    if kind == "mesh":
        return _read_mesh(t, materials, base_dir, shutter_s)

    def velocity(*points: Vec3) -> Vec3:
        return _read_velocity(t, max(abs(c) for p in points for c in p), shutter_s)

    if kind == "sphere":
        t.check_keys(["type", "center", "radius", "material", "velocity"])
        center, radius = t.vector("center", 3), t.number("radius", positive=True)
        return Sphere(center, radius, _material_name(t, materials),
                      velocity(tuple(abs(c) + radius for c in center)))
    if kind == "box":
        t.check_keys(["type", "min", "max", "material", "velocity"])
        lo, hi = t.vector("min", 3), t.vector("max", 3)
        if not all(h > l for l, h in zip(lo, hi)):
            raise t.error("max", f"expected every component above min {list(lo)}, got {list(hi)}")
        return Box(lo, hi, _material_name(t, materials), velocity(lo, hi))
    t.check_keys(["type", "corner", "edge1", "edge2", "material", "velocity"])
    e1, e2 = t.vector("edge1", 3), t.vector("edge2", 3)
    cross = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
    if not math.sqrt(sum(c * c for c in cross)) > 0.0:
        raise t.error("edge2", "is zero or parallel to edge1 (the rectangle has no area)")
    corner = t.vector("corner", 3)
    far = tuple(abs(c) + abs(a) + abs(b) for c, a, b in zip(corner, e1, e2))
    return Rectangle(corner, e1, e2, _material_name(t, materials), velocity(far))


def _read_light(t: Table) -> PointLight:
    t.check_keys(["type", "position", "color", "falloff"])
    t.string("type", choices=("point",))
    return PointLight(t.vector("position", 3), t.vector("color", 3, non_negative=True, maximum=MAX_COLOR),
                      falloff=t.string("falloff", default="none", choices=FALLOFFS))
