"""``reset_ram``: RAM a scenario writes at each reset, drawn from the env's seeded generator.

A game that draws its random sequence from a seed in RAM plays the same
sequence from a state each time: every episode of a benchmark would start
alike. A scenario can write such bytes at every reset::

    reset_ram:
      0x0017: random_u16                        # two bytes, every value alike likely
      0x0048: {type: "<u2", range: [1, 65535]}   # a value of a type, from LO to HI (an LFSR's seed is never 0)

``random_u8``, ``random_u16`` and ``random_u32`` are 1, 2 and 4 random bytes
from the address on (every value alike likely, so their byte order does not
matter). The values come from the env's own generator (``np_random``, seeded
by ``reset(seed=...)``), drawn after its other draws at reset, so one seed
gives the same episodes, and scenarios without ``reset_ram`` draw as before.
They are written after the start state is loaded, before the first frame.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from retrokit.errors import InvalidArgumentError, did_you_mean, shown
from retrokit.host.typecodes import parse_type

MAX_WRITES = 64  # addresses one scenario writes: a seed takes a few
RANDOM = {"random_u8": "|u1", "random_u16": "<u2", "random_u32": "<u4"}
_FORMS = f"{', '.join(RANDOM)}, or {{type: \"<u2\", range: [LO, HI]}}"


def draw_of(value: object) -> tuple[str, int, int]:
    """What one ``reset_ram`` entry draws: ``(type code, lowest, highest)``.

    Raises:
        InvalidArgumentError: It is none of :data:`RANDOM`'s names nor ``{type, range}`` of a type that holds it.
    """
    if isinstance(value, str):
        if value not in RANDOM:
            raise InvalidArgumentError(f"expected {_FORMS}; got {value!r}." + did_you_mean(value, RANDOM))
        low, high = parse_type(RANDOM[value]).value_range()
        return RANDOM[value], low, high
    if not isinstance(value, Mapping) or set(value) != {"type", "range"}:
        raise InvalidArgumentError(f"expected {_FORMS}; got {shown(value)}")
    try:
        ftype = parse_type(value["type"])
    except InvalidArgumentError as exc:
        raise InvalidArgumentError(f"expected a type code in reset_ram: {exc}") from None
    bounds = value["range"]
    if not (isinstance(bounds, list) and len(bounds) == 2 and all(isinstance(b, int) and not isinstance(b, bool) for b in bounds)):
        raise InvalidArgumentError(f"expected range: [LO, HI], two whole numbers; got {shown(bounds)}")
    low, high = ftype.value_range()
    if not low <= bounds[0] <= bounds[1] <= high:
        raise InvalidArgumentError(
            f"expected a range LO <= HI within {low} to {high}, what {ftype.code} holds; got {bounds}"
        )
    return ftype.code, bounds[0], bounds[1]


def check_writes(writes: Mapping[int, tuple[str, int, int]], space: Any) -> None:
    """Check every write lands in the console's RAM (``space``: the emulator's address space).

    Raises:
        InvalidArgumentError: An address (with its type's width) is outside RAM.
    """
    for address, (code, _, _) in writes.items():
        try:
            space.offsets(address, parse_type(code).width)
        except Exception as exc:  # noqa: BLE001 - the space's own error, named with the scenario's entry
            raise InvalidArgumentError(
                f"Expected reset_ram's addresses inside the console's RAM; 0x{address:X} ({code}) is not: {exc}"
            ) from None


def apply_writes(writes: Mapping[int, tuple[str, int, int]], space: Any, rng: Any) -> None:
    """Draw each value from ``rng`` (a numpy Generator), in the scenario's order, and write it."""
    for address, (code, low, high) in writes.items():
        space.poke(address, int(rng.integers(low, high, endpoint=True)), code)
