"""The ``postfilter`` model: image-based depth of field after Potmesil and
Chakravarty (1981). A pinhole render and its depth buffer; every pixel spread
over its own eq.-5 circle of confusion.

- :mod:`.depth`: the depth buffer (native, one ray per pixel centre);
- :mod:`.blur`: each pixel's signed blur diameter, the depth layers, the spread;
- :mod:`.refine`: the default pinhole pass: 2 film samples, 16 where they show an edge;
- :mod:`.samples`: each pixel's pinhole samples, fewer where its blur averages them (opt-in);
- :mod:`.edges`: where it is wrong (occlusion edges) and the planner's predicate.

:func:`lenscompare.render.render` runs the pinhole pass and calls :func:`spread`.
"""

from __future__ import annotations

from .blur import MAX_PINHOLE_SPP, METHOD, pinhole_pass_spp, signed_coc_px, spread
from .depth import depth_buffer_m
from .samples import MIN_PINHOLE_SPP, pinhole_sample_counts
from .edges import (BAND_PX, EDGE_JUMP_PX, EdgeError, edge_band, edge_band_error, occlusion_edges, postfilter_edge_error,
                    postfilter_suffices)

__all__ = ["MAX_PINHOLE_SPP", "METHOD", "pinhole_pass_spp", "signed_coc_px", "spread", "depth_buffer_m",
           "MIN_PINHOLE_SPP", "pinhole_sample_counts",
           "BAND_PX", "EDGE_JUMP_PX", "EdgeError", "edge_band", "edge_band_error", "occlusion_edges", "postfilter_edge_error", "postfilter_suffices"]
