"""``lenscompare plan SCENE``: which effects the scene needs, and the model."""

from __future__ import annotations

import json

from ..plan import plan_scene
from . import COMMAND_HELP
from ._options import NON_NEGATIVE, SCENE_HELP, load_scene_argument, with_lens_option

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("plan", help=COMMAND_HELP["plan"],
                              description="Predict each lens effect's size from the scene and camera (no "
                                          "rendering) and pick the cheapest model within tolerance.")
    p.add_argument("scene", metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("--tolerance-px", type=NON_NEGATIVE, default=0.5, help="largest blur/distortion left out (px)")
    p.add_argument("--tolerance-percent", type=NON_NEGATIVE, default=2.0, help="largest corner falloff left out (%%)")
    p.add_argument("--lens", metavar="NAME|PATH", help="lens prescription (shipped name or file)")
    p.add_argument("--no-costs", action="store_true", help="skip the timing renders")
    p.add_argument("--json", action="store_true")
    p.set_defaults(run=run)


def run(args) -> int:
    plan = plan_scene(with_lens_option(load_scene_argument(args.scene), args.lens), tolerance_px=args.tolerance_px,
                      tolerance_percent=args.tolerance_percent, measure_costs=not args.no_costs)
    data = plan.to_json()
    if args.json:
        print(json.dumps(data))
        return 0
    print(f"model: {data['model']}  (tolerance {args.tolerance_px:g} px, {args.tolerance_percent:g} %)")
    print(f"  simulates: {', '.join(data['simulated']) or 'nothing'}" + (f"  ({data['note']})" if "note" in data else ""))
    for name, e in data["effects"].items():
        flag = "needed " if e["needed"] else "omitted"
        print(f"  {flag} {name:18s} {e['magnitude']:9.3g} {e['unit']:2s}  {e['detail']}")
    for model, seconds in data["predicted_seconds"].items():
        how = "  (the lens system as render --model auto renders it)" if model == "lens_auto" else ""
        print(f"  predicted {model:10s} {seconds:8.2f} s{how}")
    return 0
