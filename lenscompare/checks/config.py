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
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from .._schema import Table
from ..errors import InputError
from ..reference_scenes import find_scene

__all__ = ["Check", "CHECK_TYPES", "load_checks", "DEFAULT_CONFIG"]

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


def load_checks(path: str | os.PathLike) -> list[Check]:
    source = os.fspath(path)
    try:
        data = tomllib.loads(Path(source).read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(source, f"cannot read check config ({error})") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(source, f"not valid TOML ({error})") from None
    root = Table(data, source=source)
    root.check_keys(["check"])
    checks = []
    for table in root.tables("check"):
        kind = table.string("type", choices=CHECK_TYPES)
        required, optional = CHECK_TYPES[kind]
        table.check_keys(["type", "name", *sorted(required), *sorted(optional)])
        options = dict(optional)
        for key in required | set(optional):
            if key in table.data:
                value = table.data[key]
                if isinstance(optional.get(key), (int, float)) and not isinstance(optional.get(key), bool):
                    value = table.number(key, positive=key != "relative_tolerance")
                options[key] = value
            elif key in required:
                raise table.error(key, "missing (required)")
        name = table.string("name", default=f"{kind} {options.get('scene') or options.get('lens')}")
        checks.append(Check(name, kind, options, Path(source).resolve().parent))
    if not checks:
        raise InputError(source, "no [[check]] tables")
    return checks
