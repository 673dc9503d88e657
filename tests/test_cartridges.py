"""Every cartridge of tools/cartridges.yaml: its committed ROM is the one its game.yaml names, and a fresh build
from its source, with the toolchain that built it, gives that ROM byte for byte."""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml

from retrokit.data.roms import rom_sha1

REPO = Path(__file__).resolve().parent.parent
CARTRIDGES: dict[str, dict] = yaml.safe_load((REPO / "tools" / "cartridges.yaml").read_text())


def _rom(game: str) -> Path:
    return REPO / "games" / game / CARTRIDGES[game]["rom"]


@pytest.mark.parametrize("game", CARTRIDGES)
def test_each_entry_names_its_source_rom_and_benchmark(game: str) -> None:
    entry = CARTRIDGES[game]
    assert set(entry) == {"source", "rom", "tools", "versions", "packages", "benchmark"}, game
    assert (REPO / entry["source"] / "Makefile").is_file()
    assert (REPO / entry["source"] / "toolchain.txt").is_file()
    assert _rom(game).is_file()
    assert (REPO / "retrokit" / "benchmark" / f"{entry['benchmark']}.yaml").is_file()


@pytest.mark.parametrize("game", CARTRIDGES)
def test_committed_rom_is_the_one_game_yaml_names(game: str) -> None:
    # retrokit's own hash, by stable-retro's rules: an NES ROM's 16-byte iNES header is left out.
    doc = yaml.safe_load((REPO / "games" / game / "game.yaml").read_text())
    assert [r["sha1"] for r in doc["roms"]] == [rom_sha1(_rom(game))]


def test_ci_installs_every_cartridge_toolchain() -> None:
    ci = (REPO / ".ci" / "run").read_text()
    listed = set(re.search(r"^optional=\(([^)]*)\)", ci, re.MULTILINE).group(1).split())
    needed = {package for entry in CARTRIDGES.values() for package in entry["packages"]}
    assert needed <= listed, f".ci/run does not install {sorted(needed - listed)}"


@pytest.fixture(scope="module")
def builds(tmp_path_factory: pytest.TempPathFactory) -> Callable[[Path], Path]:
    """``make`` of a source folder, run once for the module: one Makefile builds both ROMs of a console pair
    (Master System and Game Gear, Game Boy and Color), so its second cartridge reads the same fresh build."""
    done: dict[Path, Path] = {}

    def build(source: Path) -> Path:
        if source not in done:
            folder = tmp_path_factory.mktemp(f"build-{source.name}")
            result = subprocess.run(
                ["make", "-s", "-C", str(source), f"BUILD={folder}", f"PYTHON={sys.executable}"],
                capture_output=True, text=True, check=False,
            )
            assert result.returncode == 0, result.stdout + result.stderr
            done[source] = folder
        return done[source]

    return build


@pytest.mark.parametrize("game", CARTRIDGES)
def test_rom_rebuilds_byte_for_byte(game: str, builds: Callable[[Path], Path]) -> None:
    entry = CARTRIDGES[game]
    source = REPO / entry["source"]
    missing = [tool for tool in entry["tools"] if not shutil.which(tool)]
    if missing:
        pytest.skip(
            f"{game}'s toolchain is not installed (missing {', '.join(missing)}; Debian: "
            f"{' '.join(entry['packages'])}); its committed ROM's SHA-1 is checked against game.yaml instead"
        )
    # Byte for byte holds for the toolchain that built the committed ROM (`make install` records it).
    recorded = (source / "toolchain.txt").read_text().splitlines()
    installed = [_first_line(command) for command in entry["versions"]]
    if installed != recorded:
        pytest.skip(f"{game}'s committed ROM was built with {recorded}, this machine has {installed}")
    rebuilt = (builds(source) / entry["rom"]).read_bytes()
    assert rebuilt == _rom(game).read_bytes(), f"the committed {entry['rom']} differs from a fresh build: run make install"


def _first_line(command: str) -> str:
    result = subprocess.run(shlex.split(command), capture_output=True, text=True, check=False)
    return (result.stdout or result.stderr).splitlines()[0]
