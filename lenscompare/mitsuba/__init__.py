"""Mitsuba 3 as a second independent reference: the same scene exported to
Mitsuba's XML (:func:`scene_to_mitsuba`, :func:`write_mitsuba`) and rendered
by Mitsuba from those files (:func:`render_mitsuba`), pinhole and thin lens."""

from .export import MAX_MITSUBA_SEED, MITSUBA_MODELS, MITSUBA_SAMPLERS, MitsubaScene, scene_to_mitsuba, write_ply
from .runner import MITSUBA_VARIANTS, load_mitsuba, mitsuba_version, render_mitsuba, write_mitsuba

__all__ = ["MITSUBA_MODELS", "MAX_MITSUBA_SEED", "MITSUBA_SAMPLERS", "MITSUBA_VARIANTS", "MitsubaScene", "scene_to_mitsuba", "write_mitsuba", "write_ply",
           "render_mitsuba", "mitsuba_version", "load_mitsuba"]
