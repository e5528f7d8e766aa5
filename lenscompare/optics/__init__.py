"""Pure optics functions (no rendering): the thin-lens relations of the paper,
the aperture's shape and its diffraction."""

from .aperture import (aperture_vertices, inside_aperture, polygon_apothem, polygon_circumradius,
                       second_moment_diameter_ratio)

from .thin_lens import (
    aperture_diameter_mm,
    blur_angle_rad,
    circle_of_confusion_mm,
    defocus_diopters,
    f_number,
    focus_film_distance_mm,
    image_distance_mm,
    lens_power_diopters,
)

__all__ = [
    "aperture_vertices",
    "inside_aperture",
    "polygon_apothem",
    "polygon_circumradius",
    "second_moment_diameter_ratio",
    "aperture_diameter_mm",
    "blur_angle_rad",
    "circle_of_confusion_mm",
    "defocus_diopters",
    "f_number",
    "focus_film_distance_mm",
    "image_distance_mm",
    "lens_power_diopters",
]
