"""Making Super Magic Drive (``.smd``) dumps of plain ROMs, for the tests of importing them."""

from __future__ import annotations

SMD_BLOCK_SIZE = 16 * 1024


def interleave_smd(data: bytes, header: bytes | None = None) -> bytes:
    """Convert a plain ``.md`` ROM to the ``.smd`` form, the inverse of ``roms.deinterleave_smd``.

    Args:
        data: The ROM; its size should be a multiple of 16 KiB.
        header: The 512-byte SMD header; a minimal one by default.
    """
    if header is None:
        header = bytes([len(data) // SMD_BLOCK_SIZE & 0xFF, 3]) + bytes(6) + b"\xaa\xbb\x06" + bytes(501)
    out = bytearray()
    for start in range(0, len(data), SMD_BLOCK_SIZE):
        block = data[start : start + SMD_BLOCK_SIZE]
        out += block[1::2] + block[0::2]
    return bytes(header) + bytes(out)
