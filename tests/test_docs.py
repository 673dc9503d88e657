"""Every Python block of README.md and docs/*.md runs as written.

The blocks of one file run in order, each in a fresh namespace, in one
temporary folder (so a file a block writes, such as a movie, is there for the
next block, and nothing lands in the checkout). A block whose first line is a
comment starting ``# needs`` (e.g. ``# needs a Sonic ROM: retrokit import``)
says, visibly, what it needs that test machines lack, and is skipped with that
reason.
"""

from __future__ import annotations

import os
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


@pytest.mark.parametrize("path", DOCUMENTS, ids=lambda p: p.name)
def test_every_python_block_runs(path: Path, tmp_path, monkeypatch) -> None:
    found = blocks(path)
    if not found:
        pytest.skip(f"{path.name} has no Python block")
    monkeypatch.chdir(tmp_path)
    skipped = []
    for line, code in found:
        first = code.lstrip().splitlines()[0] if code.strip() else ""
        if first.startswith("# needs"):
            skipped.append(f"line {line}: {first[2:]}")
            continue
        try:
            exec(compile(code, f"{path.name}:{line}", "exec"), {"__name__": f"doc_{path.stem}"})  # noqa: S102
        except Exception as exc:
            raise AssertionError(f"{path.relative_to(REPO)}, the block at line {line} fails: {exc!r}") from exc
    assert os.getcwd() == str(tmp_path)
    if skipped:
        pytest.skip("; ".join(skipped))
