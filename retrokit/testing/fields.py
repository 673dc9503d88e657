"""Checking a game's RAM fields: inside the system's memory, usual type codes, no overlaps.

Type codes are parsed when the data file is read, so a game whose codes are
not valid fails the schema check before it gets here. What is left: every
field's bytes lie inside the memory the core maps (or, without the ROM, the
RAM a state holds), a code the system's integrations do not usually use gets
a warning, and so do two fields sharing bytes (sometimes meant, as a byte
inside a word, but often a typo in an address).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from retrokit.data.games import Game
from retrokit.host.fields import FieldSpec
from retrokit.host.systems import get_system
from retrokit.testing.report import FAIL, PASS, SKIP, WARN, GameReport

if TYPE_CHECKING:
    from retrokit.host.memory import AddressSpace

__all__ = ["check_fields", "overlaps"]


def check_fields(game: Game, report: GameReport, space: AddressSpace | None, where: str = "") -> None:
    """Check the game's fields; add the results to ``report``.

    Args:
        game: The game.
        report: Where results go.
        space: The :class:`~retrokit.host.memory.AddressSpace` the fields live in, or ``None`` if unknown.
        where: What ``space`` is, for messages (e.g. "the core's memory map").
    """
    fields = game.fields
    if not fields:
        report.add("fields", WARN, "the game has no RAM fields: scenarios and info have nothing to read")
        return
    if space is None:
        report.add("fields in RAM", SKIP, "the extent of the system's RAM is not known without the ROM or a state")
    else:
        outside = [_outside(spec, space) for spec in fields.values()]
        outside = [o for o in outside if o]
        if outside:
            for message in outside:
                report.add("fields in RAM", FAIL, message)
        else:
            report.add("fields in RAM", PASS, f"all {len(fields)} fields lie inside {where or 'the mapped memory'}")
    usual = get_system(game.system).types
    unusual = sorted({f.type for f in fields.values()} - set(usual)) if usual else []
    if unusual:
        names = [f.name for f in fields.values() if f.type in unusual]
        report.add("type codes", WARN, f"valid, but not among {game.system.name}'s usual codes: {', '.join(unusual)} "
                   f"(fields {', '.join(names)}); check the byte order and width")
    else:
        report.add("type codes", PASS, f"{len(fields)} fields with valid type codes")
    groups = overlaps(fields)
    for group in groups:
        shown = [_span(spec) for spec in group[:MAX_NAMED]]
        more = f" and {len(group) - MAX_NAMED} more fields" if len(group) > MAX_NAMED else ""
        names = f"{', '.join(shown[:-1])} and {shown[-1]}" if not more else f"{', '.join(shown)}{more}"
        report.add("field overlap", WARN, f"{names} share bytes; if not meant, fix an address")
    if not groups:
        report.add("field overlap", PASS, "no two fields share a byte")


#: The most fields one overlap warning names; the rest are counted.
MAX_NAMED = 8


def overlaps(fields: Mapping[str, FieldSpec]) -> list[list[FieldSpec]]:
    """Return the groups of fields whose bytes overlap, in address order.

    A group is a run of fields, sorted by address, each starting before an
    earlier one of the run ends: one sweep, so that many fields at one address
    cost one group, not a pair for every two of them.
    """
    specs = sorted(fields.values(), key=lambda f: (f.address, f.name))
    groups: list[list[FieldSpec]] = []
    run: list[FieldSpec] = []
    end = -1
    for spec in specs:
        stop = spec.address + spec.field_type.width
        if run and spec.address < end:
            run.append(spec)
            end = max(end, stop)
        else:
            if len(run) > 1:
                groups.append(run)
            run, end = [spec], stop
    if len(run) > 1:
        groups.append(run)
    return groups


def _span(spec: FieldSpec) -> str:
    width = spec.field_type.width
    last = spec.address + width - 1
    return f"{spec.name} ({spec.address:#x}" + (f"-{last:#x})" if width > 1 else ")")


def _outside(spec: FieldSpec, space: AddressSpace) -> str:
    if not space.holds(spec.address, spec.field_type.width):
        mapped = ", ".join(f"{r.start:#x}-{r.start + r.length - 1:#x}" for r in space.regions)
        return (f"expected field {spec.name!r} ({spec.type} at {spec.address:#x}) inside the system's memory "
                f"({mapped}); found it outside. Fix its address in the data file: it is a console address.")
    return ""
