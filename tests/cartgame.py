"""An emulator running one of our cartridges, with its game.yaml fields by name (tests/test_cartridge.py, test_pcecart.py)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import yaml

from retrokit.host.emulator import Emulator


def game_fields(game_dir: Path) -> dict[str, tuple[int, str]]:
    """The fields of a game folder's game.yaml: name -> (console address, type code)."""
    doc = yaml.safe_load((game_dir / "game.yaml").read_text())
    return {name: (int(f["address"]), f["type"]) for name, f in doc["fields"].items()}


class CartGame:
    """An emulator of a cartridge, whose fields read and write as ``game["name"]``."""

    def __init__(self, emu: Emulator, fields: Mapping[str, tuple[int, str]]) -> None:
        self.emu, self.fields = emu, fields
        self.mask = emu.system.mask

    def __getitem__(self, name: str) -> int:
        address, code = self.fields[name]
        return self.emu.peek(address, code)

    def __setitem__(self, name: str, value: int) -> None:
        address, code = self.fields[name]
        self.emu.poke(address, value, code)

    def run(self, p1: Sequence[str] = (), p2: Sequence[str] = (), frames: int = 1) -> None:
        """Run frames holding buttons on pad 1 and pad 2."""
        self.emu.run([self.mask(list(p1)), self.mask(list(p2))], frames)

    def run_until(
        self, condition: Callable[[], bool], p1: Sequence[str] = (), p2: Sequence[str] = (), limit: int = 600
    ) -> int:
        """Run frames holding the buttons until ``condition()``; return the frames run."""
        for n in range(limit):
            if condition():
                return n
            self.run(p1, p2)
        raise AssertionError(f"condition not met within {limit} frames")
