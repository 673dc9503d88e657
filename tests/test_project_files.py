"""The project's own files: the license pyproject declares, and what git ignores."""

from __future__ import annotations

import subprocess
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


def test_the_declared_mit_license_ships_as_a_file() -> None:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]
    text = (REPO / "LICENSE").read_text()
    assert text.startswith("MIT License") and "WITHOUT WARRANTY OF ANY KIND" in text


def test_the_demo_output_is_ignored_by_git() -> None:
    if not (REPO / ".git").exists():
        pytest.skip("an installed copy has no git")
    probe = subprocess.run(["git", "-C", str(REPO), "check-ignore", "-q", "retrokit-demo/Dasher-Genesis.gif"], check=False)
    assert probe.returncode == 0
