"""pbrt-v4 export: our scenes as pbrt scene text (:func:`scene_to_pbrt`), for
users who render them in pbrt. pbrt itself is not run here."""

from .export import PBRT_MODELS, PbrtScene, lens_file_text, scene_to_pbrt

__all__ = ["PBRT_MODELS", "PbrtScene", "scene_to_pbrt", "lens_file_text"]
