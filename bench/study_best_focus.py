"""Best focus against paraxial focus for the shipped lenses (issue 14).

For each lens, wide open and at f/8, focused at a distance it reaches:
- the film shift of ``focus_mode = "best"`` from the paraxial image (mm;
  negative: toward the lens), and the on-axis RMS spot radius at both films;
- the plane that is sharpest in paraxial mode: the object distance whose best
  focus lies on the paraxial film (``lenses.sharpest_plane_m``), and its
  offset from the focus distance in percent.

Prints one JSON object {"rows": [...]}.  Usage: python bench/study_best_focus.py
"""

from __future__ import annotations

import json

from lenscompare.lenses import (
    best_focus_film_z_mm,
    film_distance_mm,
    load_prescription,
    paraxial_data,
    rms_spot_radius_mm,
    sharpest_plane_m,
    stopped_down,
)

FOCUS_M = {"dgauss.50mm": 2.0, "wide.22mm": 2.0, "telephoto.250mm": 5.0, "fisheye.10mm": 2.0}


def main():
    rows = []
    for name, focus_m in FOCUS_M.items():
        lens = load_prescription(name)
        for f_number in (None, 8.0):
            stopped = lens if f_number is None else stopped_down(lens, f_number)
            paraxial_z = stopped.total_track_mm + film_distance_mm(stopped, focus_m)
            best_z = best_focus_film_z_mm(stopped, focus_distance_m=focus_m)
            plane_m = sharpest_plane_m(stopped, film_z_mm=paraxial_z)
            rows.append({
                "lens": name, "f_number": round(paraxial_data(stopped).f_number, 3), "focus_distance_m": focus_m,
                "best_focus_shift_mm": best_z - paraxial_z,
                "rms_spot_um": {"paraxial": 1000 * rms_spot_radius_mm(stopped, focus_distance_m=focus_m,
                                                                      film_z_mm=paraxial_z),
                                "best": 1000 * rms_spot_radius_mm(stopped, focus_distance_m=focus_m,
                                                                  film_z_mm=best_z)},
                "sharpest_plane_in_paraxial_mode_m": plane_m,
                "sharpest_plane_offset_percent": 100.0 * (plane_m / focus_m - 1.0),
            })
    print(json.dumps({"rows": rows}, indent=1))


if __name__ == "__main__":
    main()
