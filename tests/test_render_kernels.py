"""How much the image depends on which instruction set runs Embree.

Embree picks its kernels by the CPU (the render's 16-wide packets are native
on AVX-512, split into narrower ones elsewhere); ``LENSCOMPARE_EMBREE_ISA``
caps them, so each kernel this CPU can run renders the same scene in its own
process (Embree reads the cap when a device is made). Embree's SSE2 and AVX
kernels give the same bits; its AVX2 and AVX-512 kernels round hit distances
differently (fused multiply-adds), which moves hit points by an ulp: measured
on lit_showcase, 120 x 80, 8 spp, about half the pixels differ, by at most
1.1e-6 absolute and 8e-8 of the image's sum (0.3 % in the worst pixel, a
sample that crossed a checker or shadow edge). The native code around Embree
does not depend on the CPU: it uses no fused multiply-add (CMakeLists.txt)
except the single-precision lens trace, which fuses on every kernel (the
portable one through std::fma), so its kernels agree to the bit too
(lens_batch_check.py).
"""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from helpers import REFERENCE_SCENES

RENDER = """
import sys, numpy as np
from lenscompare.render import render
from lenscompare.scene import load_scene
scene = load_scene(sys.argv[1]).with_camera(resolution=(120, 80))
for model in ("pinhole", "thin", "lens"):
    s = scene.with_camera(lens="dgauss.50mm", f_number=None) if model == "lens" else scene
    np.save(f"{sys.argv[2]}_{model}.npy", render(s, model=model, spp=8, seed=3, threads=2).pixels)
"""


def cpu_flags():
    with open("/proc/cpuinfo", encoding="ascii") as f:
        for line in f:
            if line.startswith("flags"):
                return set(line.split(":", 1)[1].split())
    return set()


def embree_isas():
    """Embree ISA caps this CPU can run, slowest first."""
    flags = cpu_flags()
    isas = ["sse2"]
    if "avx2" in flags:
        isas.append("avx2")
    if {"avx512f", "avx512dq", "avx512bw", "avx512vl", "avx512cd"} <= flags:
        isas.append("avx512")
    return isas


# lit_showcase's spheres and quads would go to the render's own tests (sphere_lanes.h,
# quad_lanes.h) and leave Embree nothing to trace: hand them all to Embree.
EMBREE_TAKES_ALL = {"LENSCOMPARE_MAX_OWN_SPHERES": "0", "LENSCOMPARE_MAX_OWN_QUADS": "0"}


@pytest.mark.skipif(not os.path.exists("/proc/cpuinfo"), reason="reads the CPU flags from /proc/cpuinfo")
def test_every_embree_kernel_renders_the_same_image(tmp_path):
    scene = REFERENCE_SCENES / "lit_showcase.toml"
    images = {}
    for isa in embree_isas():
        env = dict(os.environ, LENSCOMPARE_EMBREE_ISA=isa, **EMBREE_TAKES_ALL)
        subprocess.run([sys.executable, "-c", RENDER, str(scene), str(tmp_path / isa)], env=env, check=True)
        images[isa] = {m: np.load(tmp_path / f"{isa}_{m}.npy") for m in ("pinhole", "thin", "lens")}
    baseline = images["sse2"]
    for isa, by_model in images.items():
        for model, pixels in by_model.items():
            assert pixels.max() > 0
            difference = np.abs(pixels.astype(np.float64) - baseline[model])
            report = json.dumps({"isa": isa, "model": model,
                                 "pixels_differing": int(np.any(difference > 0, axis=-1).sum()),
                                 "max_abs": float(difference.max()),
                                 "sum_relative": float(difference.sum() / np.abs(baseline[model]).sum())})
            # Rounding of hit distances only: a wrong hit or a lost shadow would cost far more.
            assert difference.max() < 1e-4 and difference.sum() < 1e-6 * np.abs(baseline[model]).sum(), report


def test_sixteen_wide_packets_split_for_sse_give_the_sse_image(tmp_path):
    """SSE2 and AVX round alike: the same image bit for bit, and no lane of a
    16-wide packet split into SSE's 4-wide ones upsets Embree (its idle shadow
    lanes hold harmless rays; Debian's Embree checks them by assertion)."""
    scene = REFERENCE_SCENES / "lit_showcase.toml"
    images = {}
    for isa in ("sse2", "avx"):
        env = dict(os.environ, LENSCOMPARE_EMBREE_ISA=isa, **EMBREE_TAKES_ALL)
        subprocess.run([sys.executable, "-c", RENDER, str(scene), str(tmp_path / isa)], env=env, check=True)
        images[isa] = [np.load(tmp_path / f"{isa}_{m}.npy") for m in ("pinhole", "thin", "lens")]
    for sse, avx in zip(images["sse2"], images["avx"]):
        assert sse.tobytes() == avx.tobytes()
