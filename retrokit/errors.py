"""Every error retrokit raises, in one flat module.

Messages follow one pattern: what was expected, what was found, and how to fix
it. Where the user typed a name that is close to a known one, the message ends
with a did-you-mean suggestion built by :func:`did_you_mean`.
"""

from __future__ import annotations

import difflib
import os
import shlex
from collections.abc import Iterable

MIN_PART = 3
"""The shortest text that :func:`did_you_mean` also looks for inside the choices."""
MAX_PARTS = 3


def did_you_mean(name: str, choices: Iterable[str], *, n: int = 1) -> str:
    """Return ``" Did you mean 'x'?"`` for the ``n`` choices closest to ``name``, or ``""``.

    When no choice is close, up to three that contain ``name`` are suggested.
    """
    choices = [str(c) for c in choices]
    close = difflib.get_close_matches(name, choices, n=n, cutoff=0.6)
    if not close:
        lowered = {c.lower(): c for c in choices}
        close = [lowered[c] for c in difflib.get_close_matches(name.lower(), list(lowered), n=n, cutoff=0.6)]
    if not close and len(name) >= MIN_PART:
        # A part of a long name ('Sonic' for 'SonicTheHedgehog-Genesis') is too short to be "close" to it.
        close = [c for c in choices if name.lower() in c.lower()][:MAX_PARTS]
    if not close:
        return ""
    if len(close) == 1:
        return f" Did you mean {close[0]!r}?"
    return " Did you mean one of: " + ", ".join(repr(c) for c in close) + "?"


def shown(value: object, limit: int = 60) -> str:
    """``repr(value)`` for a message, cut to ``limit`` characters so a huge argument cannot flood it."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def printable(text: str, *, escape: str = "") -> str:
    """``text`` with every character that is not printable (an escape sequence's ESC, a newline) written as
    ``\\xHH``, ``\\uHHHH`` or ``\\UHHHHHHHH``, and a byte that is not UTF-8 (a file name's, kept by Python as a
    lone surrogate) as the byte: printing a file name can then never drive the terminal or break a line.

    Args:
        text: The text.
        escape: Characters to put a backslash before as well (a quoting's own).
    """
    escaped = []
    for char in text:
        code = ord(char)
        if char in escape:
            escaped.append("\\" + char)
        elif char.isprintable():
            escaped.append(char)
        elif code < 0x100 or 0xDC80 <= code <= 0xDCFF:  # a control character, or an undecodable byte
            escaped.append(f"\\x{code & 0xFF:02x}")
        else:
            escaped.append(f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}")
    return "".join(escaped)


def shell_word(value: str | os.PathLike[str]) -> str:
    """``value`` (a file name in a hint's command) as one word a shell reads back, that cannot drive the terminal.

    Printable text is quoted as :func:`shlex.quote` does; text holding control characters (an escape
    sequence, a newline) takes the ``$'...'`` form of bash, zsh and ksh, with them escaped (:func:`printable`).
    """
    text = os.fspath(value)
    return shlex.quote(text) if text.isprintable() else "$'" + printable(text, escape="'\\") + "'"


def listed(items: Iterable[str], limit: int = 10, width: int = 60) -> str:
    """Items for a one-line message: the first ``limit``, each cut to ``width`` characters, then how many more."""
    items = list(items)
    cut = [i if len(i) <= width else i[: width - 3] + "..." for i in items[:limit]]
    return ", ".join(cut) + (f" and {len(items) - limit} more" if len(items) > limit else "")


DISTRIBUTION = "retrokit-rl"
"""retrokit's name on the package index ("retrokit" there is another project); the import name stays ``retrokit``."""


def install_extra(extra: str) -> str:
    """Return the command that installs one of retrokit's optional extras: ``pip install 'retrokit-rl[ray]'``."""
    return f"pip install '{DISTRIBUTION}[{extra}]'"


class RetrokitError(Exception):
    """The root of every error retrokit raises on purpose."""


# --- Arguments and names -------------------------------------------------------------


class InvalidArgumentError(RetrokitError, ValueError):
    """An argument has the wrong type, shape, dtype or range."""


class UnknownNameError(RetrokitError, KeyError):
    """A name (game, state, field, system, option, button) is not known."""

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0]) if self.args else ""


class GameNotFoundError(UnknownNameError):
    """No integration folder holds a game of that name."""


class StateNotFoundError(UnknownNameError):
    """The game has no save state of that name."""


class FieldNotFoundError(UnknownNameError):
    """The game's data file names no RAM field of that name."""


# --- Cores and the native host -------------------------------------------------------------


class CoreError(RetrokitError, RuntimeError):
    """A libretro core refused a call or could not be loaded."""


class CoreNotFoundError(CoreError):
    """No libretro core for a system was found in any search location."""


class ChildStartError(RetrokitError, OSError):
    """The child process a core or a state is tried in could not start (no memory, no processes left).

    Attributes:
        reason: Why, as the system said it.
    """

    reason: str = ""


class CoreBuildError(RetrokitError):
    """Building a core from source failed (retrokit build-core)."""


class BuildToolError(CoreBuildError):
    """A tool the build needs (a C compiler, make, pip) is not installed."""


class SourceFetchError(CoreBuildError):
    """The package index could not be reached to fetch a core's source."""


class SourceNotFoundError(CoreBuildError):
    """The package index has no source package (sdist) of that stable-retro version."""


class PatchError(CoreBuildError):
    """A patch does not apply to the source it was given."""


class UnsupportedSystemError(UnknownNameError):
    """A ROM, file extension or system name maps to no known system."""


# --- Files: data, states, ROMs, movies -----------------------------------------------------


class DataFileError(RetrokitError, ValueError):
    """A game data, system or integration file is malformed."""


class FieldTypeError(DataFileError):
    """A RAM field's type code is not one retrokit can read."""


class StateError(RetrokitError, ValueError):
    """A save state is truncated, corrupt, or made by another core."""


class RomError(RetrokitError):
    """A ROM is missing, unreadable, or not the one a game expects."""


class RomNotFoundError(RomError, FileNotFoundError):
    """A game's ROM has not been imported."""


class RomMismatchError(RomError, ValueError):
    """A ROM's SHA-1 matches none of the game's known hashes."""


class FileConflictError(RetrokitError, FileExistsError):
    """Writing would replace a different file the user already has."""


class FileSystemError(RetrokitError, OSError):
    """A file or folder cannot be read or written: a file where a folder should be, no permission, a full disk."""


class PlantedLinkError(FileSystemError):
    """A folder or file below the data folder is a symlink, which retrokit never makes there: it would send writes
    elsewhere, and let files nobody wrote there pass for retrokit's own."""


class MovieError(RetrokitError, ValueError):
    """A .bk2 movie is malformed or does not fit the game it is played on."""


# --- Scenarios ---------------------------------------------------------------------------------


class ScenarioError(RetrokitError, ValueError):
    """A scenario file is malformed or cannot be compiled."""


class ScenarioSyntaxError(ScenarioError):
    """A scenario expression does not parse."""


class ScenarioCompileError(ScenarioError):
    """A scenario expression parses but means nothing: unknown name, arity, type."""


class ScenarioRuntimeError(RetrokitError, ArithmeticError):
    """A scenario expression failed while running: division by zero, missing table key."""


# --- Environments ------------------------------------------------------------------------------


class EnvError(RetrokitError, RuntimeError):
    """An environment was used out of order, e.g. stepped before reset."""


class MissingExtraError(RetrokitError, ImportError):
    """What was asked for needs an optional dependency (an extra, e.g. pygame for a window) that is not installed."""


# --- Benchmarks and evaluation -----------------------------------------------------------------


class BenchmarkFileError(DataFileError):
    """A benchmark YAML file is malformed."""


class RunFolderError(DataFileError):
    """An evaluation's run folder cannot be resumed: missing, damaged, or made with other settings."""


class AgentConfigError(DataFileError):
    """A learning agent's config (``--agent-config NAME|FILE``) is unreadable, or a key or value is wrong."""


class PolicyFileError(DataFileError):
    """A saved policy (``policy.json`` and its weights) is missing, damaged, too large or not of this agent."""


class AgentError(RetrokitError, RuntimeError):
    """An agent raised, or gave an action its env cannot take, while it was evaluated."""


class BackendUnavailableError(RetrokitError, ImportError):
    """An evaluation backend (Ray) is not installed, or its cluster cannot be reached."""


# --- RAM search ----------------------------------------------------------------------------------


class RamSearchError(RetrokitError, ValueError):
    """A RAM search was asked for something its snapshots or history cannot give."""


class SessionError(RamSearchError):
    """A RAM search session file is missing, corrupt, not a session, or from another game."""


# --- The studio ----------------------------------------------------------------------------------


class StudioError(RetrokitError):
    """The studio's server was asked for something it cannot do: a malformed request, a port in use."""


class PortInUseError(StudioError, OSError):
    """Another program (often another studio) already listens on the port the studio was asked to use."""


class AccessDeniedError(StudioError, PermissionError):
    """A request named a file outside the game's folders and the data folder, or came without the studio's token."""


class RequestTooLargeError(StudioError):
    """A request's body is larger than the studio accepts."""


class SkippedDataWarning(UserWarning):
    """A stable-retro data file (``data.json``, ``scenario.json``) held what retrokit skips, as stable-retro does:
    a field outside the system's memory, a key neither knows. The message, one line, names what was skipped.
    retrokit's own files (``game.yaml``, YAML scenarios) never warn: what they hold that is wrong is an error."""
