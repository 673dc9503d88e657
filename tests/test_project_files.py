"""The project's own files: the license pyproject declares, and what git ignores."""

from __future__ import annotations

import re
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


def readme_commands() -> list[str]:
    """The README's shell blocks' commands: the install-and-demo one, then the install-and-test one."""
    return re.findall(r"```sh\n(python3 -m venv .venv [^\n]*)\n```", (REPO / "README.md").read_text())


def test_ci_runs_the_readme_commands_exactly_with_the_stock_pip() -> None:
    ci = (REPO / ".ci" / "run").read_text()
    commands = readme_commands()
    assert len(commands) == 2 and "retrokit demo" in commands[0] and "pytest" in commands[1], commands
    lines = [line.rstrip("\\ ").strip() for line in ci.splitlines()]
    positions = [lines.index(command) for command in commands]  # each verbatim, as a line of its own
    build = lines.index("retrokit build-core genesis_plus_gx")
    assert positions[0] < build < positions[1]  # the patched core is built before the tests run
    for text in (ci, (REPO / "README.md").read_text()):
        assert not re.search(r"pip install[^\n]*(-U|--upgrade)[^\n]*\bpip\b", text)  # the stock pip, never upgraded


def test_the_readme_gives_the_measured_time_of_its_two_commands() -> None:
    """Measured times, with the machine and the day, not a guess ("about a minute" was 3 CPU-minutes)."""
    text = (REPO / "README.md").read_text()
    demo, tests = text.index("retrokit demo\n```"), text.index("python -m pytest -q\n```")
    before_demo = " ".join(text[:demo].split())
    assert re.search(r"\(\d+ s on the developers' 2-core \S+ VM with nothing else running, \d+ CPU-seconds, "
                     r"\d{4}-\d\d-\d\d", before_demo), "the demo's measured time, machine and day"
    after_tests = " ".join(text[tests:text.index("## The main job")].split())
    assert re.search(r"took [\d,]+ s \([\d.]+ minutes, [\d,]+ tests\) on the developers' 2-core \S+ VM with "
                     r"nothing else running \(\d{4}-\d\d-\d\d\)", after_tests), "the suite's measured time"


def test_the_readme_and_evaluate_guide_say_how_much_faster_the_built_core_is_as_the_descriptor_measured_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from retrokit.host.buildhint import build_hint
    from retrokit.host.systems import get_system

    text = " ".join((REPO / "README.md").read_text()[:4000].split())  # its first lines, before "The main job"
    assert text.index("## The main job") > text.index("retrokit build-core genesis_plus_gx")
    assert f"Genesis envs step {get_system('Genesis').build_speedup:.1f}x faster" in text
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path))  # nothing built there: the line the commands print
    monkeypatch.delenv("RETROKIT_CORES", raising=False)
    assert build_hint("Genesis") in (REPO / "docs" / "evaluate.md").read_text().splitlines()
