"""Turn Skipper's text art (src/art.txt) into SNES tile data, as a ca65 include file.

Usage: python3 mkart.py src/art.txt build/art.inc

Writes two labelled blocks of ``.byte`` rows:

- ``bg_tiles``: 128 background tiles of 16 bytes (2 bits a pixel, the SNES's
  interleaved bit planes: for each row, plane 0 then plane 1), for VRAM word 0;
- ``sprite_tiles``: 32 sprite tiles of 32 bytes (4 bits a pixel: the rows'
  planes 0/1, then the rows' planes 2/3), two rows of 16 tiles, for the sprite
  name base.

The output depends only on the art, so the ROM builds byte for byte.
"""

from __future__ import annotations

import sys
from pathlib import Path

BG_TILES = 128
SPRITE_TILES = 32


def planes(rows: list[list[int]], count: int) -> bytes:
    """The bit planes of an 8x8 tile of colour indexes, ``count`` planes, as the SNES stores them."""
    out = bytearray()
    for pair in range(0, count, 2):
        for row in rows:
            for plane in (pair, pair + 1):
                out.append(sum(((c >> plane) & 1) << (7 - i) for i, c in enumerate(row)))
    return bytes(out)


def pixels(line: str) -> list[int]:
    return [0 if ch == "." else int(ch) for ch in line]


def parse(text: str) -> tuple[bytearray, bytearray]:
    bg = bytearray(16 * BG_TILES)
    spr = bytearray(32 * SPRITE_TILES)
    lines = []
    for ln in text.splitlines():
        if not ln.strip() or ln.startswith("# ") or ln == "#":
            continue  # blank lines and comments ("# ..."; art rows never have a space after '#')
        if ln.startswith(("bg ", "glyph ", "sprite ")):
            ln = ln.split(" #", 1)[0]  # a header's trailing comment
        lines.append(ln.rstrip())
    i = 0
    while i < len(lines):
        kind, _, name = lines[i].partition(" ")
        name = name.split()[0]
        if kind == "bg":
            rows = [pixels(ln) for ln in lines[i + 1 : i + 9]]
            n = int(name)
            bg[16 * n : 16 * n + 16] = planes(rows, 2)
            i += 9
        elif kind == "glyph":
            rows = [[1 if ch == "#" else 0 for ch in ln] + [0, 0, 0] for ln in lines[i + 1 : i + 8]] + [[0] * 8]
            n = ord(name)
            bg[16 * n : 16 * n + 16] = planes(rows, 2)
            i += 8
        elif kind == "sprite":
            rows = [pixels(ln) for ln in lines[i + 1 : i + 17]]
            n = int(name)
            for k, (dy, dx) in enumerate(((0, 0), (0, 8), (8, 0), (8, 8))):
                tile = n + (k & 1) + 16 * (k >> 1)
                spr[32 * tile : 32 * tile + 32] = planes([r[dx : dx + 8] for r in rows[dy : dy + 8]], 4)
            i += 17
        else:
            raise SystemExit(f"art.txt: expected 'bg N', 'glyph C' or 'sprite N', got {lines[i]!r}")
    return bg, spr


def emit(label: str, data: bytes) -> str:
    rows = [f"{label}:"]
    for k in range(0, len(data), 16):
        rows.append("  .byte " + ",".join(f"${b:02X}" for b in data[k : k + 16]))
    return "\n".join(rows) + "\n"


def main() -> None:
    bg, spr = parse(Path(sys.argv[1]).read_text())
    text = "; Made by mkart.py from src/art.txt: do not edit.\n" + emit("bg_tiles", bg) + emit("sprite_tiles", spr)
    Path(sys.argv[2]).write_text(text)


if __name__ == "__main__":
    main()
