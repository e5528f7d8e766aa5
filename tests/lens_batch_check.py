"""The check every lockstep lens-trace test shares: the batch trace on every
kernel this CPU runs against the scalar trace (double precision, the
reference).

- ``precision="double"``: every kernel gives the scalar trace's bits.
- ``precision="single"`` (the render's trace): every kernel gives the same
  bits as the others, and the rays are the scalar trace's to float rounding.
  Measured over 200,000 samples of each shipped lens and of the hard-case
  test lenses (cemented zero-thickness layer, flat and nearly flat fronts,
  TIR prism, f/64): origins within 3e-5 mm, directions within 9.3e-6
  (fisheye) and 8e-5 (the TIR prism near its critical angle), at most one
  sample blocked by one trace only. The bounds below leave a margin over
  those figures.
"""

from __future__ import annotations

import numpy as np

from lenscompare._native import diagnostics

SINGLE_ORIGIN_TOLERANCE_M = 1e-7         # 1e-4 mm (world units are metres)
SINGLE_DIRECTION_TOLERANCE = 2e-4
SINGLE_BLOCKED_DIFFERENTLY_FRACTION = 1e-4


def assert_batch_matches_scalar(camera, batched_rays, scalar, *, kernels, precision):
    """batched_rays() returns (origin, direction, weight) from the batch trace
    under camera's current kernel; scalar is the same from the scalar trace.
    A blocked sample has a zero direction."""
    diagnostics.set_lens_trace_precision(camera, precision)
    by_kernel = {}
    for kernel in kernels:
        diagnostics.set_lens_trace_kernel(camera, kernel)
        by_kernel[kernel] = batched_rays()
    first = by_kernel[kernels[0]]
    for kernel, rays in by_kernel.items():
        for a, b in zip(first, rays):
            assert a.tobytes() == b.tobytes(), (precision, kernel)
    if precision == "double":
        for a, b in zip(scalar, first):
            assert a.tobytes() == b.tobytes()
        return
    origin, direction, weight = first
    assert all(np.isfinite(a).all() for a in first)
    passed_scalar, passed = np.any(scalar[1] != 0.0, axis=-1), np.any(direction != 0.0, axis=-1)
    assert np.mean(passed_scalar != passed) <= SINGLE_BLOCKED_DIFFERENTLY_FRACTION, np.sum(passed_scalar != passed)
    both = passed_scalar & passed
    assert np.abs(origin[both] - scalar[0][both]).max() <= SINGLE_ORIGIN_TOLERANCE_M
    assert np.abs(direction[both] - scalar[1][both]).max() <= SINGLE_DIRECTION_TOLERANCE
    # The weight comes from the aim, which stays in double: the same bits.
    assert weight[both].tobytes() == scalar[2][both].tobytes()
