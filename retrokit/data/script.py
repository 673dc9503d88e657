"""Input scripts: taps, holds and waits in one line, as ``ramsearch run --script`` and state recipes take them.

A script is steps separated by spaces; each step holds some buttons for some
frames, then the next step begins::

    START*1 _*60 RIGHT*30 RIGHT+B*2

- ``BUTTONS*FRAMES`` holds ``BUTTONS`` for ``FRAMES`` frames; ``BUTTONS`` alone is one frame (a tap).
- ``BUTTONS`` is button names joined by ``+`` (``RIGHT+B``), as the system names them; ``2:START``
  is a button of port 2. ``_`` is no button: ``_*60`` waits 60 frames.

A mistake is reported with the step and the column it starts at, and a
misspelt button with the closest name.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from retrokit.errors import InvalidArgumentError, RetrokitError, shown

if TYPE_CHECKING:
    from retrokit.host.systems import System

MAX_FRAMES = 1_000_000  # about 4.6 hours of play, as a state recipe's budget: more is a typo
MAX_SCRIPT = 100_000  # characters
WAIT = "_"
SYNTAX = "steps like START*1 _*60 RIGHT*30 RIGHT+B*2 (BUTTONS*FRAMES; _ is no button; a step alone is one frame)"
_STEP = re.compile(r"\S+")


@dataclass(frozen=True)
class Step:
    """One step of a script.

    Attributes:
        buttons: The button names held (``"2:START"`` for port 2); none for a wait.
        frames: How many frames they are held.
    """

    buttons: tuple[str, ...]
    frames: int

    def describe(self) -> str:
        """The step as a script writes it."""
        return f"{'+'.join(self.buttons) or WAIT}*{self.frames}"


def parse_script(text: str, check_buttons: Callable[[Sequence[str]], object] | None = None) -> list[Step]:
    """Parse a script into its steps.

    Args:
        text: The script.
        check_buttons: Called with each step's buttons; raises (with a did-you-mean) for an unknown one.

    Raises:
        InvalidArgumentError: The script is empty, too long, or a step is malformed or names an unknown button.
    """
    if not isinstance(text, str) or len(text) > MAX_SCRIPT:
        raise InvalidArgumentError(
            f"Expected a script of at most {MAX_SCRIPT:,} characters: {SYNTAX}; got {shown(text)}."
        )
    steps: list[Step] = []
    total = 0
    for number, match in enumerate(_STEP.finditer(text), 1):
        where = f"step {number} ({match.group()[:40]!r}, column {match.start() + 1})"
        step = _parse_step(match.group(), where)
        if check_buttons is not None and step.buttons:
            try:
                check_buttons(step.buttons)
            except RetrokitError as exc:
                raise InvalidArgumentError(f"In the script's {where}: {exc}") from None
        total += step.frames
        if total > MAX_FRAMES:
            raise InvalidArgumentError(
                f"Expected a script of at most {MAX_FRAMES:,} frames; {where} brings it to {total:,}."
            )
        steps.append(step)
    if not steps:
        raise InvalidArgumentError(f"Expected a script of {SYNTAX}; got an empty one.")
    return steps


def port_masks(system: System, ports: int, names: Sequence[str]) -> list[int]:
    """The button mask of each of ``ports`` ports for names like ``RIGHT`` (port 1) or ``2:START``.

    Raises:
        InvalidArgumentError: A port is not one of 1 to ``ports``.
        UnknownNameError: A name is not one of the system's buttons.
    """
    masks = [0] * ports
    for name in names:
        port, _, button = name.rpartition(":")
        index = int(port) - 1 if port.isdigit() else 0
        if port and not port.isdigit() or not 0 <= index < len(masks):
            raise InvalidArgumentError(f"Expected a button, or PORT:BUTTON with a port of 1 to {len(masks)}; got {name!r}.")
        masks[index] |= system.mask([button])
    return masks


def _parse_step(word: str, where: str) -> Step:
    buttons, star, count = word.partition("*")
    if star:
        if not count.isdigit() or not 0 < int(count) <= MAX_FRAMES:
            raise InvalidArgumentError(
                f"Expected a number of frames from 1 to {MAX_FRAMES:,} after '*' in the script's {where}; "
                f"got {count!r}. Write {SYNTAX}."
            )
        frames = int(count)
    else:
        frames = 1
    if buttons == WAIT:
        return Step((), frames)
    names = tuple(buttons.split("+"))
    if not buttons or any(not name for name in names):
        raise InvalidArgumentError(
            f"Expected button names joined by '+', or {WAIT} for none, in the script's {where}; got {buttons!r}. "
            f"Write {SYNTAX}."
        )
    return Step(names, frames)
