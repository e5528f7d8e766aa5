"""Scene + camera model -> POV-Ray 3.7 scene text meaning exactly the same picture.

The mapping, object by object (every line checked by a render; see
``tests/test_povray_agreement.py``):

============================  ==================================================
lenscompare                   POV-Ray 3.7
============================  ==================================================
sphere                        ``sphere { <c>, r }`` (exact, as Embree's)
box (axis-aligned)            ``box { <min>, <max> }``
mesh (OBJ / PLY)              ``mesh2`` with ``vertex_vectors`` and
                              ``face_indices`` (flat triangles, as Embree's)
rectangle (parallelogram)     ``mesh`` of two triangles (p0 p1 p3, p2 p3 p1:
                              Embree's split of the same quad); exact, and no
                              coplanarity test to trip over as ``polygon`` has
emissive, radiance L          ``pigment { rgb L }`` + ``finish { emission 1
                              diffuse 0 ambient 0 }``; POV-Ray never clamps a
                              pigment, so L > 1 survives into the EXR
diffuse, albedo A             ``finish { diffuse 1 brilliance 1 ambient 0
                              specular 0 phong 0 }``: A * I * max(0, n.l), two-
                              sided, hard shadows, no 1/pi, as ours
checker (size s, colour B)    ``pigment { checker rgb A rgb B scale s translate
                              -0.001 s (x, y, z) }``: ours is the parity of
                              floor(p/s + 0.001) summed over x, y, z, even -> A;
                              POV-Ray 3.7's checker is floor(q + 1e-10)
                              (EPSILON, not 0.001 as POV-Ray 3.6's), so the
                              pattern is moved by 0.001 s to put the cube
                              boundaries where ours are (a floor at y = 0 reads
                              y/s + 0.001: even, in both)
diffuse + emission E          POV-Ray multiplies ``emission`` by the pigment, so
                              the lit texture and an emissive one are averaged
                              (``average texture_map``) with doubled colours:
                              (2 A lit + 2 E) / 2 = A lit + E, also for A = 0
point light, intensity I      ``light_source { <p> rgb I }``: no ``fade_*``, so
                              no distance falloff; not an area light
point light, ``falloff =      POV-Ray attenuates by 2 / (1 + (d / D)^P); with
"inverse_square"``            ``fade_power 2`` and ``fade_distance D`` = 1e-4 m
                              that is 2 D² / (D² + d²), so the colour is written
                              as I / (2 D²): I / d² within D² / d² (1e-6 at 1 cm)
background                    ``background { rgb <...> }``
global                        ``assumed_gamma 1.0`` (linear colours),
                              ``ambient_light 0``, no radiosity, no photons
============================  ==================================================

Camera. World coordinates are POV-Ray's own (left-handed, +y up), so positions
copy straight over. The camera is written as explicit vectors, the native
camera's frame (:class:`lenscompare.cameras.CameraFrame`): ``location`` =
``camera.position``, ``direction`` = the unit view direction, ``right`` and
``up`` = the frame's right and up scaled to the film over the film distance,
film_w / d' and film_h / d', with d' = f d / (d - f) of the thin lens focused at
``focus_distance`` — the same frame as the native pinhole and thin lens. The
horizontal field of view 2 atan(film_w / 2 / d') is what ``angle`` would say;
explicit vectors avoid POV-Ray's order-dependent ``angle``/``sky``/``look_at``
processing and let the thin lens correct a bias of POV-Ray's (next paragraph).

The thin lens adds ``aperture`` = 2 f / N in scene units (POV-Ray's lens
diameter is aperture / 2), ``focal_point`` on the view axis at the focus
distance (POV-Ray uses only its distance and puts the focal plane square to the
view direction, as we do) and ``blur_samples N, N`` (min = max, so adaptive
stopping never truncates a pixel).

POV-Ray's focal-blur film jitter is biased: ``TraceRayWithFocalBlur`` adds
``(rand - 0.5) / 16`` px to each sub-pixel position, but its jitter table holds
values in [-0.5, 0.5], not [0, 1], so every sample sits on average 1/32 px left
of and above its pixel's centre and the whole image moves 1/32 px right and
down (measured: +0.029 px, +0.029 px against the native thin lens). The export
aims ``direction`` 1/32 px right of and below the axis to cancel it
(:data:`FOCAL_BLUR_FILM_BIAS_PX`), and scales ``focal_point``'s distance by
|direction| so the focal plane stays at the focus distance. The pinhole
(anti-aliasing, no focal blur) has no such bias and no such correction.

Motion. POV-Ray 3.7 has no motion blur. ``scene_to_pov(..., time_s=t)`` writes
the scene as it stands at time t: each moving object with ``translate v t``
after its texture (so a checker moves with its object, as natively), and the
camera at ``position + v_camera t``. The runner renders such sub-frames at
evenly spaced times and averages them (``lenscompare povray --time-samples K``).

Lengths: scene lengths are metres; the camera's are millimetres. Everything
comes from the camera value the native render uses
(:func:`lenscompare.cameras.camera_for`); f / N goes from mm to metres once, in
:func:`pov_camera`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..cameras import CameraModel, camera_for
from ..errors import InputError
from ..motion import camera_at_s, moves, object_offset_m
from ..units import m_from_mm
from ..scene import Box, DiffuseMaterial, EmissiveMaterial, Mesh, Rectangle, Scene, Sphere

__all__ = ["POVRAY_MODELS", "unsupported", "CHECKER_TOLERANCE", "FOCAL_BLUR_FILM_BIAS_PX", "FOCUS_AT_INFINITY_M",
           "INVERSE_SQUARE_FADE_DISTANCE_M", "PovCamera", "scene_to_pov", "pov_camera", "format_number",
           "radiance_bound"]

POVRAY_MODELS = ("pinhole", "thin")
"""Camera models POV-Ray can render (it has no thick-lens or lens-system camera)."""


CHECKER_TOLERANCE = 0.001
"""The native checker's tolerance: cube index floor(p / size + 0.001) (native/src/scene.cpp)."""

FOCAL_BLUR_FILM_BIAS_PX = 1.0 / 32.0
"""Mean offset of POV-Ray 3.7's focal-blur film samples, up and left, in pixels."""

INVERSE_SQUARE_FADE_DISTANCE_M = 1e-4
"""``fade_distance`` written for an inverse-square light: POV-Ray's 2 / (1 + (d/D)²)
is 2 D² / d² to a relative 1e-6 beyond 1 cm (module notes)."""

FOCUS_AT_INFINITY_M = 1e9
"""POV-Ray's focal point goes no further (its focal blur turns black near
1e200 m). Scene coordinates stop at 1e9 m (limits.MAX_LENGTH_M), and a focus
moved from there to infinity changes a 50 mm f/2.8 blur disk by 1e-9 px."""


@dataclass(frozen=True)
class PovCamera:
    """The exported camera: what the ``.pov`` text says, and why.

    Attributes
    ----------
    model : str
        ``"pinhole"`` or ``"thin"``.
    location, direction, right, up : tuple of float
        POV-Ray's camera vectors (world space, m). A pixel at normalised
        screen position (sx, sy) in [-0.5, 0.5]² looks along
        ``direction + sx right + sy up``.
    focal_length_mm, film_distance_mm : float
        f and d' = f d / (d - f), mm.
    angle_deg : float
        Horizontal field of view, 2 atan(film_w / 2 / d'), degrees.
    aperture_diameter_mm : float or None
        Thin lens diameter f / N, mm (None for the pinhole).
    pov_aperture_m : float or None
        POV-Ray's ``aperture`` = 2 f / N in metres (None for the pinhole).
    focal_point : tuple of float or None
        Point on the view axis whose distance from ``location`` tells POV-Ray
        the focus distance, m (None for the pinhole).
    camera : CameraModel
        The camera value this was exported from (the native render's).
    """

    model: str
    location: tuple[float, float, float]
    direction: tuple[float, float, float]
    right: tuple[float, float, float]
    up: tuple[float, float, float]
    focal_length_mm: float
    film_distance_mm: float
    angle_deg: float
    aperture_diameter_mm: float | None = None
    pov_aperture_m: float | None = None
    focal_point: tuple[float, float, float] | None = None
    camera: CameraModel | None = None

    def as_metadata(self) -> dict:
        info = {"focal_length_mm": self.focal_length_mm, "film_distance_mm": self.film_distance_mm,
                "angle_deg": self.angle_deg}
        if self.aperture_diameter_mm is not None:
            info["aperture_diameter_mm"] = self.aperture_diameter_mm
            info["focal_blur_film_bias_corrected_px"] = FOCAL_BLUR_FILM_BIAS_PX
        return info


def format_number(value: float) -> str:
    """A float as POV-Ray reads it back to the same double (shortest repr)."""
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"cannot write a non-finite number to POV-Ray: {value!r}")
    text = repr(value)
    return "0" if text in ("0.0", "-0.0") else text


def _vec(v) -> str:
    return "<" + ", ".join(format_number(c) for c in v) + ">"


def _tuple(v) -> tuple[float, float, float]:
    return tuple(float(c) for c in v)


def unsupported(scene: Scene, model: str) -> tuple[str, str] | None:
    """(scene key, why) when POV-Ray cannot render what ``scene`` asks of
    ``model``, else None. Its focal blur samples a circular lens only (with
    few ``blur_samples`` a hexagonal pattern, which is no diaphragm), and it
    traces geometric optics only: no polygonal aperture, no diffraction. The
    POV-Ray reference is therefore the circular, geometric case."""
    if model == "thin" and scene.camera.aperture_blades:
        return ("camera.aperture_blades", f"POV-Ray's focal blur has a circular aperture only, not "
                f"{scene.camera.aperture_blades} blades (render the polygon natively; POV-Ray is the reference "
                "for the circular aperture)")
    if scene.render.diffraction:
        return ("render.diffraction", "POV-Ray traces geometric optics only (render diffraction natively; "
                "POV-Ray is the reference without it)")
    return None


def pov_camera(scene: Scene, model: str | None = None) -> PovCamera:
    """The POV-Ray camera for ``scene`` seen through ``model`` (default: the scene's).

    Raises
    ------
    InputError
        ``model`` is "thick" or "lens" (POV-Ray has no such camera), or the
        scene lacks a value the model needs.
    """
    model = model or scene.camera.model
    if model not in POVRAY_MODELS:
        if model in ("thick", "lens"):
            raise InputError("--model", f"POV-Ray has no thick-lens / lens-system camera (model {model!r}); "
                             f"POV-Ray renders only {' and '.join(POVRAY_MODELS)}")
        raise InputError("--model", f"expected one of {', '.join(POVRAY_MODELS)}, got {model!r}")
    problem = unsupported(scene, model)
    if problem is not None:
        raise InputError(scene.source, problem[1], key=problem[0])
    value = camera_for(scene, model)
    f_mm, d_prime_mm = value.focal_length_mm, value.film_distance_mm
    film = value.film
    angle_deg = math.degrees(2.0 * math.atan(film.width_mm / 2.0 / d_prime_mm))
    origin, right, up, forward = (np.asarray(v) for v in value.frame)
    right_v, up_v = right * (film.width_mm / d_prime_mm), up * (film.height_mm / d_prime_mm)
    if model == "pinhole":
        return PovCamera(model, _tuple(origin), _tuple(forward), _tuple(right_v), _tuple(up_v), f_mm, d_prime_mm,
                         angle_deg, camera=value)

    aperture_mm = value.aperture_diameter_mm
    # Cancel the focal-blur film bias (samples 1/32 px left of and above centre): aim right and down.
    bias = FOCAL_BLUR_FILM_BIAS_PX
    direction = forward + right_v * (bias / film.width_px) - up_v * (bias / film.height_px)
    # POV-Ray's focal plane lies at |focal_point - location| / |direction| along the axis.
    focus_m = min(value.focus_distance_m, FOCUS_AT_INFINITY_M)
    focal_point = origin + forward * (focus_m * float(np.linalg.norm(direction)))
    return PovCamera(model, _tuple(origin), _tuple(direction), _tuple(right_v), _tuple(up_v), f_mm, d_prime_mm,
                     angle_deg, aperture_diameter_mm=aperture_mm, pov_aperture_m=2.0 * m_from_mm(aperture_mm),
                     focal_point=_tuple(focal_point), camera=value)


def _nearest_surface_m(point, scene: Scene) -> float:
    """A lower bound on the distance from ``point`` to any surface of the scene, m."""
    p = np.asarray(point, dtype=float)
    nearest = math.inf
    for obj in scene.objects:
        if isinstance(obj, Sphere):
            d = np.linalg.norm(p - obj.center) - obj.radius
        elif isinstance(obj, Rectangle):  # its plane
            normal = np.cross(obj.edge1, obj.edge2)
            d = abs(float(np.dot(p - np.asarray(obj.corner), normal))) / float(np.linalg.norm(normal))
        else:  # a box, or a mesh's bounding box
            lo, hi = ((obj.min, obj.max) if isinstance(obj, Box) else
                      (obj.vertices_m.min(axis=0), obj.vertices_m.max(axis=0)))
            d = float(np.linalg.norm(np.maximum(np.maximum(np.asarray(lo) - p, p - np.asarray(hi)), 0.0)))
        nearest = min(nearest, max(float(d), 0.0))
    return nearest


def radiance_bound(scene: Scene) -> float:
    """Largest value any pixel of a render of ``scene`` can take: the brightest
    emitter or background, or the brightest albedo lit by every light at once
    at normal incidence, plus its emission. An inverse-square light counts
    at the nearest surface (no nearer than its 0.1 mm cap)."""
    fade = INVERSE_SQUARE_FADE_DISTANCE_M
    intensity = np.zeros(3)
    for light in scene.lights:
        scale = 1.0 if light.falloff == "none" else 1.0 / max(_nearest_surface_m(light.position, scene), fade) ** 2
        intensity = intensity + np.asarray(light.color, dtype=float) * scale
    bound = max(scene.background)
    for m in scene.materials.values():
        if isinstance(m, EmissiveMaterial):
            bound = max(bound, max(m.color))
        elif isinstance(m, DiffuseMaterial):
            albedo = np.maximum(m.color, m.checker.color if m.checker else 0.0)
            bound = max(bound, float(np.max(albedo * intensity + np.asarray(m.emission))))
    return float(bound)


def scene_to_pov(scene: Scene, *, model: str | None = None, spp: int | None = None,
                 blur_adaptive: tuple[int, float] | None = None, radiance_scale: float = 1.0,
                 time_s: float | None = None) -> str:
    """POV-Ray 3.7 scene text for ``scene`` through the pinhole or thin lens.

    Parameters
    ----------
    scene : Scene
        A loaded scene.
    model : {'pinhole', 'thin'}, optional
        Camera model; default the scene's ``camera.model``.
    spp : int, optional
        Thin lens: ``blur_samples`` (rays per pixel; default the scene's
        ``render.spp``). Unused by the pinhole, whose pixel sampling is set on
        POV-Ray's command line (see :mod:`lenscompare.povray.runner`).
    blur_adaptive : (int, float), optional
        Thin lens: POV-Ray's own adaptive focal blur instead of a fixed count,
        ``(min_samples, variance)``: ``blur_samples min_samples, spp`` and
        ``variance``, so that a pixel stops once its samples vary less than
        that (with POV-Ray's default ``confidence 0.9``).
    radiance_scale : float, optional
        Every emitted radiance and light intensity (background, emissive
        colours, emission, lights) times this: the image scales by it, the
        albedos stay. The runner uses a power of two to keep bright scenes
        inside POV-Ray's half-float EXR (at most 65504).
    time_s : float, optional
        The instant to write, s (default: when the shutter opens): moving
        objects and the camera where they are then (module notes).

    Returns
    -------
    str
        The ``.pov`` text, starting with ``#version 3.7;``.

    Raises
    ------
    InputError
        Model "thick" or "lens" (POV-Ray has no such camera); a bad ``spp``.
    """
    time_s = scene.render.shutter_s[0] if time_s is None else float(time_s)
    camera = pov_camera(camera_at_s(scene, time_s), model)
    spp = scene.render.spp if spp is None else int(spp)
    if spp < 1:
        raise InputError("--spp", f"expected a positive integer, got {spp}")

    lines = [
        "#version 3.7;",
        f"// lenscompare scene {scene.name!r} ({scene.source!r}), {camera.model} camera",
        *([f"// the instant t = {format_number(time_s)} s of the shutter "
           f"[{format_number(scene.render.shutter_s[0])}, {format_number(scene.render.shutter_s[1])}] s: POV-Ray "
           "has no motion blur; lenscompare povray averages such sub-frames"] if moves(scene) else []),
        "// Linear colours, no ambient, no radiosity: the only light is the point lights and emission.",
        "global_settings { assumed_gamma 1.0 ambient_light 0 }",
        f"background {{ rgb {_vec(np.asarray(scene.background) * radiance_scale)} }}",
        "",
        _camera_block(scene, camera, spp, blur_adaptive),
        "",
    ]
    for light in scene.lights:
        lines.append(_light(light, radiance_scale))
    lines.append("")
    # Material names are any TOML key: number them into POV-Ray identifiers.
    names = {name: f"LC_Material{i}" for i, name in enumerate(scene.materials)}
    for name, material in scene.materials.items():
        lines.append(f"#declare {names[name]} = {_texture(material, radiance_scale)};  // {name!r}")
    lines.append("")
    for obj in scene.objects:
        lines.append(_object(obj, names[obj.material], object_offset_m(obj, time_s)))
    return "\n".join(lines) + "\n"


def _light(light, radiance_scale: float = 1.0) -> str:
    intensity = np.asarray(light.color, dtype=float) * radiance_scale
    if light.falloff == "none":
        return f"light_source {{ {_vec(light.position)} rgb {_vec(intensity)} }}"
    fade_m = INVERSE_SQUARE_FADE_DISTANCE_M
    # 2 / (1 + (d / D)^2) = 2 D^2 / (D^2 + d^2): the colour I / (2 D^2) makes it I / d^2.
    color = intensity / (2.0 * fade_m * fade_m)
    return (f"light_source {{ {_vec(light.position)} rgb {_vec(color)}  // intensity {_vec(light.color)} / d^2\n"
            f"  fade_distance {format_number(fade_m)} fade_power 2 }}")


def _camera_block(scene: Scene, camera: PovCamera, spp: int, blur_adaptive: tuple[int, float] | None) -> str:
    c = scene.camera
    items = [
        "perspective",
        f"location {_vec(camera.location)}",
        f"// the native camera frame; horizontal field of view {format_number(camera.angle_deg)} deg",
        f"// (film {format_number(c.film_mm[0])} x {format_number(c.film_mm[1])} mm "
        f"at d' = {format_number(camera.film_distance_mm)} mm)",
        f"right {_vec(camera.right)}",
        f"up {_vec(camera.up)}",
        f"direction {_vec(camera.direction)}",
    ]
    if camera.model == "thin":
        items += [
            f"// f/N = {format_number(camera.aperture_diameter_mm)} mm; POV-Ray's lens diameter is aperture/2",
            f"aperture {format_number(camera.pov_aperture_m)}",
            f"focal_point {_vec(camera.focal_point)}  // focus {format_number(c.focus_distance_m)} m",
            f"blur_samples {spp}, {spp}" if blur_adaptive is None else
            f"blur_samples {min(int(blur_adaptive[0]), spp)}, {spp} variance {format_number(blur_adaptive[1])}",
        ]
    body = "\n".join(f"  {item}" for item in items)
    return f"camera {{\n{body}\n}}"


_EMISSIVE_FINISH = "finish { emission 1 diffuse 0 ambient 0 specular 0 phong 0 reflection 0 }"
_LAMBERT_FINISH = "finish { emission 0 diffuse 1 brilliance 1 ambient 0 specular 0 phong 0 reflection 0 }"


def _diffuse_pigment(m: DiffuseMaterial, scale: float = 1.0) -> str:
    albedo = np.asarray(m.color, dtype=float) * scale
    if m.checker is None:
        return f"pigment {{ rgb {_vec(albedo)} }}"
    odd = np.asarray(m.checker.color, dtype=float) * scale
    size = m.checker.size_m
    # POV-Ray 3.7 evaluates floor(q + 1e-10) at q = (p - t) / s; t = -0.001 s makes it our floor(p / s + 0.001).
    shift = -CHECKER_TOLERANCE * size
    return (f"pigment {{ checker rgb {_vec(albedo)} rgb {_vec(odd)} scale {format_number(size)} "
            f"translate {_vec((shift, shift, shift))} }}")


def _texture(m, radiance_scale: float = 1.0) -> str:
    if isinstance(m, EmissiveMaterial):
        return f"texture {{ pigment {{ rgb {_vec(np.asarray(m.color) * radiance_scale)} }} {_EMISSIVE_FINISH} }}"
    if isinstance(m, DiffuseMaterial):
        if not any(e > 0 for e in m.emission):
            return f"texture {{ {_diffuse_pigment(m)} {_LAMBERT_FINISH} }}"
        # POV-Ray scales emission by the pigment; average a lit texture and an
        # emissive one, each at twice its colour, to get albedo * lit + emission.
        emitted = 2.0 * np.asarray(m.emission, dtype=float) * radiance_scale
        return ("texture { average texture_map {\n"
                f"    [1 {_diffuse_pigment(m, 2.0)} {_LAMBERT_FINISH}]\n"
                f"    [1 pigment {{ rgb {_vec(emitted)} }} {_EMISSIVE_FINISH}]\n"
                "  } }")
    raise TypeError(f"unknown material {m!r}")  # pragma: no cover - the scene parser admits no others


def _object(obj, texture: str, offset_m=None) -> str:
    """The object's SDL; a moving one translated by ``offset_m`` after its
    texture, so that the texture moves with it."""
    text = _still_object(obj, texture)
    if offset_m is None or not np.any(offset_m):
        return text
    return f"object {{ {text} translate {_vec(offset_m)} }}"


def _still_object(obj, texture: str) -> str:
    if isinstance(obj, Sphere):
        return f"sphere {{ {_vec(obj.center)}, {format_number(obj.radius)} texture {{ {texture} }} }}"
    if isinstance(obj, Box):
        return f"box {{ {_vec(obj.min)}, {_vec(obj.max)} texture {{ {texture} }} }}"
    if isinstance(obj, Rectangle):
        c, e1, e2 = (np.asarray(v, dtype=float) for v in (obj.corner, obj.edge1, obj.edge2))
        p0, p1, p2, p3 = c, c + e1, c + e1 + e2, c + e2
        return (f"mesh {{ triangle {{ {_vec(p0)}, {_vec(p1)}, {_vec(p3)} }} "
                f"triangle {{ {_vec(p2)}, {_vec(p3)}, {_vec(p1)} }} texture {{ {texture} }} }}")
    if isinstance(obj, Mesh):
        vertices = ",\n    ".join(_vec(v) for v in obj.vertices_m)
        faces = ",\n    ".join(f"<{a}, {b}, {c}>" for a, b, c in obj.triangles.tolist())
        return (f"mesh2 {{  // {obj.file.name}\n  vertex_vectors {{ {len(obj.vertices_m)},\n    {vertices} }}\n"
                f"  face_indices {{ {len(obj.triangles)},\n    {faces} }}\n  texture {{ {texture} }}\n}}")
    raise TypeError(f"unknown object {obj!r}")  # pragma: no cover
