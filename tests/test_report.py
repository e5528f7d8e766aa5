"""``lenscompare report``: a quick report renders, measures and writes a page
whose every image loads in a real browser (headless Chromium)."""

import copy
import json
import re
import shutil
import subprocess
from importlib import resources

import pytest

from lenscompare.report.html import SECTIONS

from helpers import REFERENCE_SCENES, run_cli


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    scenes = [REFERENCE_SCENES / f"{name}.toml" for name in ("blur_disks", "flat_field", "showcase")]
    result = run_cli("report", *scenes, "-o", out, "--quick")
    assert result.returncode == 0, result.stderr
    assert "index.html" in result.stdout
    return out


def test_results_json_holds_every_render_and_measurement(quick_report):
    results = json.loads((quick_report / "results.json").read_text())
    labels = {(r["scene"], r["model"], r["renderer"]) for r in results["renders"]}
    for scene in ("blur_disks", "flat_field", "showcase"):
        for model in ("pinhole", "thin", "thick", "lens"):
            assert (scene, model, "native") in labels
        for model in ("pinhole", "thin"):
            assert (scene, model, "povray") in labels
    blur = results["scenes"]["blur_disks"]["blur_disks"]["renders"]["thin"]
    # Quick mode halves the resolution: only disks of 4 px and more are measured well.
    large = [row for row in blur if row and row["expected_px"] >= 4.0]
    assert large and all(abs(row["error_percent"]) < 10 for row in large), large
    vignetting = results["scenes"]["flat_field"]["vignetting"]["renders"]
    assert vignetting["thin"]["at"]["10_deg"] == pytest.approx(1.0, abs=0.02)
    assert vignetting["lens"]["at"]["10_deg"] < 0.85  # the Double Gauss vignettes
    assert results["scenes"]["showcase"]["vs_povray"]["thin"]["ssim"] > 0.95
    # Mitsuba renders blur_disks and flat_field (emissive only); showcase's lights have no inverse-square
    # falloff, so Mitsuba leaves it out and says why.
    for scene in ("blur_disks", "flat_field"):
        assert {(scene, m, "mitsuba") for m in ("pinhole", "thin")} <= labels
        assert results["scenes"][scene]["vs_mitsuba"]["thin"]["ssim"] > 0.95
    assert results["scenes"]["showcase"]["vs_mitsuba"] == {}
    assert any("Mitsuba" in n and "falloff" in n for n in results["scenes"]["showcase"]["notes"])
    mitsuba_blur = results["scenes"]["blur_disks"]["blur_disks"]["renders"]["thin (Mitsuba)"]
    assert all(abs(row["error_percent"]) < 10 for row in mitsuba_blur if row and row["expected_px"] >= 4.0)
    for render in results["renders"]:
        assert (quick_report / render["exr"]).is_file() and (quick_report / render["png"]).is_file()


def _schema_errors(results: dict) -> list[str]:
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(resources.files("lenscompare.report").joinpath("results.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
            for e in jsonschema.Draft202012Validator(schema).iter_errors(results)]


def test_results_json_follows_the_published_schema(quick_report):
    results = json.loads((quick_report / "results.json").read_text())
    assert _schema_errors(results) == []
    # Strict where the shape is fixed: a renamed or missing key is caught ...
    broken = copy.deepcopy(results)
    broken["scenes"]["showcase"]["vs_lens"]["thin"]["SSIM"] = broken["scenes"]["showcase"]["vs_lens"]["thin"].pop("ssim")
    del broken["scenes"]["showcase"]["renders"][0]["seconds"]
    del broken["scenes"]["blur_disks"]["blur_disks"]
    broken["render_list"] = broken.pop("renders")
    errors = " ".join(_schema_errors(broken))
    for missing in ("'ssim' is a required property", "'SSIM' was unexpected", "'seconds' is a required property",
                    "'blur_disks' is a required property", "'renders' is a required property"):
        assert missing in errors, (missing, errors)
    # ... but any scene name is allowed.
    renamed = copy.deepcopy(results)
    renamed["scenes"]["my scene, v2"] = renamed["scenes"].pop("showcase")
    assert _schema_errors(renamed) == []


def test_an_unknown_short_scene_name_is_refused_with_the_shipped_names(tmp_path):
    result = run_cli("report", "no_such_scene", "-o", tmp_path / "out", cwd=tmp_path)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "no_such_scene" in result.stderr and "showcase" in result.stderr, result.stderr


def test_page_has_its_sections_and_every_image_loads_in_chromium(quick_report):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        pytest.skip("chromium is not installed (make test installs it)")
    dom = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                          "--virtual-time-budget=5000", "--dump-dom", (quick_report / "index.html").as_uri()],
                         capture_output=True, text=True, timeout=120).stdout
    for key, title in SECTIONS:
        assert f'id="{key}"' in dom, key
    loaded = re.search(r'data-images-loaded="(\d+)"', dom)
    total = re.search(r'data-images-total="(\d+)"', dom)
    assert loaded and total, "the page's load script did not run"
    assert int(total.group(1)) >= 3 * 6 + 3
    assert loaded.group(1) == total.group(1)
