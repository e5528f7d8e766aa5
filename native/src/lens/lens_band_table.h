// What a dispersive lens system's band rays (cameras/lens_system_bands.cpp)
// need from the back-trace at 380 nm, by table look-up instead of a trace
// per sample: how fast the film point and the rim clearance move with the
// dispersion parameter k.
//
// On the lens-ray table's grid (lens_ray_table.h: per exit-pupil ring, both
// of its ends x radial x around, half of the pupil), each node traces its
// ray at d and back at 380 nm, both with the rims stopping nothing (the
// clearances kept), and holds the film point's shift per unit of k (mm, for
// the film point on +x) and the clearance's slope in k. A sample's values
// are interpolated trilinearly and turned to its film azimuth. Both are
// smooth where the rays are: the shift is lateral and longitudinal colour
// (under half a pixel on the shipped lenses), so a relative error of 1e-3
// moves a wavelength's film point by 1e-3 of that; the slope only places
// the end of a rim's stretch of the spectrum, within the sliver of rays
// whose clearance changes sign over it. tests/test_lens_bands.py measures
// both against the trace.
#pragma once

#include <memory>
#include <vector>

#include "lens/exit_pupil.h"
#include "lens/lens_ray_table.h"
#include "lens/lens_trace.h"

namespace lc {

enum BandTableValue : int {
    kBandShiftX,  // film point's shift per unit of k, mm (film point on +x)
    kBandShiftY,
    kBandSlope,   // d(clearance) / dk
    kBandValues
};

// One node: its values at the ring's inner and outer film radius (NaN
// throughout where a trace failed: a sample in a cell touching it is
// back-traced instead; 0 on rings outside the image circle, whose samples
// the lens blocks).
struct alignas(32) BandTableNode {
    float end[2][4];
};

struct LensBandTable : LensTableGrid {
    std::vector<BandTableNode> nodes;  // [ring][radial][around, u.y from 0 to 1/2]
};

// elements at d (the camera's), blue_reversed the lens at 380 nm mirrored
// for the back-trace (lens_reverse.h), k_per_blue = k(380 nm) - k(d).
std::shared_ptr<const LensBandTable> build_lens_band_table(const std::vector<LensElement>& elements,
                                                           const std::vector<LensElement>& blue_reversed,
                                                           double k_per_blue, const ExitPupil& pupil,
                                                           double film_z_mm, int radial_cells, int around_cells);

// Lanes [0, n): shift_x_mm / shift_y_mm per unit of k (lens frame) and the
// clearance's slope; valid[i] false where the table cannot answer (the
// caller back-traces those lanes).
void look_up_band_shifts(const LensBandTable& table, FilmPlacement film, const Point2f* raster_px,
                         const Point2f* lens_sample, int n, double* shift_x_mm, double* shift_y_mm, double* slope,
                         bool* valid);

// The same in two steps, so that other work can hide the table's cache
// misses between them: where lanes [0, n) read the table, their cells'
// cache lines asked for (prefetched); then the values.
void locate_band_cells(const LensBandTable& table, FilmPlacement film, const Point2f* raster_px,
                       const Point2f* lens_sample, int n, TableCellLanes* cells);
void look_up_band_shifts(const LensBandTable& table, const TableCellLanes& cells, int n, double* shift_x_mm,
                         double* shift_y_mm, double* slope, bool* valid);

}  // namespace lc
