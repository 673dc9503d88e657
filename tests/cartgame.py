"""A cartridge we build (tools/cartridges.yaml) under test: an emulator with the game's RAM fields by name.

tests/test_cartridge.py (Dasher) and tests/test_gbcart.py (Trekker) play their games through it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import yaml

from retrokit.host.emulator import Emulator


def game_fields(game_dir: Path) -> dict[str, tuple[int, str]]:
    """The fields of a game's game.yaml, as ``name: (address, type)``."""
    doc = yaml.safe_load((game_dir / "game.yaml").read_text())
    return {name: (int(f["address"]), f["type"]) for name, f in doc["fields"].items()}


def header_defines(header: Path) -> dict[str, int]:
    """The hexadecimal ``#define NAME 0x...`` constants of a C header (a cartridge's RAM map)."""
    text = header.read_text()
    return {name: int(value, 16) for name, value in re.findall(r"^#define (\w+) (0x[0-9A-Fa-f]+)\b", text, re.MULTILINE)}


def assert_fields_match(fields: Mapping[str, tuple[int, str]], known: Mapping[str, int], source: str) -> None:
    """Every game.yaml field is at the address the cartridge's source gives it."""
    for name, (address, _) in fields.items():
        assert name in known, f"game.yaml field {name!r} is not in {source}"
        assert address == known[name], f"{name}: game.yaml says {address:#x}, {source} {known[name]:#x}"


class CartridgeGame:
    """An emulator running one of our cartridges, its fields read and written by name.

    Args:
        rom: The ROM.
        fields: ``name: (address, type)``, from :func:`game_fields`.
        options: Core options.
    """

    def __init__(self, rom: Path, fields: Mapping[str, tuple[int, str]], options: dict[str, str] | None = None) -> None:
        self.emu = Emulator.for_rom(rom, options=options or {})
        self.fields = fields
        self.mask = self.emu.system.mask

    def __getitem__(self, name: str) -> int:
        address, code = self.fields[name]
        return self.emu.peek(address, code)

    def __setitem__(self, name: str, value: int) -> None:
        address, code = self.fields[name]
        self.emu.poke(address, value, code)

    def run(self, *ports: Sequence[str], frames: int = 1) -> None:
        """Run frames holding each port's buttons (port 1 first; none: nothing pressed)."""
        self.emu.run([self.mask(list(buttons)) for buttons in ports] or [0], frames)

    def run_until(self, condition: Callable[[], bool], *ports: Sequence[str], limit: int = 600) -> int:
        """Run frames holding the buttons until ``condition()``; return the frames run."""
        for n in range(limit):
            if condition():
                return n
            self.run(*ports)
        raise AssertionError(f"condition not met within {limit} frames")
