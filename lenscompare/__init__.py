"""lenscompare: pinhole, thin, thick and full-lens cameras, compared.

The native tracer (``lenscompare._native``) is private; this package is the
public face.  Submodules are imported on use so that the pure-Python parts
(optics, lenses, metrics) work without the compiled module.
"""

__version__ = "0.1.0"
