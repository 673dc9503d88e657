"""Playing one of our cartridges frame by frame in a test: its game.yaml fields by name, buttons by name per port."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import yaml

from retrokit.host.emulator import Emulator


def game_fields(game_dir: Path) -> dict[str, tuple[int, str]]:
    """``{name: (address, type code)}`` of the fields in ``game_dir``/game.yaml."""
    doc = yaml.safe_load((game_dir / "game.yaml").read_text())
    return {name: (int(f["address"]), f["type"]) for name, f in doc["fields"].items()}


class CartridgePlay:
    """An emulator running a cartridge, with its fields readable and writable as ``play["name"]``."""

    def __init__(self, emu: Emulator, fields: dict[str, tuple[int, str]]) -> None:
        self.emu = emu
        self.fields = fields
        self.mask = emu.system.mask

    def __getitem__(self, name: str) -> int:
        address, code = self.fields[name]
        return self.emu.peek(address, code)

    def __setitem__(self, name: str, value: int) -> None:
        address, code = self.fields[name]
        self.emu.poke(address, value, code)

    def run(self, p1: Sequence[str] = (), p2: Sequence[str] = (), frames: int = 1) -> None:
        """Run ``frames`` frames holding the named buttons on ports 1 and 2."""
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
