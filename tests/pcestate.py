"""Mednafen's save states (pce_fast's), taken apart for tests: sections, variables, and forged ones added.

A state is a 32-byte header, then sections (a 32-byte NUL-padded name, a
little-endian 32-bit size, then that many bytes of variables), each variable
a length byte, its name, a 32-bit size and its bytes. The core reads a
section's variables by name, prints every name it does not know on stdout
(``Unknown variable in save state: <name>``), byte for byte, and skips its bytes.
"""

from __future__ import annotations

import struct

HEADER = 32


def _sections(state: bytes) -> dict[bytes, tuple[int, int]]:
    """Each section's name, to where its variables start and its size."""
    found, at = {}, HEADER
    while at + 36 <= len(state):
        (size,) = struct.unpack_from("<I", state, at + 32)
        found[state[at : at + 32].rstrip(b"\0")] = (at + 36, size)
        at += 36 + size
    return found


def _variable(state: bytes, section: bytes, name: bytes) -> tuple[int, int]:
    """Where the variable ``name`` of ``section`` starts (its length byte) and where its bytes start."""
    start, size = _sections(state)[section]
    at = start
    while at < start + size:
        length = state[at]
        (var_size,) = struct.unpack_from("<I", state, at + 1 + length)
        data = at + 1 + length + 4
        if state[at + 1 : at + 1 + length] == name:
            return at, data
        at = data + var_size
    raise KeyError(name)


def with_variable(state: bytes, section: bytes, name: bytes, value: bytes) -> bytes:
    """``state`` with the variable ``name`` of ``section`` set to ``value`` (its first bytes)."""
    _, data = _variable(state, section, name)
    return state[:data] + value + state[data + len(value) :]


def renamed(state: bytes, section: bytes, name: bytes, names: list[bytes]) -> bytes:
    """``state`` with the variable ``name`` of ``section`` replaced by variables of these names (at most 255 bytes
    each), the last holding what is left of its bytes: the state keeps its size, and the core skips them all."""
    at, data = _variable(state, section, name)
    end = data + struct.unpack_from("<I", state, data - 4)[0]
    heads = [bytes([len(n)]) + n for n in names]
    room = end - at - sum(len(h) + 4 for h in heads)
    assert room >= 0, "the variable is too small to hold those names"
    body = b"".join(h + struct.pack("<I", 0) for h in heads[:-1]) + heads[-1] + struct.pack("<I", room)
    return state[:at] + body + state[at + len(body) : end] + state[end:]
