"""The shading lanes give the same image on every instruction set.

The per-packet shading (native/src/shading_lanes.cpp: surface points, normals
and checker albedo, shadow-ray set-up, the lights' sums) is compiled once per
instruction set; ``LENSCOMPARE_SHADING_KERNEL`` makes a process run the named
one. Each kernel uses only correctly rounded operations in the scalar code's
order (no fused multiply-adds), so every kernel the CPU can run must render
the same bits: RGB and spectral, a still and a moving scene, and the lens
system (whose packets take their live rays in vectors with the AVX-512
kernel), with Embree held to one instruction set so that only the shading
kernel changes.
"""

import os
import subprocess
import sys

import numpy as np
import pytest

from helpers import REFERENCE_SCENES

RENDER = """
import sys, numpy as np
from lenscompare._native import diagnostics
from lenscompare.render import render
from lenscompare.scene import load_scene
print(diagnostics.shading_kernel())
for name in ("lit_showcase", "moving_showcase"):
    scene = load_scene(f"{sys.argv[1]}/{name}.toml").with_camera(resolution=(96, 64))
    np.save(f"{sys.argv[2]}_{name}.npy", render(scene, model="thin", spp=4, seed=5, threads=2).pixels)
scene = load_scene(f"{sys.argv[1]}/showcase.toml").with_camera(resolution=(96, 64))
np.save(f"{sys.argv[2]}_spectral.npy", render(scene, model="thin", spp=4, seed=5, threads=2, spectral=True).pixels)
# The lens system wide open vignettes: on AVX-512 a packet's live rays are
# appended in vectors (native/src/packet_append.h), elsewhere one by one.
lens = scene.with_camera(lens="dgauss.50mm", f_number=None)
np.save(f"{sys.argv[2]}_lens.npy", render(lens, model="lens", spp=4, seed=5, threads=2).pixels)
np.save(f"{sys.argv[2]}_lens_table_mirrored.npy",
        render(lens, model="lens", spp=4, seed=5, threads=2, lens_rays="table", lens_mirrors=True).pixels)
"""
IMAGES = ("lit_showcase", "moving_showcase", "spectral", "lens", "lens_table_mirrored")


def shading_kernels():
    """Shading kernels this CPU can run, slowest first."""
    flags = set()
    if os.path.exists("/proc/cpuinfo"):
        with open("/proc/cpuinfo", encoding="ascii") as f:
            flags = next((set(line.split(":", 1)[1].split()) for line in f if line.startswith("flags")), set())
    return ["default"] + [k for k, flag in (("avx2", "avx2"), ("avx512", "avx512f")) if flag in flags]


@pytest.mark.skipif(len(shading_kernels()) < 2, reason="this CPU runs only the default shading kernel")
def test_every_shading_kernel_renders_the_same_bits(tmp_path):
    images = {}
    for kernel in shading_kernels():
        env = dict(os.environ, LENSCOMPARE_SHADING_KERNEL=kernel, LENSCOMPARE_EMBREE_ISA="sse2")
        run = subprocess.run([sys.executable, "-c", RENDER, str(REFERENCE_SCENES), str(tmp_path / kernel)], env=env,
                             check=True, capture_output=True, text=True)
        assert run.stdout.split()[0] == kernel  # the variable took effect
        images[kernel] = {name: np.load(tmp_path / f"{kernel}_{name}.npy") for name in IMAGES}
    for kernel, by_name in images.items():
        for name, pixels in by_name.items():
            assert pixels.max() > 0
            assert pixels.tobytes() == images["default"][name].tobytes(), (kernel, name)


def test_an_unknown_shading_kernel_falls_back_to_the_fastest():
    env = dict(os.environ, LENSCOMPARE_SHADING_KERNEL="no-such-kernel")
    run = subprocess.run([sys.executable, "-c", "from lenscompare._native import diagnostics; "
                          "print(diagnostics.shading_kernel())"], env=env, check=True, capture_output=True, text=True)
    assert run.stdout.strip() == shading_kernels()[-1]
