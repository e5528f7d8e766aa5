"""Constants and helpers the tests share (import as ``from helpers import ...``)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
REFERENCE_SCENES = REPO / "reference_scenes"

# A small valid scene; tests replace pieces of it with str.replace.
MINIMAL_SCENE = textwrap.dedent("""\
    name = "minimal"

    [camera]
    model = "thin"
    position = [0.0, 0.0, 0.0]
    look_at = [0.0, 0.0, 1.0]
    focal_length_mm = 50.0
    f_number = 2.8
    focus_distance = 2.0
    film_mm = [36.0, 24.0]
    resolution = [36, 24]

    [render]
    spp = 4

    [materials.glow]
    type = "emissive"
    color = [1.0, 1.0, 1.0]

    [materials.grey]
    type = "diffuse"
    color = [0.5, 0.5, 0.5]

    [[objects]]
    type = "sphere"
    center = [0.0, 0.0, 2.0]
    radius = 0.1
    material = "glow"

    [[objects]]
    type = "box"
    min = [-1.0, -1.0, 3.0]
    max = [1.0, 1.0, 3.1]
    material = "grey"

    [[lights]]
    type = "point"
    position = [1.0, 2.0, -1.0]
    color = [1.0, 1.0, 1.0]
    """)


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run ``python -m lenscompare`` as a user would, capturing its output."""
    return subprocess.run([sys.executable, "-m", "lenscompare", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def camera_scene_text(*, model="thin", position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0),
                      focal_length_mm=50.0, f_number=2.8, focus_distance=2.0, resolution=(360, 240),
                      film_mm=(36.0, 24.0), spp=64, objects="", extra=""):
    """Scene text with one emissive material ``glow`` and the given camera; ``objects`` is appended."""

    def vec(v):
        return "[" + ", ".join(repr(float(c)) for c in v) + "]"

    return textwrap.dedent(f"""\
        [camera]
        model = "{model}"
        position = {vec(position)}
        look_at = {vec(look_at)}
        up = {vec(up)}
        focal_length_mm = {focal_length_mm!r}
        f_number = {f_number!r}
        focus_distance = {focus_distance!r}
        film_mm = {vec(film_mm)}
        resolution = [{resolution[0]}, {resolution[1]}]

        [render]
        spp = {spp}

        [materials.glow]
        type = "emissive"
        color = [1.0, 1.0, 1.0]
        """) + extra + objects


def sphere_text(center, radius, material="glow"):
    x, y, z = (float(c) for c in center)
    return (f'\n[[objects]]\ntype = "sphere"\ncenter = [{x!r}, {y!r}, {z!r}]\n'
            f'radius = {float(radius)!r}\nmaterial = "{material}"\n')


def white_points_text(lens_path, *, angles_deg, film_mm, width_px: int, spp: int) -> str:
    """A spectral lens-system scene: white emissive points 1 km away at
    ``angles_deg`` from the axis (toward +x) on the plane of focus, on black
    (the lateral-colour tests' scene)."""
    import math

    spheres = "".join(f"""
[[objects]]
type = "sphere"
center = [{1000.0 * math.sin(math.radians(a))}, 0.0, {1000.0 * math.cos(math.radians(a))}]
radius = 0.5
material = "white"
""" for a in angles_deg)
    return f"""
[camera]
model = "lens"
lens = "{lens_path}"
f_number = 20
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
focus_distance = 1000.0
film_mm = [{film_mm[0]}, {film_mm[1]}]
resolution = [{width_px}, {int(width_px * film_mm[1] / film_mm[0])}]

[render]
spp = {spp}
sampler = "sobol"
spectral = true

[background]
color = [0.0, 0.0, 0.0]

[materials.white]
type = "emissive"
color = [1.0, 1.0, 1.0]
{spheres}"""
