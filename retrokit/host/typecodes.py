"""Gym Retro's RAM type codes: parsing, byte order, and decoding.

A code is ``<order><kind><width>``:

- order: ``>`` big-endian, ``<`` little-endian, ``|`` a single byte (or
  don't-care), ``=`` the host's order; the mixed orders ``><`` (big-endian
  words of little-endian bytes), ``<>`` (little-endian words of big-endian
  bytes), ``>=`` and ``<=`` (words in one order, bytes in the host's).
- kind: ``u`` unsigned, ``i`` signed (two's complement), ``d`` BCD (two digits
  a byte), ``n`` low-nibble BCD (one digit a byte, high nibble ignored).
- width: bytes, 1 to 8.

Mixed orders split the value in two halves of ``width // 2`` bytes. BCD
nibbles above 9 wrap modulo 10, as in Gym Retro's reader.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass

from retrokit.errors import FieldTypeError

UNSIGNED, SIGNED, BCD, LOW_BCD = 0, 1, 2, 3
_KINDS = {"u": UNSIGNED, "i": SIGNED, "d": BCD, "n": LOW_BCD}
_ORDERS = ("><", "<>", ">=", "<=", ">", "<", "|", "=")
_CODE = re.compile(r"^(><|<>|>=|<=|>|<|\||=)([uidn])([1-8])$")
_HOST_BIG = sys.byteorder == "big"

# The codes Gym Retro integrations use, and the 3-byte ones a RAM search finds, for did-you-mean suggestions.
COMMON_CODES = (
    "|u1", "|i1", "|d1", "|n1", ">u2", "<u2", ">i2", "<i2", ">d2", "<d2", ">u3", "<u3", ">i3", "<i3", ">d3", "<d3",
    ">u4", "<u4", ">i4", "<i4", ">d4", "<d4", ">n4", "<n4", ">d6", ">n6", ">d8", ">n8", "><u4", "<>u4",
)  # fmt: skip


@dataclass(frozen=True)
class FieldType:
    """A parsed type code.

    Attributes:
        code: The code as written, e.g. ``">u2"``.
        order: The byte-order prefix, e.g. ``">"`` or ``"><"``.
        kind: ``UNSIGNED``, ``SIGNED``, ``BCD`` or ``LOW_BCD``.
        width: The size in bytes.
    """

    code: str
    order: str
    kind: int
    width: int

    def significance(self) -> tuple[int, ...]:
        """Return the field's byte indices from least to most significant."""
        w = self.width
        order = _reduce(self.order)
        if order in ("<", "|"):
            return tuple(range(w))
        if order == ">":
            return tuple(range(w - 1, -1, -1))
        half = w // 2
        if order == "><":  # big-endian words of little-endian bytes: low word last
            return tuple(range(half, w)) + tuple(range(half))
        # "<>": little-endian words of big-endian bytes: low word first
        return tuple(range(half - 1, -1, -1)) + tuple(range(w - 1, half - 1, -1))

    @property
    def signed(self) -> bool:
        """Whether values can be negative."""
        return self.kind == SIGNED

    def value_range(self) -> tuple[int, int]:
        """Return the smallest and largest value the type can hold."""
        if self.kind == UNSIGNED:
            return 0, (1 << (8 * self.width)) - 1
        if self.kind == SIGNED:
            return -(1 << (8 * self.width - 1)), (1 << (8 * self.width - 1)) - 1
        digits = 2 * self.width if self.kind == BCD else self.width
        return 0, 10**digits - 1

    def decode(self, data: bytes) -> int:
        """Decode ``width`` bytes laid out in field order (reference implementation)."""
        value = 0
        for index in reversed(self.significance()):
            b = data[index]
            if self.kind == BCD:
                value = value * 100 + (b & 0xF) % 10 + ((b >> 4) % 10) * 10
            elif self.kind == LOW_BCD:
                value = value * 10 + (b & 0xF) % 10
            else:
                value = (value << 8) | b
        if self.kind == SIGNED and value >= 1 << (8 * self.width - 1):
            value -= 1 << (8 * self.width)
        return value

    def encode(self, value: int) -> bytes:
        """Encode ``value`` as ``width`` bytes in field order.

        Raises:
            InvalidArgumentError: The value does not fit the type.
        """
        from retrokit.errors import InvalidArgumentError

        low, high = self.value_range()
        if not low <= value <= high:
            raise InvalidArgumentError(
                f"Expected a value from {low} to {high} for type {self.code!r}, got {value}."
            )
        out = bytearray(self.width)
        rest = value % (1 << (8 * self.width)) if self.kind == SIGNED else value
        for index in self.significance():
            if self.kind == BCD:
                rest, digits = divmod(rest, 100)
                out[index] = ((digits // 10) << 4) | (digits % 10)
            elif self.kind == LOW_BCD:
                rest, digit = divmod(rest, 10)
                out[index] = digit
            else:
                rest, out[index] = divmod(rest, 256)
        return bytes(out)


def _reduce(order: str) -> str:
    """Resolve the host-relative orders to fixed ones, as Gym Retro does."""
    if order == "=":
        return ">" if _HOST_BIG else "<"
    if order == ">=":
        return ">" if _HOST_BIG else "><"
    if order == "<=":
        return "<>" if _HOST_BIG else "<"
    return order


def parse_type(code: str) -> FieldType:
    """Parse a Gym Retro type code such as ``">u2"`` or ``"<>d4"``.

    Raises:
        FieldTypeError: The code is not a valid type code.
    """
    from retrokit.errors import did_you_mean

    if not isinstance(code, str):
        raise FieldTypeError(f"Expected a type code string such as '>u2', got {code!r} ({type(code).__name__}).")
    match = _CODE.match(code)
    if not match:
        raise FieldTypeError(
            f"Expected a type code: a byte order ({' '.join(_ORDERS)}), a kind (u unsigned, i signed, "
            f"d BCD, n low-nibble BCD) and a width of 1 to 8 bytes, such as '>u2'; got {code!r}."
            + did_you_mean(code, COMMON_CODES)
        )
    order, kind, width = match.group(1), match.group(2), int(match.group(3))
    if len(order) == 2 and width % 2:
        raise FieldTypeError(
            f"Expected an even width for the mixed byte order {order!r}, which splits a value into two words; "
            f"got {code!r}. Use a width of 2, 4, 6 or 8."
        )
    return FieldType(code=code, order=order, kind=_KINDS[kind], width=width)
