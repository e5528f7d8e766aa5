"""Scene + camera model -> pbrt-v4 scene text, so that users can render our scenes in pbrt.

pbrt itself is not installable here (no Debian or PyPI package), so this text is
checked by a parser test against pbrt-v4's documented syntax
(``tests/test_export.py``), not by a pbrt render. The mapping:

=============================  ===================================================
lenscompare                    pbrt-v4
=============================  ===================================================
world (left-handed, +y up)     pbrt's world is left-handed too: coordinates and
                               ``LookAt`` copy straight over (+x on the right)
pinhole                        ``Camera "perspective"``, ``fov`` = the field of
                               view of the SHORTER film side (pbrt's rule)
thin lens, f / N, focus d      ``perspective`` with ``lensradius`` = f / 2N (m)
                               and ``focaldistance`` = d (m)
lens system (model ``lens``)   ``Camera "realistic"`` with the prescription
                               written beside the scene (pbrt's own lens format),
                               ``aperturediameter`` = the stop's diameter (mm);
                               pbrt puts the camera at the FILM and measures
                               ``focusdistance`` from it, so the eye moves back by
                               the entrance pupil-to-film distance and the focus
                               distance grows by it
pixels                         ``Film "rgb"``, ``PixelFilter "box"`` radius 0.5,
                               ``Sampler "independent"``
sphere                         ``Shape "sphere"`` after ``Translate``
box, rectangle, mesh           ``Shape "trianglemesh"``
emissive, radiance L           ``AreaLightSource "diffuse"`` ``L``, two-sided, on
                               a black diffuse material
diffuse, albedo A              ``Material "diffuse"`` (A / pi: the lights carry pi)
checker (size s)               ``Texture "checkerboard"`` with ``dimension 3``,
                               defined under ``Scale s`` and ``Translate -0.001``
                               so that pbrt's floor(q) sums are ours,
                               floor(p / s + 0.001)
point light, inverse square    ``LightSource "point"`` ``I`` = pi I
background B                   ``LightSource "infinite"`` ``L`` = B
integrator                     ``Integrator "path"`` ``maxdepth 1``: direct light
=============================  ===================================================

Where pbrt differs from the contract, and says so in the file: its emissive
surfaces and its background light the diffuse ones (ours light nothing), so
scenes with emitters or a background near lit surfaces render brighter there;
``falloff = "none"`` has no pbrt form and is refused for lit scenes, as for
Mitsuba.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..cameras import LensSystemCamera, camera_for
from ..errors import InputError
from ..motion import moves
from ..flat_geometry import CHECKER_TOLERANCE
from ..native_scene import box_quads, rectangle_quad
from ..scene import Box, DiffuseMaterial, EmissiveMaterial, Mesh, Rectangle, Scene, Sphere
from ..units import m_from_mm

__all__ = ["PBRT_MODELS", "PbrtScene", "scene_to_pbrt", "lens_file_text"]

PBRT_MODELS = ("pinhole", "thin", "lens")

PLANE_RADIUS_MM = 1e12
"""pbrt's lens format reads radius 0 as the stop and has no infinity: a plane is a huge radius."""


@dataclass(frozen=True)
class PbrtScene:
    """The scene text and the files it names beside it (file name -> text)."""

    text: str
    files: dict[str, str] = field(default_factory=dict)


def _num(value: float) -> str:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write a non-finite number to pbrt: {value!r}")
    text = repr(value)
    return "0" if text in ("0.0", "-0.0") else text


def _nums(values) -> str:
    return " ".join(_num(v) for v in np.asarray(values, dtype=float).reshape(-1))


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def lens_file_text(prescription) -> str:
    """The prescription in pbrt's lens format (radius, thickness, n_d, aperture diameter; mm)."""
    lines = [f"# {prescription.name}, written by lenscompare (pbrt lens format: radius thickness n_d aperture, mm);",
             f"# a planar refracting surface (radius inf) is written as radius {_num(PLANE_RADIUS_MM)}"]
    for surface in prescription.surfaces:
        radius = 0.0 if surface.is_stop else PLANE_RADIUS_MM if math.isinf(surface.radius_mm) else surface.radius_mm
        n = 0.0 if surface.is_stop else surface.n_after
        lines.append(f"{_num(radius)}\t{_num(surface.thickness_mm)}\t{_num(n)}\t{_num(2 * surface.semi_aperture_mm)}")
    return "\n".join(lines) + "\n"


def _camera(scene: Scene, model: str, lens_file: str) -> tuple[list[str], dict[str, str]]:
    camera = camera_for(scene, model)
    origin, right, up, forward = (np.asarray(v, dtype=float) for v in camera.frame)
    film = camera.film
    lines, files = [], {}
    if isinstance(camera, LensSystemCamera):
        # pbrt's realistic camera sits at the film and measures focus from there.
        pupil_to_film_m = m_from_mm(camera.film_z_mm - camera.paraxial.entrance_pupil_position_mm)
        eye = origin - forward * pupil_to_film_m
        lines.append(f"# realistic camera at the film: {_num(pupil_to_film_m)} m behind the entrance pupil "
                     f"({_nums(origin)})")
        lines.append(f"LookAt {_nums(eye)}  {_nums(eye + forward)}  {_nums(up)}")
        stop = camera.prescription.surfaces[camera.prescription.stop_index]
        files[lens_file] = lens_file_text(camera.prescription)
        lines.append(f'Camera "realistic" "string lensfile" [ {_quote(lens_file)} ] '
                     f'"float aperturediameter" [ {_num(2 * stop.semi_aperture_mm)} ] '
                     f'"float focusdistance" [ {_num(camera.focus_distance_m + pupil_to_film_m)} ]')
        return lines + _film(film, diagonal_mm=math.hypot(film.width_mm, film.height_mm)), files
    lines.append(f"LookAt {_nums(origin)}  {_nums(origin + forward)}  {_nums(up)}")
    half_w, half_h = camera.screen_half_extent
    fov_deg = math.degrees(2.0 * math.atan(min(half_w, half_h)))  # pbrt: the shorter side's field of view
    params = f'"float fov" [ {_num(fov_deg)} ]'
    if model == "thin":
        params += (f' "float lensradius" [ {_num(m_from_mm(camera.aperture_diameter_mm / 2.0))} ]'
                   f' "float focaldistance" [ {_num(camera.focus_distance_m)} ]')
    lines.append(f'Camera "perspective" {params}')
    return lines + _film(film), files


def _film(film, *, diagonal_mm: float | None = None) -> list[str]:
    extra = f' "float diagonal" [ {_num(diagonal_mm)} ]' if diagonal_mm is not None else ""
    return [f'Film "rgb" "integer xresolution" [ {film.width_px} ] "integer yresolution" [ {film.height_px} ] '
            f'"string filename" [ "render.exr" ]{extra}',
            'PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]']


def _material(name: str, m, texture_names: dict[str, str]) -> list[str]:
    if isinstance(m, EmissiveMaterial):
        return ['Material "diffuse" "rgb reflectance" [ 0 0 0 ]',
                f'AreaLightSource "diffuse" "rgb L" [ {_nums(m.color)} ] "bool twosided" [ true ]']
    lines = []
    if m.checker is not None:
        lines.append(f'Material "diffuse" "texture reflectance" [ {_quote(texture_names[name])} ]')
    else:
        lines.append(f'Material "diffuse" "rgb reflectance" [ {_nums(m.color)} ]')
    if any(c > 0 for c in m.emission):
        lines.append(f'AreaLightSource "diffuse" "rgb L" [ {_nums(m.emission)} ] "bool twosided" [ true ]')
    return lines


def _triangle_mesh(polygons) -> str:
    points, indices = [], []
    for polygon in polygons:
        base = len(points)
        points.extend(np.asarray(polygon, dtype=float))
        for i in range(1, len(polygon) - 1):
            indices += [base, base + i, base + i + 1]
    return (f'Shape "trianglemesh" "integer indices" [ {" ".join(map(str, indices))} ] '
            f'"point3 P" [ {_nums(points)} ]')


def scene_to_pbrt(scene: Scene, *, model: str | None = None, spp: int | None = None, seed: int | None = None,
                  lens_file: str = "lens.dat") -> PbrtScene:
    """pbrt-v4 scene text for ``scene`` through the pinhole, the thin lens or the lens system.

    Parameters
    ----------
    scene : Scene
    model : {'pinhole', 'thin', 'lens'}, optional
        Default the scene's.
    spp, seed : int, optional
        ``pixelsamples`` and ``seed`` (default the scene's ``[render]``).
    lens_file : str
        Name (relative to the scene text) of the lens file for model ``lens``.

    Raises
    ------
    InputError
        Model ``thick`` (pbrt has no thick-lens camera), a lit scene whose
        lights have no inverse-square falloff, a bladed aperture or diffraction.
    """
    model = model or scene.camera.model
    if model not in PBRT_MODELS:
        raise InputError("--model", f"pbrt renders {', '.join(PBRT_MODELS)} here, not {model!r}")
    if model != "pinhole" and scene.camera.aperture_blades:
        # pbrt's thin lens is round, and its realistic camera's built-in shapes are not our polygon.
        raise InputError(scene.source, "the pbrt export writes round apertures only (render the polygon "
                         "natively)", key="camera.aperture_blades")
    if scene.render.diffraction:
        raise InputError(scene.source, "pbrt renders geometric optics only (render diffraction natively)",
                         key="render.diffraction")
    if moves(scene):
        raise InputError(scene.source, "the pbrt export writes still scenes only (render motion blur natively)",
                         key="render.shutter")
    lit = any(isinstance(scene.materials[o.material], DiffuseMaterial) for o in scene.objects)
    for i, light in enumerate(scene.lights):
        if lit and light.falloff != "inverse_square" and any(c > 0 for c in light.color):
            raise InputError(scene.source, "pbrt's point light falls off as 1/d^2 and cannot render "
                             f"falloff = {light.falloff!r}; set falloff = \"inverse_square\"",
                             key=f"lights[{i}].falloff")
    spp = scene.render.spp if spp is None else int(spp)
    seed = scene.render.seed if seed is None else int(seed)

    lines = [f"# lenscompare scene {scene.name!r} ({scene.source}), {model} camera; pbrt-v4 scene format.",
             "# Mapping and differences from lenscompare: lenscompare/pbrt/export.py. Here emissive surfaces",
             "# and the background also light diffuse surfaces (in lenscompare they light nothing)."]
    camera_lines, files = _camera(scene, model, lens_file)
    lines += camera_lines
    lines += [f'Sampler "independent" "integer pixelsamples" [ {spp} ] "integer seed" [ {seed} ]',
              'Integrator "path" "integer maxdepth" [ 1 ]', "", "WorldBegin", ""]

    for light in scene.lights if lit else []:
        if any(c > 0 for c in light.color):
            intensity = np.asarray(light.color, dtype=float) * math.pi  # the diffuse BSDF's 1/pi
            lines.append(f'LightSource "point" "point3 from" [ {_nums(light.position)} ] "rgb I" [ {_nums(intensity)} ]')
    if any(c > 0 for c in scene.background):
        lines.append(f'LightSource "infinite" "rgb L" [ {_nums(scene.background)} ]')
    lines.append("")

    texture_names = {}
    for i, (name, m) in enumerate(scene.materials.items()):
        if isinstance(m, DiffuseMaterial) and m.checker is not None:
            texture_names[name] = f"checker{i}"
            s = m.checker.size_m
            lines += ["AttributeBegin",
                      f"  # texture space q = p / s + {CHECKER_TOLERANCE}: pbrt's 3-D checker floor(q) is ours",
                      f"  Scale {_nums((s, s, s))}",
                      f"  Translate {_nums((-CHECKER_TOLERANCE,) * 3)}",
                      f'  Texture {_quote(texture_names[name])} "spectrum" "checkerboard" "integer dimension" [ 3 ] '
                      f'"rgb tex1" [ {_nums(m.color)} ] "rgb tex2" [ {_nums(m.checker.color)} ]',
                      "AttributeEnd"]

    for i, obj in enumerate(scene.objects):
        material = scene.materials[obj.material]
        lines += ["AttributeBegin", f"  # objects[{i}]: {type(obj).__name__.lower()}, material {obj.material!r}"]
        lines += ["  " + line for line in _material(obj.material, material, texture_names)]
        if isinstance(obj, Sphere):
            lines += [f"  Translate {_nums(obj.center)}", f'  Shape "sphere" "float radius" [ {_num(obj.radius)} ]']
        elif isinstance(obj, Box):
            lines.append("  " + _triangle_mesh(box_quads(obj.min, obj.max)))
        elif isinstance(obj, Rectangle):
            lines.append("  " + _triangle_mesh([rectangle_quad(obj.corner, obj.edge1, obj.edge2)]))
        elif isinstance(obj, Mesh):
            lines.append(f'  Shape "trianglemesh" "integer indices" [ {" ".join(map(str, obj.triangles.reshape(-1)))} ] '
                         f'"point3 P" [ {_nums(obj.vertices_m)} ]')
        lines.append("AttributeEnd")
    return PbrtScene(text="\n".join(lines) + "\n", files=files)
