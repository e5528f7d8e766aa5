"""Shared fixtures: scene text builders."""

from __future__ import annotations

from pathlib import Path

import pytest

from helpers import MINIMAL_SCENE


@pytest.fixture
def minimal_scene_text() -> str:
    return MINIMAL_SCENE


@pytest.fixture
def main():
    """The command line's ``main`` (every command registered)."""
    from lenscompare import cli

    return cli.main


@pytest.fixture
def write_scene(tmp_path):
    """Write scene text to a file in tmp_path and return its path."""

    def _write(text: str, name: str = "scene.toml") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path

    return _write
