"""Lens systems: prescriptions, paraxial data, focusing and the real-ray trace.

Pure Python and numpy.  One job per module:

- :mod:`.prescription` reads and validates pbrt lens files;
- :mod:`.resolve` finds the file a scene's ``camera.lens`` names;
- :mod:`.info` gathers a lens's first-order data for ``lens info`` and checks;
- :mod:`.paraxial` gives first-order data (focal lengths, principal planes,
  pupils, f-number) and stops a lens down;
- :mod:`.focus` places the film for a focus distance;
- :mod:`.best_focus` finds the film position of the smallest on-axis spot
  (``focus_mode = "best"``) and the plane a film position shows sharpest;
- :mod:`.trace` is the exact ray trace (the native tracer ports it to C++);
- :mod:`.analysis` measures distortion, relative illumination and the image
  circle with it;
- :mod:`.chromatic` measures lateral and longitudinal colour (per-wavelength
  chief rays and paraxial foci);
- :mod:`.maps` traces a focused lens's distortion and illumination against
  film radius once, for the composite camera.

Lengths are mm, focus distances m; axial positions are mm from the first
vertex, positive toward the film.
"""

from .analysis import (
    chief_ray_distortion_percent,
    chief_ray_film_height_mm,
    field_at_film_height_deg,
    image_circle_radius_mm,
    paraxial_image_scale_mm,
    real_f_number,
    relative_illumination,
    point_source_spot_mm,
    spot_diameter_mm,
    traced_spot_diameter_mm,
)
from .chromatic import (
    axial_image_z_mm,
    chief_ray_height_at_mm,
    chief_ray_heights_at_mm,
    lateral_color_mm,
    longitudinal_color_blur_mm,
)
from .best_focus import best_focus_film_z_mm, rms_spot_radius_mm, sharpest_plane_m
from .maps import LateralColorMap, RadialMaps, lateral_color_map, pupil_relative_illumination, radial_maps
from .focus import closest_focus_distance_m, film_distance_mm, front_most_z_mm
from .paraxial import (
    ParaxialData,
    aperture_stop_index,
    paraxial_data,
    ray_transfer_matrix,
    stop_semi_aperture_for_f_number,
    stopped_down,
)
from .prescription import (
    Prescription,
    Surface,
    load_prescription,
    parse_prescription,
    sag_mm,
    shipped_lens_names,
)
from .resolve import resolve_lens
from .trace import TracedRays, trace_from_film, trace_from_scene

__all__ = [
    "Prescription",
    "Surface",
    "load_prescription",
    "parse_prescription",
    "sag_mm",
    "shipped_lens_names",
    "resolve_lens",
    "ParaxialData",
    "aperture_stop_index",
    "paraxial_data",
    "ray_transfer_matrix",
    "stop_semi_aperture_for_f_number",
    "stopped_down",
    "closest_focus_distance_m",
    "film_distance_mm",
    "front_most_z_mm",
    "best_focus_film_z_mm",
    "rms_spot_radius_mm",
    "sharpest_plane_m",
    "TracedRays",
    "trace_from_film",
    "trace_from_scene",
    "chief_ray_distortion_percent",
    "chief_ray_film_height_mm",
    "field_at_film_height_deg",
    "image_circle_radius_mm",
    "paraxial_image_scale_mm",
    "traced_spot_diameter_mm",
    "point_source_spot_mm",
    "spot_diameter_mm",
    "real_f_number",
    "relative_illumination",
    "axial_image_z_mm",
    "chief_ray_height_at_mm",
    "chief_ray_heights_at_mm",
    "lateral_color_mm",
    "longitudinal_color_blur_mm",
    "LateralColorMap",
    "lateral_color_map",
    "RadialMaps",
    "radial_maps",
    "pupil_relative_illumination",
]
