"""A game's named RAM fields, as plain data.

A :class:`FieldSpec` is what a data file says of a field: its console address
and type code. It imports nothing native, so the data layer can build specs
without loading the host; :mod:`retrokit.host.memory` reads them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
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
        range: ``(lo, hi)``, the values the field takes in play, or ``None``: a state
            holding a value outside it is another game's, or broken (see :func:`out_of_range`).
    """

    name: str
    address: int
    type: str
    mask: int | None = None
    range: tuple[int, int] | None = None
    field_type: FieldType = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "field_type", parse_type(self.type))
        if not isinstance(self.address, int) or self.address < 0:
            raise InvalidArgumentError(
                f"Expected a non-negative integer address for field {self.name!r}, got {self.address!r}."
            )
        if self.range is not None:
            low, high = self.range
            least, most = self.field_type.value_range()
            if not least <= low <= high <= most:
                raise InvalidArgumentError(
                    f"Expected the range of field {self.name!r} as [lo, hi] with lo <= hi, within what its type "
                    f"{self.type} holds ({least} to {most}); got [{low}, {high}]. Fix the range."
                )


def ranged(specs: Iterable[FieldSpec]) -> list[FieldSpec]:
    """The fields that declare a range."""
    return [spec for spec in specs if spec.range is not None]


def out_of_range(specs: Iterable[FieldSpec], values: Mapping[str, int]) -> list[str]:
    """Describe each field whose value is outside its declared range: ``"lives=26 (range 0 to 9)"``.

    A field without a range, or without a value in ``values``, is never out of it.
    """
    wrong = []
    for spec in specs:
        if spec.range is not None and spec.name in values and not spec.range[0] <= values[spec.name] <= spec.range[1]:
            wrong.append(f"{spec.name}={values[spec.name]} (range {spec.range[0]} to {spec.range[1]})")
    return wrong
