#!/usr/bin/env python3
"""Finish a linked Master System / Game Gear ROM image: pad it and write the `TMR SEGA` header.

Usage: fixheader.py IN.bin OUT.rom sms|gg

- Pads the image with 0xFF to 32 KiB (refusing an image that reaches the header).
- Writes the header at 0x7FF0: ``TMR SEGA``, two reserved bytes (0), the
  checksum (little-endian, at 0x7FFA), product code 0 and version 0
  (0x7FFC-0x7FFE), and at 0x7FFF the region code in the high nibble (4 Master
  System export, 6 Game Gear export) and the size code 0xC (32 KiB, which
  also says the checksum covers 0x0000-0x7FEF) in the low nibble.
- The checksum is the 16-bit sum of the bytes 0x0000-0x7FEF, as the export
  Master System's BIOS computes it.

Standard library only; the output depends on nothing but the input bytes.
"""

from __future__ import annotations

import struct
import sys
from pathlib import Path

SIZE = 0x8000
HEADER = 0x7FF0
REGIONS = {"sms": 0x4, "gg": 0x6}
SIZE_32K = 0xC


def checksum(rom: bytes) -> int:
    return sum(rom[:HEADER]) & 0xFFFF


def fix(image: bytes, console: str) -> bytes:
    if len(image) > SIZE or any(b != 0xFF for b in image[HEADER:SIZE]):
        raise SystemExit(f"the image ({len(image)} bytes) runs into the header at {HEADER:#06x}: make the game smaller")
    rom = bytearray(image + b"\xff" * (SIZE - len(image)))
    rom[HEADER : HEADER + 8] = b"TMR SEGA"
    rom[HEADER + 8 : HEADER + 10] = b"\x00\x00"
    struct.pack_into("<H", rom, HEADER + 10, checksum(bytes(rom)))
    rom[HEADER + 12 : HEADER + 15] = b"\x00\x00\x00"
    rom[HEADER + 15] = REGIONS[console] << 4 | SIZE_32K
    return bytes(rom)


def main(argv: list[str]) -> int:
    if len(argv) != 4 or argv[3] not in REGIONS:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    source, target, console = argv[1:]
    rom = fix(Path(source).read_bytes(), console)
    Path(target).write_bytes(rom)
    print(f"{target}: {len(rom)} bytes, checksum {checksum(rom):04X}, region {REGIONS[console]:X}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
