"""Fill the checksum and its complement in a LoROM SNES image's internal header.

Usage: python3 fixheader.py build/rom.bin build/rom.sfc

The header sits at file offset 0x7FC0 (CPU $00:FFC0). The checksum (0x7FDE,
little-endian) is the 16-bit sum of every byte of the ROM, and the complement
(0x7FDC) is its bitwise inverse; the sum is taken with the complement at 0xFFFF
and the checksum at 0, whose four bytes add up to what any final pair adds up
to (0x1FE), so writing them keeps the sum right. snes9x and emulators' header
scoring check both.
"""

from __future__ import annotations

import sys
from pathlib import Path

HEADER = 0x7FC0
SIZE = 0x8000  # one 32 KiB bank, the header's ROM size byte 0x05 (2**5 KiB)


def main() -> None:
    data = bytearray(Path(sys.argv[1]).read_bytes())
    if len(data) != SIZE:
        raise SystemExit(f"fixheader.py: expected a {SIZE}-byte image, got {len(data)} bytes: check snes.cfg")
    if data[HEADER + 0x15] != 0x20:
        raise SystemExit("fixheader.py: expected map mode 0x20 (LoROM) at 0x7FD5: check the HEADER segment")
    data[HEADER + 0x1C : HEADER + 0x20] = b"\xff\xff\x00\x00"
    checksum = sum(data) & 0xFFFF
    data[HEADER + 0x1C : HEADER + 0x1E] = (checksum ^ 0xFFFF).to_bytes(2, "little")
    data[HEADER + 0x1E : HEADER + 0x20] = checksum.to_bytes(2, "little")
    Path(sys.argv[2]).write_bytes(data)


if __name__ == "__main__":
    main()
