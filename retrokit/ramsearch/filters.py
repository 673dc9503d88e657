"""Filters: what a RAM search compares each candidate with, and how.

Filters follow BizHawk's RAM Search: compare each candidate's value in the
newest snapshot with a number, with its value in the previous or the first
snapshot or any earlier one (by its number, from 0 in the order taken), or
with the value at another address, by ``equal``,
``not-equal``, ``less``, ``greater``, ``less-equal``, ``greater-equal``,
``changed-by N``, ``increased``, ``decreased``, ``changed`` or
``unchanged``; or compare its change count (snapshots at which its value
differed from the one before) with a number. :func:`check_filter` checks the
parts fit together; :mod:`retrokit.ramsearch.engine` runs them.
"""

from __future__ import annotations

import numbers
import operator
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from retrokit.errors import InvalidArgumentError, did_you_mean, shown

if TYPE_CHECKING:  # `retrokit ramsearch --help` names the operations: it must not import numpy for them
    import numpy as np

    from retrokit.ramsearch.ram import RamLayout

COMPARISONS: dict[str, Callable[[np.ndarray, object], np.ndarray]] = {
    "equal": operator.eq,
    "not-equal": operator.ne,
    "less": operator.lt,
    "greater": operator.gt,
    "less-equal": operator.le,
    "greater-equal": operator.ge,
}
#: The operations that compare with a snapshot, and the comparison each is.
CHANGES = {"increased": "greater", "decreased": "less", "changed": "not-equal", "unchanged": "equal"}
OPS = (*COMPARISONS, "changed-by", *CHANGES)
REFERENCES = ("previous", "first", "changes")
#: Every form ``--than`` takes, as the messages and ``--help`` name them.
THAN_FORMS = (
    "previous (the snapshot before the newest: the default), first (snapshot 0), N (snapshot N, numbered from 0 "
    "in the order taken: `ramsearch history` lists them), 0xADDRESS (the value at that console address, in hex), "
    "or changes (with a number: how many times the value changed)"
)


@dataclass(frozen=True)
class Filter:
    """One filter: an operation, an optional number, and what to compare with.

    Attributes:
        op: One of :data:`OPS`.
        value: The number compared with (for ``changed-by``, the difference).
        than: ``"previous"``, ``"first"``, ``"changes"``, a snapshot's number as a
            string of digits (``"2"``), or a console address (an ``int``);
            ``None`` with a number means the number itself.
    """

    op: str
    value: int | None = None
    than: str | int | None = None

    @property
    def snapshot(self) -> int | None:
        """The snapshot number ``than`` names, if it names one by number."""
        return int(self.than) if isinstance(self.than, str) and self.than.isdigit() else None

    def reference_snapshot(self, count: int) -> int | None:
        """The index of the snapshot compared with, of ``count`` (``None``: not a snapshot)."""
        if self.than == "previous":
            return count - 2
        if self.than == "first":
            return 0
        return self.snapshot

    def describe(self, layout: RamLayout | None = None) -> str:
        """The filter as the command line writes it."""
        words = [self.op] + ([] if self.value is None else [str(self.value)])
        if self.than is not None:
            than = (
                (layout.format(self.than) if layout is not None else hex(self.than))
                if isinstance(self.than, int)
                else self.than
            )
            words.append(f"--than {than}")
        return " ".join(words)


def _is_int(value: object) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)  # numpy's integers are Integral


def check_filter(op: str, value: int | None = None, than: str | int | None = None) -> Filter:
    """Check a filter's parts fit together and fill in the default reference.

    Raises:
        InvalidArgumentError: Unknown operation or reference, or a missing or extra number.
    """
    for what, number in (("number", value), ("address", than)):
        if number is not None and not isinstance(number, str) and not _is_int(number):
            raise InvalidArgumentError(f"Expected a whole number as the filter's {what}, got {number!r}.")
    value = None if value is None else int(value)  # numpy integers become plain ones
    than = int(than) if _is_int(than) else than
    for what, number in (("number", value), ("address", than)):
        # RAM holds at most 8-byte values at 64-bit addresses; a longer number cannot even be printed (Python
        # refuses to turn more than 4,300 digits into text), so it is refused by its size, before any message.
        if isinstance(number, int) and number.bit_length() > 64:
            raise InvalidArgumentError(
                f"Expected the filter's {what} to fit in 64 bits; got a number of {number.bit_length()} bits."
            )
    if isinstance(than, str) and than.isdigit():
        if len(than.lstrip("0")) > 20:
            raise InvalidArgumentError(
                f"Expected --than N to be a snapshot's number (retrokit ramsearch history lists them); got a number "
                f"of {len(than)} digits."
            )
        than = str(int(than))  # "007" is snapshot 7
    if op not in OPS:
        raise InvalidArgumentError(
            f"Expected a filter operation ({', '.join(OPS)}), got {op!r}." + did_you_mean(op, OPS)
        )
    if isinstance(than, str) and than not in REFERENCES and not than.isdigit():
        raise InvalidArgumentError(f"Expected --than {THAN_FORMS}; got {shown(than)}." + did_you_mean(than, REFERENCES))
    if op in CHANGES:
        if value is not None:
            raise InvalidArgumentError(
                f"Expected no number after {op!r}, got {value}. For a difference, use: changed-by N."
            )
        if than == "changes":
            raise InvalidArgumentError(f"Expected --than previous, first, N or an address for {op!r}, got 'changes'.")
        return Filter(op, None, "previous" if than is None else than)
    if op == "changed-by":
        if value is None:
            raise InvalidArgumentError("Expected a number after 'changed-by' (the difference, e.g. -1), got none.")
        if than == "changes":
            raise InvalidArgumentError(
                "Expected --than previous, first, N or an address for 'changed-by', got 'changes'."
            )
        return Filter(op, value, "previous" if than is None else than)
    if value is None:
        if than == "changes":
            raise InvalidArgumentError(f"Expected a number to compare change counts with: {op} N --than changes.")
        return Filter(op, None, "previous" if than is None else than)
    if than is not None and than != "changes":
        raise InvalidArgumentError(
            f"Expected a number or --than {than}, not both: '{op} {value}' compares with the number, "
            f"'{op} --than {than}' with the snapshot. For a difference, use: changed-by {value} --than {than}."
        )
    return Filter(op, value, than)
