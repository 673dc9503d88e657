"""A game's named RAM fields, as plain data.

A :class:`FieldSpec` is what a data file says of a field: its console address
and type code. It imports nothing native, so the data layer can build specs
without loading the host; :mod:`retrokit.host.memory` reads them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from retrokit.errors import InvalidArgumentError
from retrokit.host.typecodes import FieldType, parse_type


@dataclass(frozen=True)
class FieldSpec:
    """A named RAM field of a game.

    Attributes:
        name: The field's name, e.g. ``"lives"``.
        address: Its console address, e.g. ``0xFF0366``.
        type: Its Gym Retro type code, e.g. ``">u2"``.
        mask: Bits kept after decoding, or ``None`` for all.
    """

    name: str
    address: int
    type: str
    mask: int | None = None
    field_type: FieldType = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "field_type", parse_type(self.type))
        if not isinstance(self.address, int) or self.address < 0:
            raise InvalidArgumentError(
                f"Expected a non-negative integer address for field {self.name!r}, got {self.address!r}."
            )
