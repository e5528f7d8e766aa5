"""``lenscompare report [SCENES...] -o DIR``: the main job."""

from __future__ import annotations

import contextlib
from pathlib import Path

from ..cluster import open_cluster
from ..errors import InputError
from ..experiment import ExperimentSettings
from ..lenses import resolve_lens
from ..reference_scenes import scenes_dir
from ..report import build_report
from ..scene import load_scene
from . import COMMAND_HELP
from ._options import THREADS, scene_path

__all__ = ["add_parser", "run", "DEFAULT_SCENES"]

# The scenes shipped in the package (lenscompare/reference_scenes/; the source
# tree's reference_scenes/ links to it), so an installed wheel finds them too.
DEFAULT_SCENES = scenes_dir()


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "report", help=COMMAND_HELP["report"],
        description="Render the scenes through pinhole, thin, thick and full-lens cameras and POV-Ray, measure "
                    "blur, distortion, vignetting and similarity, and write DIR/index.html and DIR/results.json.")
    p.add_argument("scenes", nargs="*", metavar="SCENE.toml",
                   help="scene files, or short names of the shipped scenes (showcase, blur_disks, ...) when no "
                        "such file exists (default: every shipped reference scene)")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--lens", default="dgauss.50mm", help="lens for scenes that name none (default dgauss.50mm)")
    p.add_argument("--quick", action="store_true", help="half resolution, a quarter of the samples (CI)")
    p.add_argument("--no-povray", action="store_true", help="skip the POV-Ray reference renders")
    p.add_argument("--no-mitsuba", action="store_true", help="skip the Mitsuba 3 reference renders")
    p.add_argument("--threads", type=THREADS, default=None,
                   help="threads per render (default and at most: every core; on a cluster, its machine's cores over "
                        "its Dask slots)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the renders as tasks on the Dask cluster of this scheduler (tcp://HOST:PORT)")
    p.set_defaults(run=run)


def run(args) -> int:
    paths = [scene_path(s) for s in args.scenes] or sorted(DEFAULT_SCENES.glob("*.toml"))
    if not paths:
        raise InputError("SCENE", f"no scene files given and none in {DEFAULT_SCENES}")
    resolve_lens(args.lens, source="--lens", key=None)  # a bad --lens fails now, not after the first scene
    scenes = [load_scene(p) for p in paths]
    names = [s.name for s in scenes]
    if len(set(names)) != len(names):
        raise InputError("SCENE", f"two scenes share a name ({', '.join(names)}); the report keys its results by name")
    settings = ExperimentSettings(lens=args.lens, quick=args.quick, threads=args.threads, povray=not args.no_povray,
                                  mitsuba=not args.no_mitsuba)
    with open_cluster(args.scheduler) if args.scheduler else contextlib.nullcontext() as cluster:
        results = build_report(scenes, args.output, settings, cluster=cluster, final=True)
    index = Path(args.output).resolve() / "index.html"
    print(f"Report written in {results['total_seconds']:.0f} s: open {index}")
    return 0
