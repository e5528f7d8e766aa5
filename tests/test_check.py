"""``lenscompare check``: the shipped config passes; failures and bad configs
give exit 1 and 2; JUnit XML is written."""

from xml.etree import ElementTree as ET

import pytest

from lenscompare.errors import InputError

from helpers import REPO, run_cli


def test_default_config_passes_and_writes_junit(tmp_path):
    junit = tmp_path / "junit.xml"
    result = run_cli("check", "--junit", junit)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "5 passed, 0 failed" in result.stdout
    suite = ET.parse(junit).getroot()
    assert suite.tag == "testsuite" and suite.get("tests") == "5" and suite.get("failures") == "0"


def test_a_failing_check_exits_1(tmp_path):
    config = tmp_path / "checks.toml"
    config.write_text('[[check]]\ntype = "lens_paraxial"\nlens = "dgauss.50mm"\n'
                      'quantity = "effective_focal_length_mm"\nexpected = 50.0\n')
    junit = tmp_path / "j.xml"
    result = run_cli("check", config, "--junit", junit)
    assert result.returncode == 1
    assert "FAIL" in result.stdout and "0 passed, 1 failed" in result.stdout
    assert ET.parse(junit).getroot().get("failures") == "1"


def test_image_matches_its_own_render(tmp_path):
    scene = REPO / "reference_scenes" / "flat_field.toml"
    out = tmp_path / "mine.exr"
    assert run_cli("render", scene, "-o", out, "--spp", "16").returncode == 0
    config = tmp_path / "checks.toml"
    config.write_text(f'[[check]]\ntype = "image_matches"\nimage = "{out}"\nscene = "{scene}"\nspp = 16\n')
    result = run_cli("check", config)
    assert result.returncode == 0, result.stdout


def test_a_short_scene_name_means_the_shipped_scene_unless_such_a_file_exists(tmp_path):
    from lenscompare.checks import load_checks
    from lenscompare.reference_scenes import find_scene, scenes_dir, shipped_scene_names

    assert {"blur_disks", "dot_grid", "flat_field", "showcase"} <= set(shipped_scene_names())
    # The source tree's reference_scenes/ is the packaged folder itself.
    assert (REPO / "reference_scenes").resolve() == scenes_dir().resolve()
    config = tmp_path / "checks.toml"
    shipped_text = (scenes_dir() / "showcase.toml").read_text()
    (tmp_path / "showcase.toml").write_text(shipped_text)
    config.write_text('[[check]]\ntype = "blur_equation5"\nscene = "showcase"\n'
                      '[[check]]\ntype = "blur_equation5"\nscene = "showcase.toml"\n')
    shipped, path = load_checks(config)
    assert shipped.path("scene") == scenes_dir() / "showcase.toml"
    assert path.path("scene") == tmp_path / "showcase.toml"  # a .toml name is always a path
    (tmp_path / "showcase").write_text("")
    assert shipped.path("scene") == tmp_path / "showcase"  # a file of that name wins
    # Neither a file nor shipped: the config is refused when it loads, naming the check and key.
    config.write_text('[[check]]\ntype = "blur_equation5"\nscene = "mine"\n')
    with pytest.raises(InputError, match=r"check\[0\]\.scene: .*mine: no such scene file"):
        load_checks(config)
    assert find_scene("showcase", tmp_path / "elsewhere") == scenes_dir() / "showcase.toml"


def test_bad_config_exits_2(tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text('[[check]]\ntype = "blur_equation5"\nscene = "x.toml"\ntolerance = 3\n')
    result = run_cli("check", config)
    assert result.returncode == 2 and "check[0].tolerance" in result.stderr and "Traceback" not in result.stderr
    config.write_text('[[check]]\ntype = "magic"\n')
    assert run_cli("check", config).returncode == 2
