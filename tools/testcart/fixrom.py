#!/usr/bin/env python3
"""Finish a linked Genesis ROM image: pad it, then fill in the header.

Usage: fixrom.py IN.bin OUT.md

- Pads the image with 0xFF to a power of two of at least 64 KiB (cartridge
  ROM sizes are powers of two).
- Writes the ROM end address (size - 1) at 0x1A4, big-endian.
- Writes the checksum at 0x18E: the 16-bit sum of all big-endian words from
  0x200 to the end, as the console's BIOS-era games check it.

Standard library only; the output depends on nothing but the input bytes.
"""

from __future__ import annotations

import struct
import sys

HEADER_SYSTEM = 0x100
CHECKSUM = 0x18E
ROM_END = 0x1A4
MIN_SIZE = 0x10000


def checksum(rom: bytes) -> int:
    words = struct.unpack(f">{(len(rom) - 0x200) // 2}H", rom[0x200:])
    return sum(words) & 0xFFFF


def fix(image: bytes) -> bytes:
    if image[HEADER_SYSTEM:HEADER_SYSTEM + 4] != b"SEGA":
        raise SystemExit(f"no 'SEGA' system string at 0x100: {image[0x100:0x110]!r}")
    size = MIN_SIZE
    while size < len(image):
        size *= 2
    rom = bytearray(image + b"\xff" * (size - len(image)))
    struct.pack_into(">I", rom, ROM_END, size - 1)
    struct.pack_into(">H", rom, CHECKSUM, checksum(bytes(rom)))
    return bytes(rom)


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    with open(argv[1], "rb") as f:
        rom = fix(f.read())
    with open(argv[2], "wb") as f:
        f.write(rom)
    print(f"{argv[2]}: {len(rom)} bytes, checksum {checksum(rom):04X}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
