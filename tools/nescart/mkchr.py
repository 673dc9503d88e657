"""Turn Hopper's text-art tiles (src/art.txt) into the 8 KiB CHR ROM.

    python mkchr.py src/art.txt build/chr.bin

A NES tile is 16 bytes: eight bytes of each pixel's low colour bit, then eight
of its high bit, the leftmost pixel in bit 7. Unlisted tiles stay blank.
"""

from __future__ import annotations

import sys
from pathlib import Path

TILES = 512  # two pattern tables; Hopper uses the first for both planes


def _encode(rows: list[str]) -> bytes:
    low, high = bytearray(8), bytearray(8)
    for y, row in enumerate(rows):
        for x, char in enumerate(row):
            colour = 0 if char == "." else int(char)
            low[y] |= (colour & 1) << (7 - x)
            high[y] |= (colour >> 1) << (7 - x)
    return bytes(low + high)


def parse(text: str) -> dict[int, bytes]:
    """Map tile numbers to their 16 bytes, from art.txt's tiles and glyphs."""
    tiles: dict[int, bytes] = {}
    lines = [line.rstrip() for line in text.splitlines() if line.strip() and not line.startswith("#")]
    i = 0
    while i < len(lines):
        words = lines[i].split()
        if words[0] == "tile":
            index, rows, i = int(words[1], 0), lines[i + 1 : i + 9], i + 9
        elif words[0] == "glyph":
            # 5x7 characters, one column in from the left, on the top seven rows.
            index = ord(words[1])
            rows = ["." + row + ".." for row in lines[i + 1 : i + 8]] + ["........"]
            i += 8
        else:
            raise SystemExit(f"art.txt: expected 'tile' or 'glyph', got {lines[i]!r}")
        if len(rows) != 8 or any(len(r) != 8 or set(r) - set(".123") for r in rows):
            raise SystemExit(f"art.txt: tile {index:#x} is not 8 rows of 8 of '.123'")
        if index in tiles:
            raise SystemExit(f"art.txt: tile {index:#x} drawn twice")
        tiles[index] = _encode(rows)
    return tiles


def main() -> None:
    source, target = sys.argv[1:3]
    tiles = parse(Path(source).read_text())
    chr_rom = b"".join(tiles.get(n, bytes(16)) for n in range(TILES))
    Path(target).write_bytes(chr_rom)


if __name__ == "__main__":
    main()
