"""What machine a benchmark ran on, for its JSON: figures are tied to a CPU.

The project's benchmarks have run on four kinds of machine (AMD Zen 4, an AVX2-only
AMD EPYC, an Intel Xeon with AVX-512, AMD Zen 5) whose ratios differ by tens of per
cent; ``describe()`` names the CPU, its family and model, the vector extensions the
native kernels choose between and the lens-trace kernel this CPU runs.
"""

from __future__ import annotations

import os
import platform
from pathlib import Path

from lenscompare._native import diagnostics

# The extensions the native kernels are built for (cpu_kernels.h, lens_trace_kernels.cpp).
VECTOR_FLAGS = ("avx2", "fma", "avx512f", "avx512vl", "avx512bw", "avx512dq")


def describe() -> dict:
    """The CPU as /proc/cpuinfo gives it (Linux), and the native kernels' choice."""
    fields = _cpuinfo_fields()
    flags = set(fields.get("flags", "").split())
    return {
        "machine": platform.machine(),
        "cpu_count": os.cpu_count(),
        "cpu_model": fields.get("model name"),
        "cpu_family": _int(fields.get("cpu family")),
        "cpu_model_number": _int(fields.get("model")),
        "vector_extensions": [f for f in VECTOR_FLAGS if f in flags],
        "lens_trace_kernels": list(diagnostics.lens_trace_kernels()),
    }


def _cpuinfo_fields() -> dict:
    """The first processor's fields of /proc/cpuinfo; empty where there is none."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return {}
    fields = {}
    for line in text.split("\n\n", 1)[0].splitlines():
        key, _, value = line.partition(":")
        fields[key.strip()] = value.strip()
    return fields


def _int(text):
    try:
        return int(text)
    except (TypeError, ValueError):
        return None
