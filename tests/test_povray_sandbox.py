"""POV-Ray's second barrier (lenscompare/povray/sandbox.py): should an SDL file
ever carry a write outside POV-Ray's private folder, the operating system
refuses it; no file can grow past the limit."""

from __future__ import annotations

import shutil
import signal
import subprocess
import tempfile
from pathlib import Path

import pytest

from lenscompare.errors import ExternalError
from lenscompare.povray.runner import run_povray
from lenscompare.povray.sandbox import landlock_abi

pytestmark = pytest.mark.skipif(shutil.which("povray") is None, reason="needs POV-Ray")

CAMERA = "camera { location <0, 0, -1> look_at <0, 0, 0> }\nglobal_settings { assumed_gamma 1.0 }\n"


def _writing_sdl(target: Path) -> str:
    return f'#version 3.7;\n#fopen F "{target}" write\n#write (F, "written by SDL\\n")\n#fclose F\n{CAMERA}'


@pytest.fixture
def outside(tmp_path):
    """A file under /tmp outside POV-Ray's folder (Debian's povray.conf lets POV-Ray write all of /tmp)."""
    folder = Path(tempfile.mkdtemp(prefix="lenscompare-outside-", dir="/tmp"))
    yield folder / "escaped.txt"
    shutil.rmtree(folder)


def test_povray_alone_writes_outside_its_folder_here(outside, tmp_path):
    """What the second barrier is for: POV-Ray's own restriction lets the write through on this system."""
    (tmp_path / "scene.pov").write_text(_writing_sdl(outside))
    result = subprocess.run(["povray", "+Iscene.pov", "-D", "+W4", "+H4", "-GA"], cwd=tmp_path,
                            capture_output=True, text=True, env={"HOME": str(tmp_path), "PATH": "/usr/bin:/bin"})
    if not outside.exists():
        pytest.skip(f"this POV-Ray's own configuration already refuses the write ({result.returncode})")
    assert outside.read_text() == "written by SDL\n"


@pytest.mark.skipif(landlock_abi() == 0, reason="the kernel has no Landlock")
def test_under_the_sandbox_povray_cannot_write_outside_its_folder(outside):
    with pytest.raises(ExternalError, match=r"Cannot open user file"):
        run_povray(_writing_sdl(outside), ["-D", "+W4", "+H4", "+FE"])
    assert not outside.exists()


def test_under_the_sandbox_povray_still_writes_its_image():
    pixels, result, _, _ = run_povray(f"#version 3.7;\n{CAMERA}background {{ rgb <0.25, 0.5, 1> }}\n",
                                      ["-D", "+W4", "+H3", "+FE", "-A"])
    assert pixels.shape == (3, 4, 3) and abs(float(pixels[..., 2].mean()) - 1.0) < 1e-3


def test_no_file_povray_writes_can_grow_past_the_limit():
    # About 2 MB of text into its own folder, under a 1 MiB limit: the write stops POV-Ray.
    sdl = ('#version 3.7;\n#fopen F "big.txt" write\n#for (I, 1, 20000)\n'
           f'#write (F, "{"x" * 99}\\n")\n#end\n#fclose F\n{CAMERA}')
    with pytest.raises(ExternalError, match=f"exit status -{int(signal.SIGXFSZ)}"):  # killed by the limit
        run_povray(sdl, ["-D", "+W4", "+H4", "+FE"], max_file_bytes=2**20)
    run_povray(sdl, ["-D", "+W4", "+H4", "+FE"], max_file_bytes=2**30)  # the same file under a larger limit
