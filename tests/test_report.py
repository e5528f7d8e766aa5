"""``lenscompare report``: a quick report renders, measures and writes a page
whose every image loads in a real browser (headless Chromium)."""

import json
import re
import shutil
import subprocess

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
    for render in results["renders"]:
        assert (quick_report / render["exr"]).is_file() and (quick_report / render["png"]).is_file()


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
