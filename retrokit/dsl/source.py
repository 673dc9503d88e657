"""Where scenario text comes from, and errors that point into it.

Every expression the compiler sees is a :class:`Snippet`: its text, the file it
was read from, and the position of each of its characters in that file. Errors
are built by :func:`located`, which names the file, the line and the column,
and prints the source line with carets under the offending text::

    games/Dasher-Genesis/scenario.yaml:7:18: unknown field 'xpso'. Did you mean 'xpos'?
      progress: clip(xpso - initial(x), 0, end_x) / end_x
                     ^^^^
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field
from pathlib import Path

from retrokit.errors import FileSystemError, RetrokitError, ScenarioError


@dataclass(frozen=True)
class SourceText:
    """The full text of one source (a file, or a lone expression), for locating."""

    name: str
    text: str
    line_starts: tuple[int, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        starts = [0] + [i + 1 for i, c in enumerate(self.text) if c == "\n"]
        object.__setattr__(self, "line_starts", tuple(starts))

    def line_col(self, index: int) -> tuple[int, int]:
        """Return the 1-based line and column of the character at ``index``."""
        line = bisect.bisect_right(self.line_starts, index) - 1
        return line + 1, index - self.line_starts[line] + 1

    def line_text(self, line: int) -> str:
        """Return line ``line`` (1-based) without its newline."""
        start = self.line_starts[line - 1]
        end = self.text.find("\n", start)
        return self.text[start:] if end < 0 else self.text[start:end]

    def excerpt(self, start: int, end: int) -> tuple[str, str]:
        """Return ``name:line:col``, and the source line with carets under [start, end)."""
        line, col = self.line_col(start)
        text = self.line_text(line).replace("\t", " ")
        width = max(1, min(end - start, len(text) - col + 1))
        return f"{self.name}:{line}:{col}", f"    {text}\n    {' ' * (col - 1)}{'^' * width}"


@dataclass(frozen=True)
class Snippet:
    """One expression's text, and where each of its characters sits in its source.

    Attributes:
        text: The expression as the parser sees it.
        source: The text it was read from (a YAML or JSON file, or the expression itself).
        role: What the expression is, for messages: ``"reward"``, ``"define 'progress'"``.
        offsets: For each character of ``text``, and one past the end, its index in
            ``source.text``; ``None`` when ``text`` *is* ``source.text``.
    """

    text: str
    source: SourceText
    role: str
    offsets: tuple[int, ...] | None = None

    @classmethod
    def standalone(cls, text: str, name: str, role: str) -> Snippet:
        """A snippet that is its own source, e.g. an expression given in a dict."""
        return cls(text, SourceText(name, text), role)

    def file_index(self, offset: int) -> int:
        """Map an offset in ``text`` to an index in ``source.text``."""
        if self.offsets is None:
            return offset
        return self.offsets[max(0, min(offset, len(self.offsets) - 1))]

    def where(self, start: int = 0) -> str:
        """Return ``file:line:col`` of ``text[start]``."""
        line, col = self.source.line_col(self.file_index(start))
        return f"{self.source.name}:{line}:{col}"

    def error(self, cls: type[RetrokitError], start: int, end: int, message: str) -> RetrokitError:
        """Build ``cls`` pointing at ``text[start:end]`` (see :func:`located`)."""
        first = self.file_index(start)
        last = self.file_index(max(start, end - 1)) + 1
        return located(cls, self.source, first, last, f"{message} (in {self.role})")


def align(value: str, raw: str, base: int) -> tuple[int, ...]:
    """Map each character of a YAML scalar's ``value`` to its index in the file.

    ``raw`` is the scalar as written (with quotes, block indicators, indentation
    and folded line breaks), starting at file index ``base``. Each non-blank
    character of ``value`` is matched to the next equal character of ``raw``;
    blanks take the position after the previous match. This is exact for plain,
    literal and folded scalars and for quoted ones without escapes, and degrades
    to nearby positions otherwise.
    """
    offsets = []
    j = 0
    last = 0
    for ch in value:
        if ch.isspace():
            offsets.append(base + min(last, len(raw)))
            continue
        k = raw.find(ch, j)
        if k < 0:
            offsets.append(base + min(last, len(raw)))
            continue
        offsets.append(base + k)
        j = last = k + 1
    offsets.append(base + min(last, len(raw)))
    return tuple(offsets)


def located(cls: type[RetrokitError], source: SourceText, start: int, end: int, message: str) -> RetrokitError:
    """Build an error of class ``cls`` that names the place and shows it.

    Args:
        cls: The error class, e.g. ``ScenarioCompileError``.
        source: The text the place is in.
        start: Index of the first offending character in ``source.text``.
        end: Index one past the last.
        message: What is wrong and how to fix it.

    Returns:
        The error, with ``file``, ``line`` and ``column`` attributes set.
    """
    place, excerpt = source.excerpt(start, end)
    err = cls(f"{place}: {message}\n{excerpt}")
    line, col = source.line_col(start)
    err.file, err.line, err.column = source.name, line, col  # type: ignore[attr-defined]
    return err



def read_source(path: Path) -> SourceText:
    """Read a scenario file as UTF-8 text (a leading byte-order mark is allowed).

    The file is read by :func:`retrokit.paths.read_regular_file`, with the size
    cap of every YAML file: a FIFO, a device or a symlink loop is an error.

    Raises:
        ScenarioError: The file cannot be read, is not a regular file, is too
            large, or is not UTF-8; the error points at the first byte that is not.
    """
    from retrokit.data.yamlfile import MAX_YAML_BYTES
    from retrokit.paths import read_regular_file

    try:
        data = read_regular_file(path, "a scenario file", MAX_YAML_BYTES)
    except FileSystemError as exc:
        raise ScenarioError(str(exc)) from None
    try:
        return SourceText(str(path), data.decode("utf-8-sig"))
    except UnicodeDecodeError as exc:
        # Locate the bad byte in the text as far as it decodes, so the message shows its line.
        bom = 3 if data.startswith(b"\xef\xbb\xbf") else 0
        good = data[bom : exc.start].decode("utf-8")
        shown = SourceText(str(path), good + data[exc.start :].decode("utf-8", errors="replace"))
        raise located(
            ScenarioError, shown, len(good), len(good) + 1,
            f"expected UTF-8 text, got the byte 0x{data[exc.start]:02x}; save the file as UTF-8",
        ) from None
