"""Fill a Game Boy ROM's header checksum and global checksum (Pan Docs, "The Cartridge Header").

    python fixrom.py IN OUT

IN is makebin's image: 32 KiB, the header written by boot/crt0.s with both checksums 0.
The header checksum (0x14D) covers 0x134-0x14C, as the boot ROM computes it before it
starts the cartridge; the global checksum (0x14E-0x14F, big-endian) is the sum of every
other byte of the ROM, which no console checks but emulators report.
"""

from __future__ import annotations

import sys
from pathlib import Path

SIZE = 32 * 1024
LOGO_START, LOGO_END = 0x104, 0x134


def fix(rom: bytearray) -> bytearray:
    """Return ``rom`` with both checksums filled in."""
    if len(rom) != SIZE:
        raise SystemExit(f"expected a {SIZE}-byte image from makebin, got {len(rom)} bytes")
    if rom[0x147] != 0 or rom[0x148] != 0:
        raise SystemExit("expected a 32 KiB ROM-only header (0x147 = 0x148 = 0), as boot/crt0.s writes")
    if not any(rom[LOGO_START:LOGO_END]):
        raise SystemExit("expected the Nintendo logo at 0x104-0x133: the header area is empty")
    check = 0
    for byte in rom[0x134:0x14D]:
        check = (check - byte - 1) & 0xFF
    rom[0x14D] = check
    rom[0x14E] = rom[0x14F] = 0
    total = sum(rom) & 0xFFFF
    rom[0x14E], rom[0x14F] = total >> 8, total & 0xFF
    return rom


def main() -> None:
    source, target = sys.argv[1:3]
    Path(target).write_bytes(fix(bytearray(Path(source).read_bytes())))


if __name__ == "__main__":
    main()
