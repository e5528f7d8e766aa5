"""Independent check of the ``aberrations`` effect: the lens system's spot at
the film corner by a brute-force Monte Carlo trace written here (own sphere
intersections and Snell's law, random rays over the front element), not by
lenscompare.lenses.trace. Only the prescription's numbers (radii,
thicknesses, indices, semi-apertures at the scene's f-number), the film
position and the entrance pupil come from lenscompare.

Prints one JSON object: the planner's axis and corner spots (px) and this
trace's, in the window rule of lenscompare.plan.spot_window.

Usage: python bench/check_spot_montecarlo.py SCENE [--rays N]
(e.g. reference_scenes/effects/wide_stopped_down.toml: planner 0.306 px at the
44.3 deg corner, this trace 0.29 px)
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np

from lenscompare.cameras import camera_for
from lenscompare.lenses import field_at_film_height_deg, paraxial_data
from lenscompare.plan.effects import aberration_spot_px
from lenscompare.plan.spot_window import settled_window_px
from lenscompare.reference_scenes import find_scene
from lenscompare.scene import load_scene


def trace(surfaces, origins, directions):
    """Rays (mm, lens frame: z = 0 at the first vertex) through the surfaces:
    where they leave the last one, their directions, and which got through."""
    o, d, z0, n1 = origins, directions, 0.0, 1.0
    alive = np.ones(len(o), bool)
    for s in surfaces:
        if math.isinf(s.radius_mm):
            p, normal = o + ((z0 - o[:, 2]) / d[:, 2])[:, None] * d, None
        else:
            centre = np.array([0.0, 0.0, z0 + s.radius_mm])
            oc = o - centre
            b = (oc * d).sum(1)
            disc = b * b - ((oc * oc).sum(1) - s.radius_mm ** 2)
            alive &= disc > 0
            root = np.sqrt(np.maximum(disc, 0.0))
            p = o + (-b - root if s.radius_mm > 0 else -b + root)[:, None] * d  # the cap through the vertex
            normal = (p - centre) / s.radius_mm
            normal *= -np.sign(normal[:, 2:3])  # against the light
        alive &= p[:, 0] ** 2 + p[:, 1] ** 2 <= s.semi_aperture_mm ** 2
        n2 = s.n_after
        if normal is not None and n2 != n1:
            eta, cos_i = n1 / n2, -(normal * d).sum(1)
            k = 1.0 - eta * eta * (1.0 - cos_i ** 2)
            alive &= k > 0
            d = eta * d + (eta * cos_i - np.sqrt(np.maximum(k, 0.0)))[:, None] * normal
            d /= np.linalg.norm(d, axis=1)[:, None]
        alive &= d[:, 2] > 0
        o, z0, n1 = p, z0 + s.thickness_mm, n2
    return o, d, alive


def spot_px(system, field_deg, rays, seed=1):
    """Second-moment spot diameter (px, windowed as the planner's) of a point on the plane of focus."""
    rng = np.random.default_rng(seed)
    prescription = system.prescription
    distance = system.focus_distance_mm
    pupil_z = paraxial_data(prescription).entrance_pupil_position_mm
    source = np.array([0.0, distance * math.tan(math.radians(field_deg)), pupil_z - distance])
    front = prescription.surfaces[0].semi_aperture_mm * 1.05
    r, a = front * np.sqrt(rng.random(rays)), 2.0 * math.pi * rng.random(rays)
    target = np.stack([r * np.cos(a), r * np.sin(a), np.zeros(rays)], 1)
    toward = target - source
    length = np.linalg.norm(toward, axis=1)
    weight = toward[:, 2] / length ** 3  # solid angle per unit area of the target disk
    d = toward / length[:, None]
    o = source + d * ((-1.0 - source[2]) / d[:, 2])[:, None]
    out_o, out_d, passed = trace(prescription.surfaces, o, d)
    out_o, out_d, w = out_o[passed], out_d[passed], weight[passed]
    xy = out_o[:, :2] + out_d[:, :2] * ((system.film_z_mm - out_o[:, 2]) / out_d[:, 2])[:, None]
    pitch = system.pixel_pitch_mm

    def diameter(window_px):  # weighted second moment about the centroid, inside the window
        centre = np.average(xy, axis=0, weights=w)
        inside = np.hypot(*(xy - centre).T) <= window_px * pitch
        pts, pw = xy[inside], w[inside]
        var = np.average((pts - np.average(pts, axis=0, weights=pw)) ** 2, axis=0, weights=pw)
        return 4.0 * math.sqrt(0.5 * var.sum()) / pitch

    return settled_window_px(diameter)[1], len(xy)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--rays", type=int, default=4_000_000)
    args = parser.parse_args()
    scene = load_scene(find_scene(args.scene))
    system = camera_for(scene, "lens")
    corner = field_at_film_height_deg(scene.camera.lens, system.film.half_diagonal_mm,
                                      focus_distance_m=system.focus_distance_m, start_deg=system.corner_field_deg)
    rows = {}
    for where, field in (("axis", 0.0), ("corner", corner)):
        brute, passed = spot_px(system, field, args.rays)
        rows[where] = {"field_deg": field, "planner_px": aberration_spot_px(system, field),
                       "montecarlo_px": brute, "rays_passed": passed}
    print(json.dumps({"scene": scene.name, "f_number": system.f_number, "focus_mode": system.focus_mode, **rows},
                     indent=1))


if __name__ == "__main__":
    main()
