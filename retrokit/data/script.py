"""Input scripts: taps, holds, waits and repeats, as ``ramsearch``, state recipes and the studio take them.

A script is steps separated by spaces (or lines); each step holds some
buttons for some frames, then the next step begins::

    START*1 _*60 RIGHT*30 RIGHT+B*2 (DOWN*40 _*4)*60

- ``BUTTONS*FRAMES`` holds ``BUTTONS`` for ``FRAMES`` frames; ``BUTTONS`` alone is one frame (a tap).
- ``BUTTONS`` is button names joined by ``+`` (``RIGHT+B``), as the system names them; ``2:START``
  is a button of port 2. ``_`` is no button: ``_*60`` waits 60 frames.
- ``(STEPS)*N`` plays ``STEPS`` ``N`` times; groups nest.

One grammar (:data:`GRAMMAR`, parsed by lark) is every caller's: a mistake
is reported with its line and column and a caret under it, as lark gives
them, and a misspelt button with the closest name. A script's frames are
counted before any of it is expanded, so ``((A*9999)*99999)*99999`` is
refused at once, in one line.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

from retrokit.errors import InvalidArgumentError, RetrokitError, shown

if TYPE_CHECKING:
    from retrokit.host.systems import System

MAX_FRAMES = 1_000_000  # about 4.6 hours of play, as a state recipe's budget: more is a typo
MAX_SCRIPT = 100_000  # characters
MAX_NAME = 32  # characters of a button's name (2:START, C-RIGHT): a longer word is no button
MAX_NESTING = 16  # groups inside groups: more is no script a person writes, and lark's tree is walked recursively
WAIT = "_"
SYNTAX = (
    "steps like START*1 _*60 RIGHT*30 RIGHT+B*2 (DOWN*40 _*4)*60 (BUTTONS*FRAMES; _ is no button; a step alone "
    "is one frame; (STEPS)*N repeats them)"
)

#: The script language. A button name is anything but blanks and the language's own ``+ * ( )``.
GRAMMAR = r"""
script: item+
?item: step | group
group: "(" item+ ")" ("*" COUNT)?
step: BUTTONS ("*" COUNT)?
BUTTONS: /[^\s+*()]+(\+[^\s+*()]+)*/
COUNT: /[0-9]+/
%import common.WS
%ignore WS
"""

_TERMINALS = {"$END": "the end", "BUTTONS": "buttons", "COUNT": "a number of frames", "LPAR": "'('", "RPAR": "')'", "STAR": "'*'"}


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


@functools.cache
def _lark() -> Lark:
    return Lark(GRAMMAR, start="script", parser="lalr", propagate_positions=True)


def parse_script(text: str, check_buttons: Callable[[Sequence[str]], object] | None = None) -> list[Step]:
    """Parse a script into its steps, repeats expanded (a repeated step is the same object each time).

    Args:
        text: The script.
        check_buttons: Called with each step's buttons; raises (with a did-you-mean) for an unknown one.

    Raises:
        InvalidArgumentError: The script is empty, too long (in characters or frames), malformed, or names an
            unknown button.
    """
    if not isinstance(text, str) or len(text) > MAX_SCRIPT:
        raise InvalidArgumentError(
            f"Expected a script of at most {MAX_SCRIPT:,} characters: {SYNTAX}; got {shown(text)}."
        )
    if not text.strip():
        raise InvalidArgumentError(f"Expected a script of {SYNTAX}; got an empty one.")
    _check_nesting(text)
    try:
        tree = _lark().parse(text)
    except UnexpectedInput as exc:
        raise _syntax_error(text, exc) from None
    total = _frames(text, tree)
    if total > MAX_FRAMES:
        raise InvalidArgumentError(
            f"Expected a script of at most {MAX_FRAMES:,} frames; got one of {total:,} frames "
            f"({shown(' '.join(text.split()))}). Play fewer repeats."
        )
    return _expand(text, tree, check_buttons, {})


def script_frames(steps: Sequence[Step]) -> int:
    """How many frames a parsed script plays."""
    return sum(step.frames for step in steps)


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


# --- positions and messages ----------------------------------------------------------------------


def _located(text: str, pos: int, message: str) -> InvalidArgumentError:
    """``message``, then where in the script: its line and column, and lark's picture (the line, a caret below)."""
    line = text.count("\n", 0, pos) + 1
    column = pos - (text.rfind("\n", 0, pos) + 1) + 1
    picture = UnexpectedInput()  # lark draws the caret from a position alone
    picture.pos_in_stream = pos
    return InvalidArgumentError(
        f"In the script at line {line}, column {column}: {message}{'' if message.endswith(('.', '?')) else '.'}\n{picture.get_context(text).rstrip()}"
    )


def _syntax_error(text: str, exc: UnexpectedInput) -> InvalidArgumentError:
    """A lark error as a message saying what was found, what was expected, and where."""
    if isinstance(exc, UnexpectedCharacters):
        pos, found, expected = exc.pos_in_stream, repr(text[exc.pos_in_stream]), exc.allowed
    elif isinstance(exc, UnexpectedToken) and exc.token.type != "$END":
        pos, found, expected = exc.token.start_pos, repr(str(exc.token)), exc.expected
    else:  # the text stopped too early
        pos, found = len(text.rstrip()), "the end of the script"
        expected = exc.expected if isinstance(exc, (UnexpectedToken, UnexpectedEOF)) else set()
    wanted = sorted({_TERMINALS.get(name, name) for name in getattr(exc, "accepts", None) or expected})
    return _located(
        text, min(pos, len(text) - 1), f"Expected {' or '.join(wanted) or 'a step'}; found {found}. Write {SYNTAX}"
    )


def _check_nesting(text: str) -> None:
    """Refuse groups nested deeper than :data:`MAX_NESTING` before lark parses (and a transformer recurses)."""
    depth = 0
    for index, char in enumerate(text):
        depth += (char == "(") - (char == ")")
        if depth > MAX_NESTING:
            raise _located(text, index, f"Expected groups nested at most {MAX_NESTING} deep; found deeper ones")


# --- counting and expanding ----------------------------------------------------------------------


def _count(text: str, token: Token | None) -> int:
    if token is None:
        return 1
    count = int(token)
    if not 0 < count <= MAX_FRAMES:
        raise _located(
            text, token.start_pos, f"Expected a count from 1 to {MAX_FRAMES:,} after '*'; found {str(token)[:20]!r}"
        )
    return count


def _parts(node: Tree) -> tuple[list[Tree], Token | None]:
    """A group's items and its repeat count (or a step's buttons and frames)."""
    counts = [c for c in node.children if isinstance(c, Token) and c.type == "COUNT"]
    return [c for c in node.children if not (isinstance(c, Token) and c.type == "COUNT")], (counts or [None])[0]


def _frames(text: str, node: Tree) -> int:
    """The frames a node plays, counted without expanding anything (Python's integers do not overflow)."""
    items, count = _parts(node)
    if node.data == "step":
        return _count(text, count)
    return sum(_frames(text, item) for item in items) * (_count(text, count) if node.data == "group" else 1)


def _expand(
    text: str, node: Tree, check: Callable[[Sequence[str]], object] | None, made: dict[int, Step]
) -> list[Step]:
    items, count = _parts(node)
    if node.data == "step":
        token = items[0]
        if token.start_pos not in made:  # a repeated step is checked and made once
            made[token.start_pos] = _step(text, token, _count(text, count), check)
        return [made[token.start_pos]]
    body = [step for item in items for step in _expand(text, item, check, made)]
    return body * (_count(text, count) if node.data == "group" else 1)


def _step(text: str, token: Token, frames: int, check: Callable[[Sequence[str]], object] | None) -> Step:
    if str(token) == WAIT:
        return Step((), frames)
    names = tuple(str(token).split("+"))
    long = next((name for name in names if len(name) > MAX_NAME), None)
    if long is not None:  # no button is named so: say so, without quoting it all in the message
        raise _located(text, token.start_pos, f"Expected button names of at most {MAX_NAME} characters; got {shown(long)}")
    if WAIT in names:
        raise _located(text, token.start_pos, f"Expected button names, or {WAIT} alone for none; found {str(token)!r}")
    if check is not None:
        try:
            check(names)
        except RetrokitError as exc:
            raise _located(text, token.start_pos, str(exc)) from None
    return Step(names, frames)
