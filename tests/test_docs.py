"""Every Python block of README.md and docs/*.md runs as written.

The blocks of one file run in order, each in a fresh namespace, in one
temporary folder (so a file a block writes, such as a movie, is there for the
next block, and nothing lands in the checkout). A block whose first line is a
comment starting ``# needs`` (e.g. ``# needs a Sonic ROM: retrokit import``)
says, visibly, what it needs that test machines lack, and is skipped with that
reason.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```", re.MULTILINE | re.DOTALL)


def blocks(path: Path) -> list[tuple[int, str]]:
    """Each Python block of a Markdown file, with the line it starts on."""
    text = path.read_text()
    return [(text.count("\n", 0, match.start()) + 2, match.group(1)) for match in BLOCK.finditer(text)]


def test_the_documents_have_python_blocks() -> None:
    counted = {path.name: len(blocks(path)) for path in DOCUMENTS}
    assert counted["README.md"] >= 3 and counted["scenarios.md"] >= 1 and counted["movies.md"] >= 2
    assert counted["from-stable-retro.md"] >= 1


BLOCKS = [(path, line, code) for path in DOCUMENTS for line, code in blocks(path)]


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> dict[Path, tuple[Path, int]]:
    """Per document: its working folder, and how many of its blocks ran there."""
    return {path: (tmp_path_factory.mktemp(path.stem), 0) for path in DOCUMENTS}


def _run(path: Path, line: int, code: str) -> None:
    try:
        exec(compile(code, f"{path.name}:{line}", "exec"), {"__name__": f"doc_{path.stem}"})  # noqa: S102
    except Exception as exc:
        raise AssertionError(f"{path.relative_to(REPO)}, the block at line {line} fails: {exc!r}") from exc


def _needs(code: str) -> str | None:
    first = code.lstrip().splitlines()[0] if code.strip() else ""
    return first[2:] if first.startswith("# needs") else None


@pytest.mark.parametrize("path,line,code", BLOCKS, ids=[f"{p.name}:{line}" for p, line, _ in BLOCKS])
def test_every_python_block_runs(path: Path, line: int, code: str, folders, monkeypatch) -> None:
    folder, done = folders[path]
    monkeypatch.chdir(folder)
    mine = blocks(path)
    index = mine.index((line, code))
    for earlier_line, earlier in mine[done:index]:  # a block may use what the ones above it made
        if _needs(earlier) is None:
            _run(path, earlier_line, earlier)
    folders[path] = (folder, index + 1)
    reason = _needs(code)
    if reason is not None:
        pytest.skip(reason)
    _run(path, line, code)
