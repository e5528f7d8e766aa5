"""Scene + camera model -> a Mitsuba 3 scene (XML and PLY meshes) meaning the same picture.

The mapping, object by object (checked by renders in ``tests/test_mitsuba.py``):

=============================  ===================================================
lenscompare                    Mitsuba 3 (variant ``scalar_rgb``)
=============================  ===================================================
camera frame (left-handed)     ``to_world`` = the matrix with columns (-right, up,
                               forward, position): Mitsuba's camera space has +x
                               on the image's LEFT (it is right-handed), so the
                               camera is mirrored; the world's coordinates are
                               copied unchanged
pinhole                        ``perspective``, ``fov`` = 2 atan(film_w / 2 / d')
                               along ``fov_axis = "x"`` (d' = the thin lens's film
                               distance at the focus, as ours)
thin lens, f / N, focus d      ``thinlens``, the same ``fov``, ``aperture_radius``
                               = f / 2N in m, ``focus_distance`` = d (a plane
                               square to the view axis, as ours)
pixel sampling                 ``hdrfilm`` with a ``box`` filter (each sample
                               counts in the pixel it falls in, as ours),
                               ``independent`` sampler, ``sample_count`` = spp
sphere                         ``sphere`` (exact)
box, rectangle, mesh           triangles in a PLY file (``face_normals``: flat)
emissive, radiance L           an ``area`` emitter of radiance L on a black
                               ``diffuse`` BSDF; ``sampling_weight`` 0, so it is
                               seen but lights nothing (our emissive surfaces
                               light nothing); flat faces are turned toward the
                               camera, because Mitsuba's area emitters emit on
                               their front side only
diffuse, albedo A              ``twosided`` ``diffuse`` of reflectance A: lit
                               radiance A/pi * E; the lights carry the pi
checker (size s)               each flat face cut along the cube boundaries of
                               the native checker (:mod:`lenscompare.flat_geometry`)
                               into two meshes of one colour each: exact for any
                               plane. A checker on a sphere has no exact Mitsuba
                               form and is refused
diffuse + emission E           the same diffuse BSDF plus an area emitter of
                               radiance E (``sampling_weight`` 0)
point light, ``falloff =       ``point`` emitter of intensity pi I: (A / pi) (pi I)
"inverse_square"``             cos / d^2 = A I cos / d^2, the native shading;
                               ``falloff = "none"`` has no Mitsuba form and is
                               refused for scenes that have something to light
background B                   ``constant`` emitter of radiance B,
                               ``sampling_weight`` 0
integrator                     ``direct`` with ``bsdf_samples`` 0 and one emitter
                               sample (a light picked in proportion to its mean
                               intensity): point lights and hard shadows
                               only, no light from emissive surfaces or the
                               background (every emitter but the point lights has
                               weight 0, and a black point light at the camera
                               keeps the emitter list non-empty in scenes without
                               lights)
=============================  ===================================================

Mitsuba picks one light per emitter sample at random where the native tracer
sums every light, so its lit pixels carry more noise at the same spp; both
converge to the same image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from xml.etree import ElementTree as ET

import numpy as np

from ..cameras import CameraModel, camera_for
from ..errors import InputError
from ..motion import moves
from ..flat_geometry import flat_pieces
from ..scene import DiffuseMaterial, EmissiveMaterial, Scene, Sphere
from ..units import m_from_mm

__all__ = ["MITSUBA_MODELS", "MAX_MITSUBA_SEED", "MITSUBA_SAMPLERS", "MitsubaScene", "scene_to_mitsuba", "write_ply"]

MITSUBA_MODELS = ("pinhole", "thin")
"""Camera models Mitsuba renders here (``perspective`` and ``thinlens``)."""
MAX_MITSUBA_SEED = 2**32 - 1
"""Mitsuba's samplers take a 32-bit seed."""
MITSUBA_SAMPLERS = ("independent", "stratified", "multijitter", "orthogonal", "ldsampler")
"""Mitsuba's samplers the export may write: ``independent`` (a uniform point
per dimension, as the native ``random``; the default), ``stratified`` (one
jittered point per stratum, the strata paired between dimensions by a per-pixel
hashed permutation (Kensler 2013), as the native ``jittered``; it takes a square
sample count), and the stratified ones
that round the count themselves."""

NEAR_CLIP_M, FAR_CLIP_M = 1e-5, 1e9  # Mitsuba's defaults (1 cm, 10 km) would clip scenes the native tracer shows


@dataclass(frozen=True)
class MitsubaScene:
    """An exported scene: the XML text and the PLY meshes it names (file name -> triangles (3 t, 3), m)."""

    xml: str
    meshes: dict[str, np.ndarray] = field(default_factory=dict)
    camera: CameraModel | None = None
    model: str = "thin"


def _num(value: float) -> str:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write a non-finite number to Mitsuba: {value!r}")
    text = repr(value)
    return "0" if text in ("0.0", "-0.0") else text


def _rgb(parent, name: str, value) -> None:
    ET.SubElement(parent, "rgb", name=name, value=" ".join(_num(v) for v in value))


def _sub(parent, tag: str, name: str, value) -> None:
    text = value if isinstance(value, str) else _num(value) if tag == "float" else str(value)
    ET.SubElement(parent, tag, name=name, value=text)


def _point(parent, name: str, p) -> None:
    ET.SubElement(parent, "point", name=name, x=_num(p[0]), y=_num(p[1]), z=_num(p[2]))


def _check(scene: Scene, model: str) -> None:
    if model not in MITSUBA_MODELS:
        raise InputError("--model", f"Mitsuba renders only {' and '.join(MITSUBA_MODELS)} here, not {model!r} "
                         "(no thick-lens or lens-system sensor)")
    if model == "thin" and scene.camera.aperture_blades:
        raise InputError(scene.source, "Mitsuba's thinlens sensor has a round aperture only (render the "
                         "polygon natively)", key="camera.aperture_blades")
    if scene.render.diffraction:
        raise InputError(scene.source, "Mitsuba is rendered here with geometric optics only (render "
                         "diffraction natively)", key="render.diffraction")
    if moves(scene):
        raise InputError(scene.source, "the Mitsuba export writes still scenes only (render motion blur natively, "
                         "or with lenscompare povray --time-samples)", key="render.shutter")
    lit = any(isinstance(scene.materials[o.material], DiffuseMaterial) for o in scene.objects)
    for i, light in enumerate(scene.lights):
        if lit and light.falloff != "inverse_square" and any(c > 0 for c in light.color):
            raise InputError(scene.source, "Mitsuba's point light falls off as 1/d^2 and cannot render "
                             f"falloff = {light.falloff!r}; set falloff = \"inverse_square\" (native and POV-Ray "
                             "then render the same light)", key=f"lights[{i}].falloff")
    for i, obj in enumerate(scene.objects):
        material = scene.materials[obj.material]
        if isinstance(obj, Sphere) and getattr(material, "checker", None) is not None:
            raise InputError(scene.source, f"material {obj.material!r} has a checker, which Mitsuba cannot draw "
                             "exactly on a sphere (flat faces only)", key=f"objects[{i}].material")


def _sensor(root, camera: CameraModel, spp: int, seed: int, sampler_type: str) -> None:
    sensor = ET.SubElement(root, "sensor", type="perspective" if camera.model == "pinhole" else "thinlens")
    half_w, _ = camera.screen_half_extent
    _sub(sensor, "float", "fov", math.degrees(2.0 * math.atan(half_w)))
    _sub(sensor, "string", "fov_axis", "x")
    if camera.model == "thin":
        _sub(sensor, "float", "aperture_radius", m_from_mm(camera.aperture_diameter_mm / 2.0))
        _sub(sensor, "float", "focus_distance", camera.focus_distance_m)
    _sub(sensor, "float", "near_clip", NEAR_CLIP_M)
    _sub(sensor, "float", "far_clip", FAR_CLIP_M)
    origin, right, up, forward = (np.asarray(v, dtype=float) for v in camera.frame)
    # Columns: camera x (image LEFT in Mitsuba) = -right, y = up, z = forward; translation = position.
    matrix = np.eye(4)
    matrix[:3, 0], matrix[:3, 1], matrix[:3, 2], matrix[:3, 3] = -right, up, forward, origin
    transform = ET.SubElement(sensor, "transform", name="to_world")
    transform.append(ET.Comment(" mirrored: our world is left-handed (POV-Ray's), Mitsuba's camera right-handed "))
    ET.SubElement(transform, "matrix", value=" ".join(_num(v) for v in matrix.reshape(-1)))
    sampler = ET.SubElement(sensor, "sampler", type=sampler_type)
    _sub(sampler, "integer", "sample_count", int(spp))
    _sub(sampler, "integer", "seed", int(seed))
    film = ET.SubElement(sensor, "film", type="hdrfilm")
    _sub(film, "integer", "width", camera.film.width_px)
    _sub(film, "integer", "height", camera.film.height_px)
    _sub(film, "string", "pixel_format", "rgb")
    _sub(film, "string", "component_format", "float32")
    ET.SubElement(film, "rfilter", type="box")


def _bsdf(parent, material, odd: bool | None) -> None:
    if isinstance(material, EmissiveMaterial):
        bsdf = ET.SubElement(parent, "bsdf", type="diffuse")
        _rgb(bsdf, "reflectance", (0.0, 0.0, 0.0))
        return
    albedo = material.checker.color if odd else material.color
    two_sided = ET.SubElement(parent, "bsdf", type="twosided")
    _rgb(ET.SubElement(two_sided, "bsdf", type="diffuse"), "reflectance", albedo)


def _emitter(parent, material) -> None:
    radiance = material.color if isinstance(material, EmissiveMaterial) else material.emission
    if not any(c > 0 for c in radiance):
        return
    emitter = ET.SubElement(parent, "emitter", type="area")
    _rgb(emitter, "radiance", radiance)
    _sub(emitter, "float", "sampling_weight", 0.0)  # seen, but lights nothing (as ours)


def _face_camera(triangles: np.ndarray, origin) -> np.ndarray:
    """Triangles wound so that their front (emitting) side faces ``origin``."""
    t = triangles.reshape(-1, 3, 3).copy()
    normal = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    away = np.einsum("ij,ij->i", normal, np.asarray(origin) - t[:, 0]) < 0
    t[away, 1], t[away, 2] = t[away, 2].copy(), t[away, 1].copy()
    return t.reshape(-1, 3)


def write_ply(path, triangles: np.ndarray) -> None:
    """Binary little-endian PLY of triangles (3 t, 3): float32 vertices, uchar/int faces."""
    vertices = np.ascontiguousarray(triangles, dtype="<f4")
    n_tri = len(vertices) // 3
    faces = np.zeros(n_tri, dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"], faces["v"] = 3, np.arange(3 * n_tri, dtype="<i4").reshape(-1, 3)
    header = ("ply\nformat binary_little_endian 1.0\ncomment lenscompare export\n"
              f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {n_tri}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(vertices.tobytes())
        f.write(faces.tobytes())


def scene_to_mitsuba(scene: Scene, *, model: str | None = None, spp: int | None = None, seed: int | None = None,
                     sampler: str = "independent", mesh_prefix: str = "meshes/") -> MitsubaScene:
    """A Mitsuba 3 scene for ``scene`` through the pinhole or the thin lens.

    Parameters
    ----------
    scene : Scene
        A loaded scene.
    model : {'pinhole', 'thin'}, optional
        Camera model; default the scene's.
    spp, seed : int, optional
        Samples per pixel and sampler seed (default the scene's ``[render]``).
    sampler : {'independent', 'stratified', 'multijitter', 'orthogonal', 'ldsampler'}
        Mitsuba's sampler plugin (``stratified`` needs a square ``spp``; the
        last three round ``spp`` to what they take).
    mesh_prefix : str
        Folder (relative to the XML) the PLY meshes are named in.

    Returns
    -------
    MitsubaScene
        XML text and the meshes it names (written by :func:`write_mitsuba`).

    Raises
    ------
    InputError
        A model Mitsuba has no sensor for; a light with ``falloff = "none"``
        in a scene with lit surfaces; a checker on a sphere; a bladed
        aperture or diffraction (Mitsuba's thin lens is round and geometric).
    """
    model = model or scene.camera.model
    _check(scene, model)
    camera = camera_for(scene, model)
    spp = scene.render.spp if spp is None else int(spp)
    seed = scene.render.seed if seed is None else int(seed)
    if spp < 1:
        raise InputError("--spp", f"expected a positive integer, got {spp}")
    if sampler not in MITSUBA_SAMPLERS:
        raise ValueError(f"sampler must be one of {MITSUBA_SAMPLERS}, got {sampler!r}")
    if sampler == "stratified" and math.isqrt(spp) ** 2 != spp:  # Mitsuba would round it up to a square
        raise InputError("--spp", f"Mitsuba's stratified sampler takes a square sample count, got {spp}")
    if not 0 <= seed <= MAX_MITSUBA_SEED:  # Mitsuba's sampler seed is 32-bit
        raise InputError(scene.source, f"Mitsuba's seed is at most {MAX_MITSUBA_SEED:,} (2^32 - 1), got {seed:,}",
                         key="render.seed")

    root = ET.Element("scene", version="3.0.0")
    root.append(ET.Comment(f" lenscompare scene {scene.name!r} ({scene.source}), {model} camera; "
                           "mapping: lenscompare/mitsuba/export.py "))
    lights = [light for light in scene.lights if any(c > 0 for c in light.color)]
    integrator = ET.SubElement(root, "integrator", type="direct")
    # One emitter sample: with bsdf_samples 0, Mitsuba 3.9 sums (not averages) several.
    _sub(integrator, "integer", "emitter_samples", 1)
    _sub(integrator, "integer", "bsdf_samples", 0)
    _sensor(root, camera, spp, seed, sampler)

    lit = any(isinstance(scene.materials[o.material], DiffuseMaterial) for o in scene.objects)
    for light in lights if lit else []:
        emitter = ET.SubElement(root, "emitter", type="point")
        _point(emitter, "position", light.position)
        _rgb(emitter, "intensity", np.asarray(light.color, dtype=float) * math.pi)  # the BSDF's 1/pi
        _sub(emitter, "float", "sampling_weight", float(np.mean(light.color)))  # brighter lights sampled more
    if not (lit and lights):
        placeholder = ET.SubElement(root, "emitter", type="point")
        placeholder.append(ET.Comment(" black: Mitsuba needs one emitter it may sample "))
        _point(placeholder, "position", camera.frame.origin)
        _rgb(placeholder, "intensity", (0.0, 0.0, 0.0))
    if any(c > 0 for c in scene.background):
        background = ET.SubElement(root, "emitter", type="constant")
        _rgb(background, "radiance", scene.background)
        _sub(background, "float", "sampling_weight", 0.0)

    for i, obj in enumerate(scene.objects):
        if isinstance(obj, Sphere):
            shape = ET.SubElement(root, "shape", type="sphere", id=f"object{i}")
            _point(shape, "center", obj.center)
            _sub(shape, "float", "radius", obj.radius)
            material = scene.materials[obj.material]
            _bsdf(shape, material, None)
            _emitter(shape, material)

    meshes = {}
    for piece in flat_pieces(scene):
        material = scene.materials[piece.material]
        triangles = piece.vertices
        emits = isinstance(material, EmissiveMaterial) or any(c > 0 for c in material.emission)
        if emits:
            triangles = _face_camera(triangles, camera.frame.origin)
        suffix = "" if piece.odd is None else ("_odd" if piece.odd else "_even")
        name = f"{mesh_prefix}object{piece.object_index}{suffix}.ply"
        meshes[name] = triangles
        shape = ET.SubElement(root, "shape", type="ply", id=f"object{piece.object_index}{suffix}")
        _sub(shape, "string", "filename", name)
        _sub(shape, "boolean", "face_normals", "true")
        _bsdf(shape, material, piece.odd)
        _emitter(shape, material)

    ET.indent(root, space="  ")
    xml = '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    return MitsubaScene(xml=xml, meshes=meshes, camera=camera, model=model)
