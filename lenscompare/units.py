"""The one boundary between scene units (metres) and camera units (millimetres).

Scene lengths are metres, camera and lens lengths millimetres (DESIGN.md); every
conversion goes through these two functions, so a missing factor of 1000 has
one place to hide.

>>> mm_from_m(2.0)
2000.0
>>> m_from_mm(50.0)
0.05
"""

from __future__ import annotations

__all__ = ["MM_PER_M", "mm_from_m", "m_from_mm"]

MM_PER_M = 1000.0


def mm_from_m(length_m):
    """Metres to millimetres (floats or numpy arrays)."""
    return length_m * MM_PER_M


def m_from_mm(length_mm):
    """Millimetres to metres (floats or numpy arrays)."""
    return length_mm / MM_PER_M
