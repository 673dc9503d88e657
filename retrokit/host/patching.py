"""Applying a unified diff to a source tree, exactly, in pure Python.

``retrokit build-core`` patches a core's source with a diff kept in the
package. The ``patch`` program may be missing, and its fuzz could apply a hunk
to the wrong place in a source it was not made for; here each hunk must match
its context exactly (at its stated line, or anywhere else in the file), else
nothing is written and the error names the hunk.

Only what ``diff -u`` writes is understood: ``--- a/path``, ``+++ b/path``,
``@@ -l,n +l,n @@`` hunks of `` ``, ``-`` and ``+`` lines. Text before the
first ``---`` (a description) is ignored. Lines match whatever their ends
(a patch kept with LF ends applies to a source file with CRLF ends), and
the lines written end as the file's first line does.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from retrokit.errors import PatchError

_HUNK = re.compile(r"^@@ -(\d+)(?:,(\d+))? \+(\d+)(?:,(\d+))? @@")


@dataclass
class _Hunk:
    start: int  # 1-based line of the old text
    old: list[str] = field(default_factory=list)
    new: list[str] = field(default_factory=list)


@dataclass
class FilePatch:
    """The hunks of one file of a diff."""

    path: str  # relative to the tree, without the a/ or b/ prefix
    hunks: list[_Hunk] = field(default_factory=list)


def parse_patch(text: str, name: str = "the patch") -> list[FilePatch]:
    """Parse a unified diff into its files' hunks.

    Raises:
        PatchError: The text holds no file, or a hunk line of an unknown kind.
    """
    files: list[FilePatch] = []
    lines = text.splitlines(keepends=True)
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("--- ") and i + 1 < len(lines) and lines[i + 1].startswith("+++ "):
            path = lines[i + 1][4:].split("\t")[0].strip()
            files.append(FilePatch(path.removeprefix("b/")))
            i += 2
            continue
        match = _HUNK.match(line)
        if match and files:
            hunk = _Hunk(int(match.group(1)))
            old_left, new_left = int(match.group(2) or 1), int(match.group(4) or 1)
            i += 1
            while (old_left > 0 or new_left > 0) and i < len(lines):
                body, kind = lines[i][1:], lines[i][:1]
                if kind in (" ", "\n"):  # an empty context line may have lost its space
                    body = body if kind == " " else "\n"
                    hunk.old.append(body)
                    hunk.new.append(body)
                    old_left, new_left = old_left - 1, new_left - 1
                elif kind == "-":
                    hunk.old.append(body)
                    old_left -= 1
                elif kind == "+":
                    hunk.new.append(body)
                    new_left -= 1
                elif not lines[i].startswith("\\"):  # "\ No newline at end of file"
                    raise PatchError(
                        f"Expected hunk lines starting with ' ', '-' or '+' in {name}; found {lines[i].rstrip()!r} "
                        f"(line {i + 1}). Regenerate the patch with diff -u."
                    )
                i += 1
            files[-1].hunks.append(hunk)
            continue
        i += 1
    if not files:
        raise PatchError(f"Expected a unified diff (--- a/file, +++ b/file, @@ hunks) in {name}; found none.")
    return files


def _bare(lines: list[str]) -> list[str]:
    """The lines without their line ends: a patch's lines end in LF whatever the file's (CRLF) end in."""
    return [line.rstrip("\r\n") for line in lines]


def _find(lines: list[str], old: list[str], near: int) -> int:
    """The index where ``old`` occurs in ``lines`` (line ends aside), the nearest to ``near``; -1 if nowhere."""
    n, bare, wanted = len(old), _bare(lines), _bare(old)
    starts = [s for s in range(len(lines) - n + 1) if bare[s : s + n] == wanted]
    return min(starts, key=lambda s: abs(s - near)) if starts else -1


def _with_ends(new: list[str], end: str) -> list[str]:
    """A hunk's new lines ending as the file's do (a last line without an end keeps none)."""
    return [line.rstrip("\r\n") + end if line.endswith("\n") else line for line in new]


def apply_patch(text: str, tree: Path, name: str = "the patch") -> list[Path]:
    """Apply a unified diff to the files under ``tree``; return the files changed.

    Every hunk of every file is checked before any file is written, so a
    failed patch leaves the tree as it was.

    Raises:
        PatchError: A file is missing, or a hunk's lines are not in its file.
    """
    results: list[tuple[Path, str]] = []
    for patch in parse_patch(text, name):
        path = tree / patch.path
        if not path.is_file():
            raise PatchError(f"Expected {patch.path} in {tree} for {name}; found no such file.")
        lines = path.read_bytes().decode("latin-1").splitlines(keepends=True)  # bytes kept as they are
        end = "\r\n" if lines and lines[0].endswith("\r\n") else "\n"
        shift = 0
        for number, hunk in enumerate(patch.hunks, 1):
            at = _find(lines, hunk.old, hunk.start - 1 + shift)
            if at < 0:
                raise PatchError(
                    f"Expected the lines of hunk {number} of {name} in {patch.path} (near line {hunk.start}); "
                    f"found them nowhere, so this source is not the one the patch was made for. "
                    f"Build from the stable-retro version the patch names, or update the patch."
                )
            lines[at : at + len(hunk.old)] = _with_ends(hunk.new, end)
            shift = at - (hunk.start - 1) + len(hunk.new) - len(hunk.old)
        results.append((path, "".join(lines)))
    for path, content in results:
        path.write_bytes(content.encode("latin-1"))
    return [path for path, _ in results]
