"""System descriptors agree with the facts in the stable-retro wheel's cores/*.json (each system's tools on a real game: tests/test_systems.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml

from retrokit.errors import InvalidArgumentError, UnknownNameError, UnsupportedSystemError
from retrokit.host.cores import find_core
from retrokit.host.systems import all_systems, get_system, system_for_extension
from retrokit.paths import wheel_cores_dir, wheel_dir


def wheel_systems() -> dict[str, dict]:
    folder = wheel_cores_dir()
    assert folder is not None
    facts: dict[str, dict] = {}
    for path in sorted(folder.glob("*.json")):
        facts.update(json.loads(path.read_text()))
    return facts


WHEEL = wheel_systems()

# Where a descriptor departs from the wheel's file on purpose, the fact is checked on the real
# core instead: the PC Engine's action groups (the wheel's repeat IV and offer III-VI, which
# the core's 2-button pad never delivers and, for III and IV, turns into turbo switches;
# tests/test_pcecart.py).
CORRECTED = {("PCEngine", "actions")}


def test_every_wheel_system_has_a_descriptor() -> None:
    assert set(WHEEL) == set(all_systems())


@pytest.mark.parametrize("name", sorted(WHEEL))
def test_descriptor_matches_the_wheel(name: str) -> None:
    ours, theirs = get_system(name), WHEEL[name]
    assert ours.core == theirs["lib"]
    assert list(ours.extensions) == theirs["ext"]
    assert list(ours.buttons) == theirs["buttons"]
    assert ours.ram_base == (theirs.get("rambase") or 0)
    assert ours.ram_swap == (theirs["overlay"][2] if "overlay" in theirs else 1)
    assert list(ours.types) == theirs.get("types", [])
    if (name, "actions") not in CORRECTED:
        assert [[list(c) for c in group] for group in ours.actions] == theirs.get("actions", [])


@pytest.mark.parametrize("name", sorted(WHEEL))
def test_each_system_core_is_installed(name: str) -> None:
    assert find_core(get_system(name).core).is_file()


def test_genesis_buttons_are_retropad_bits() -> None:
    genesis = get_system("Genesis")
    # RetroPad ids: B 0, Y 1, SELECT 2, START 3, UP 4 ... A 8, X 9, L 10, R 11.
    assert genesis.mask(["B"]) == 1 << 0
    assert genesis.mask(["A"]) == 1 << 1  # the core maps RetroPad Y to Genesis A
    assert genesis.mask(["C"]) == 1 << 8  # and RetroPad A to Genesis C
    assert genesis.mask(["MODE", "START"]) == (1 << 2) | (1 << 3)
    assert genesis.buttons_of(genesis.mask(["RIGHT", "C"])) == ["RIGHT", "C"]


def test_system_lookup_is_case_insensitive_and_suggests() -> None:
    assert get_system("genesis").name == "Genesis"
    with pytest.raises(UnsupportedSystemError, match="Did you mean 'Genesis'"):
        get_system("Genisis")


def test_extension_lookup() -> None:
    assert system_for_extension(".md").name == "Genesis"
    assert system_for_extension("smd").name == "Genesis"
    assert system_for_extension("sfc").name == "Snes"
    with pytest.raises(UnsupportedSystemError, match=r"got '\.mdd'.*Did you mean '\.md'"):
        system_for_extension("mdd")


def test_unknown_button_suggests() -> None:
    with pytest.raises(UnknownNameError, match="Did you mean 'START'"):
        get_system("Genesis").mask(["STRAT"])
    with pytest.raises(InvalidArgumentError, match=r"list of button names.*\['RIGHT'\]"):
        get_system("Genesis").mask("RIGHT")


def test_genesis_dump_aliases_name_genesis() -> None:
    for ext in ("gen", "smd"):
        assert system_for_extension(ext).name == "Genesis"
    assert system_for_extension("bin").name == "N64"  # a system's own extension wins over an alias

# --- what proves each system: the descriptor's proven_by, tools/cartridges.yaml and docs/systems.md agree ----

REPO = Path(__file__).resolve().parent.parent
CARTRIDGES = yaml.safe_load((REPO / "tools" / "cartridges.yaml").read_text())


def test_each_cartridge_proves_its_system_and_each_proof_exists() -> None:
    for game in CARTRIDGES:
        assert get_system(game.rsplit("-", 1)[1]).proven_by.get("cartridge") == game, game
    for system in all_systems().values():
        assert set(system.proven_by) <= {"cartridge", "stable-retro", "ale-py"}, system.name
        if "cartridge" in system.proven_by:
            assert system.proven_by["cartridge"] in CARTRIDGES, system.name
        if "stable-retro" in system.proven_by:  # a wheel game whose ROM the wheel ships
            folder = wheel_dir() / "data" / "stable" / f"{system.proven_by['stable-retro']}-v0"
            assert any(folder.glob("rom.*")), folder


def systems_page() -> dict[str, dict[str, str]]:
    """docs/systems.md: each system's table, row name -> text."""
    sections = re.split(r"^## ", (REPO / "docs" / "systems.md").read_text(), flags=re.MULTILINE)[1:]
    out = {}
    for section in sections:
        name, _, body = section.partition("\n")
        out[name.strip()] = dict(re.findall(r"^\| ([^|]+?) \| (.+) \|$", body, flags=re.MULTILINE))
    return out


def test_the_systems_page_has_every_system_and_says_how_each_is_proven() -> None:
    page = systems_page()
    assert set(page) == set(all_systems())
    for name, rows in page.items():
        system = get_system(name)
        assert rows["core"] == f"`{system.core}`" and f"base `0x{system.ram_base:X}`" in rows["RAM"], name
        if system.proven:
            assert all(game in rows["proven by"] for game in system.proven_by.values() if game), name
        else:
            assert rows["proven by"].startswith("Nothing proves it yet"), name
        for rate in system.frame_rates.values():
            assert f"{rate:g}" in rows["frame rate"], name


def test_games_marks_the_games_of_an_unproven_system(capsys) -> None:
    from retrokit.cli import main

    assert main(["games", "1942-Nes"]) == 0
    out = capsys.readouterr().out
    assert ("[unproven: Nes]" in out) == (not get_system("Nes").proven)
    assert main(["games", "Dasher-Genesis"]) == 0
    assert "unproven" not in capsys.readouterr().out
