"""Mesh scenes: a mesh of more than 100,000 triangles loaded (binary PLY, ASCII PLY, OBJ),
built into Embree and rendered; load time and memory printed as JSON.

The mesh is the shipped Stanford Bunny (reference_scenes/bunny.ply, 3,000
triangles) subdivided by trimesh until it has at least 100,000 triangles
(3,000 -> 12,000 -> 48,000 -> 192,000). Each format is written to a temporary
folder and loaded through a scene file in a fresh subprocess, which reports
the scene load time (trimesh read, the count check, the transform), the
Embree build time, a 360 x 240 thin-lens render at 16 spp, and the process's
peak resident memory (``ru_maxrss``) after the imports and after the load.

Usage: python bench/bench_mesh.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np
import trimesh

BUNNY = Path(__file__).resolve().parent.parent / "reference_scenes" / "bunny.ply"
MIN_TRIANGLES = 100_000

CHILD = textwrap.dedent("""
    import json, resource, sys, time
    before_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    from lenscompare.native_scene import build_native_scene
    from lenscompare.render import render
    from lenscompare.scene import load_scene
    imported_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter(); scene = load_scene(sys.argv[1]); t1 = time.perf_counter()
    loaded_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    build_native_scene(scene); t2 = time.perf_counter()
    image = render(scene, spp=16, threads=2, progress=False)
    print(json.dumps({"load_seconds": t1 - t0, "embree_build_seconds": t2 - t1,
                      "render_seconds": image.metadata["seconds"],
                      "samples_per_second": image.metadata["samples_per_second"],
                      "peak_rss_after_imports_mb": imported_kb / 1024, "peak_rss_after_load_mb": loaded_kb / 1024,
                      "load_rss_increase_mb": (loaded_kb - imported_kb) / 1024, "image_mean": float(image.pixels.mean())}))
""")

SCENE = """
[camera]
model = "thin"
position = [0.0, 0.5, -1.0]
look_at = [0.0, 0.3, 2.5]
focal_length_mm = 50.0
f_number = 4.0
focus_distance = 3.5
resolution = [360, 240]
[materials.grey]
type = "diffuse"
color = [0.7, 0.7, 0.7]
[[objects]]
type = "mesh"
file = "{file}"
scale = 0.8
translate = [0.0, 0.3947, 2.5]
material = "grey"
[[lights]]
type = "point"
position = [2.0, 4.0, 0.0]
color = [30.0, 30.0, 30.0]
falloff = "inverse_square"
"""


def main():
    mesh = trimesh.load(BUNNY, process=False)
    while len(mesh.faces) < MIN_TRIANGLES:
        mesh = mesh.subdivide()
    results = {"triangles": int(len(mesh.faces)), "vertices": int(len(mesh.vertices)), "formats": {}}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        files = {"ply_binary": ("mesh.ply", dict(encoding="binary")), "ply_ascii": ("mesh_ascii.ply",
                 dict(encoding="ascii")), "obj": ("mesh.obj", {})}
        for label, (name, options) in files.items():
            mesh.export(folder / name, **options)
            scene = folder / f"{label}.toml"
            scene.write_text(SCENE.format(file=name))
            out = subprocess.run([sys.executable, "-c", CHILD, str(scene)], capture_output=True, text=True, check=True)
            results["formats"][label] = {"file_mb": (folder / name).stat().st_size / 2**20, **json.loads(out.stdout)}
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
