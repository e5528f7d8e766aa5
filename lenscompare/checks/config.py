"""Check configurations (TOML): a list of declarative accuracy checks.

```toml
[[check]]
name = "thin-lens blur disks within 2 % of equation 5"   # optional
type = "blur_equation5"        # see CHECK_TYPES for each type's keys
scene = "scenes/blur.toml"     # paths are relative to this file
```

How a check's ``scene`` is found: a path (relative paths against the config
file's folder) when that file exists; otherwise a bare name with no folder and
no ``.toml`` (``scene = "showcase"``) names the scene of that name shipped in
the package (``lenscompare/reference_scenes/``, see
:func:`lenscompare.reference_scenes.find_scene`).  The shipped ``default.toml``
names its scenes this way, so it runs the same from a source tree and from an
installed wheel, and a copy of it keeps working wherever it is put.  ``image``
and ``lens`` paths are relative to the config file (a lens may also be a
shipped lens name such as ``dgauss.50mm``).

Everything is checked when the config is loaded, before any check runs: each
key's type and range (``spp`` an integer from 1 to 2^20, ``model`` one the
check can render, ``quantity`` one ``lens info`` gives...), and that every
scene, lens and image a check names can be read (a scene also through the
check's model, and through POV-Ray for ``povray_ssim``). A bad config is exit 2
naming the config file, the check (``check[N]``) and the key; only what the
checks measure decides between exit 0 and 1.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .._schema import Table, load_toml
from ..cameras import camera_for
from ..errors import InputError
from ..lenses import load_prescription
from ..lenses.info import LENS_INFO_FIELDS
from ..limits import MAX_NAME_CHARS, MAX_SPP, check_render_budget
from ..mitsuba import MITSUBA_MODELS
from ..povray import MAX_POVRAY_SPP, POVRAY_MODELS, pov_camera
from ..reference_scenes import find_scene
from ..scene import MODELS, load_scene

__all__ = ["Check", "CHECK_TYPES", "load_checks", "DEFAULT_CONFIG", "lens_argument"]

# Read through importlib.resources: the package's own folder, in a source tree
# or an installed wheel.
DEFAULT_CONFIG = Path(str(resources.files(__package__) / "default.toml"))

# type -> (required keys, optional keys with defaults)
CHECK_TYPES = {
    # image = "...": measure that image (any renderer's) instead of a native render.
    "blur_equation5": ({"scene"}, {"model": "thin", "tolerance_percent": 2.0, "spp": 256, "min_expected_px": 4.0,
                                   "image": None}),
    # Every measurement the scene lists, on any renderer's image (lenscompare measure).
    "measure": ({"scene", "image"}, {"model": None, "blur_tolerance_percent": 2.0, "min_blur_px": 4.0,
                                     "projection_tolerance_px": 0.25, "distortion_tolerance_percent": 0.2,
                                     "vignetting_tolerance": 0.02, "min_ssim": 0.97}),
    "povray_ssim": ({"scene"}, {"model": "thin", "min_ssim": 0.97, "spp": 64, "povray_spp": 256}),
    # Mitsuba 3 against native: SSIM, and (for thin-lens scenes with emissive spheres) blur disks against eq. 5.
    "mitsuba_agreement": ({"scene"}, {"model": "thin", "min_ssim": 0.97, "spp": 64, "mitsuba_spp": 128,
                                      "tolerance_percent": 2.0, "min_expected_px": 4.0}),
    "lens_paraxial": ({"lens", "quantity", "expected"}, {"relative_tolerance": 1e-6}),
    "image_matches": ({"image", "scene"}, {"model": None, "spp": 256, "min_ssim": 0.97, "max_delta_e": 2.0}),
}

# The models each check type can render.
_MODELS = {"blur_equation5": MODELS, "povray_ssim": POVRAY_MODELS, "image_matches": MODELS, "measure": MODELS,
           "mitsuba_agreement": MITSUBA_MODELS}
_QUANTITIES = tuple(key for key, _, _ in LENS_INFO_FIELDS)


def _read_key(table: Table, key: str, kind: str):
    """One option's value, checked for its type and range."""
    if key in ("scene", "lens", "image"):
        return table.string(key, max_chars=4096)
    if key == "model":
        return table.string(key, choices=_MODELS[kind])
    if key == "quantity":
        return table.string(key, choices=_QUANTITIES)
    if key in ("spp", "povray_spp", "mitsuba_spp"):
        return table.integer(key, minimum=1, maximum=MAX_POVRAY_SPP if key == "povray_spp" else MAX_SPP)
    if key == "min_ssim":
        return table.number(key, minimum=-1.0, maximum=1.0)
    if key in ("tolerance_percent",):
        return table.number(key, positive=True)
    if key == "expected":
        return table.number(key)
    return table.number(key, non_negative=True)  # relative_tolerance, min_expected_px, max_delta_e


@dataclass(frozen=True)
class Check:
    name: str
    type: str
    options: dict
    base_dir: Path

    def path(self, key: str) -> Path:
        """The file an option names: relative to the config file; for ``scene``
        a shipped scene's short name too (see the module docstring)."""
        if key == "scene":
            return find_scene(self.options[key], self.base_dir)
        value = Path(self.options[key])
        return value if value.is_absolute() else self.base_dir / value


def lens_argument(check: Check) -> str:
    """What ``load_prescription`` gets for the check's ``lens``: a path when it
    looks like one (relative to the config file), else the shipped name."""
    lens = str(check.options["lens"])
    return str(check.path("lens")) if ("/" in lens or lens.endswith(".dat")) else lens


def load_checks(path: str | os.PathLike) -> list[Check]:
    """Read, type-check and resolve a check config (see the module docstring).

    Raises
    ------
    InputError
        Naming the config file, ``check[N].key`` and what is wrong.
    """
    source = os.fspath(path)
    root = Table(load_toml(source, what="check config"), source=source)
    root.check_keys(["check"])
    checks = []
    for table in root.tables("check"):
        kind = table.string("type", choices=CHECK_TYPES)
        required, optional = CHECK_TYPES[kind]
        table.check_keys(["type", "name", *sorted(required), *sorted(optional)])
        options = dict(optional)
        for key in sorted(required | set(optional)):
            if key in table.data:
                options[key] = _read_key(table, key, kind)
            elif key in required:
                raise table.error(key, "missing (required)")
        name = table.string("name", default=f"{kind} {options.get('scene') or options.get('lens')}",
                            max_chars=MAX_NAME_CHARS)
        check = Check(name, kind, options, Path(source).resolve().parent)
        _check_inputs(check, table)
        checks.append(check)
    if not checks:
        raise InputError(source, "no [[check]] tables")
    return checks


def _check_inputs(check: Check, table: Table) -> None:
    """Every file the check names can be read, and its scene rendered as asked."""
    o = check.options
    try:
        if "scene" in o:
            key = "scene"
            scene = load_scene(check.path("scene"))
            model = o["model"] or scene.camera.model
            key = "model"
            camera_for(scene, model)
            if check.type == "povray_ssim":
                pov_camera(scene, model)
            key = "spp"
            width, height = scene.camera.resolution
            check_render_budget(width, height, max(o.get("spp", 1), o.get("povray_spp", 1), o.get("mitsuba_spp", 1)),
                                source=scene.source)
        if "lens" in o:
            key = "lens"
            load_prescription(lens_argument(check))
        if o.get("image") is not None:  # optional for some types (None: render natively)
            key = "image"
            image = check.path("image")
            if not image.is_file():
                raise InputError(str(image), "no such image file" if not image.exists() else "is not a regular file")
    except InputError as error:
        raise table.error(key, str(error)) from None
