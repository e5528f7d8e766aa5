"""Pure optics functions (no rendering): the thin-lens relations of the paper."""

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
    "aperture_diameter_mm",
    "blur_angle_rad",
    "circle_of_confusion_mm",
    "defocus_diopters",
    "f_number",
    "focus_film_distance_mm",
    "image_distance_mm",
    "lens_power_diopters",
]
