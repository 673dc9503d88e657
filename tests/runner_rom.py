"""Runner: a copy of Dasher's ROM whose header names say RUNNER, so that no known game's SHA-1 matches it.

The game that issue 21 integrated from scratch, and that docs/integrate.md's
walkthrough ("Your own game, from a ROM") integrates again.
"""

from __future__ import annotations

from pathlib import Path

from retrokit.paths import repo_games_dir

DASHER_ROM = repo_games_dir() / "Dasher-Genesis" / "rom.md"
NAME_OFFSETS = (0x120, 0x150)  # the Genesis header's domestic and overseas names, 48 bytes each


def write_runner_rom(path: Path) -> Path:
    """Write the header-patched Dasher to ``path`` (a .bin, as dumps often are); return ``path``."""
    rom = bytearray(DASHER_ROM.read_bytes())
    for offset in NAME_OFFSETS:
        at = rom.index(b"DASHER", offset, offset + 48)
        rom[at : at + 6] = b"RUNNER"
    path.write_bytes(bytes(rom))
    return path
