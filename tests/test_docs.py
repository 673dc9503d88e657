"""Every Python block of README.md and docs/*.md runs as written.

The blocks of one file run in order, in one temporary folder (so a file a
block writes, such as a movie, is there for the next block, and nothing lands
in the checkout). A block's first line may say what it needs:

- ``# needs ...`` (e.g. ``# needs a Sonic ROM: retrokit import``): something
  test machines lack; the block is skipped with that reason.
- ``# requires MODULE, ...: pip install ...`` (a recipe with other packages:
  SB3, RLlib, SuperSuit): it runs where every module can be imported, in a
  fresh interpreter (so Ray or torch never stay in the test process), and is
  skipped otherwise, naming what is missing and how to install it. A line
  ``NAME = VALUE  # tests: SMALL`` runs with the tiny budget SMALL. A header
  ending in ``; this is FILE`` (an agent file) is written as FILE in the
  folder instead, for what comes after it to run (the command that evaluates
  the SB3 agent, run by its own test).

Other blocks run in this process, each in a fresh namespace.
"""

from __future__ import annotations

import importlib.util
import re
import shlex
import subprocess
import sys
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


REQUIRES = re.compile(r"^# requires (?P<modules>[\w., ]+): (?P<install>.+?)(?:; this is (?P<file>[\w.]+))?$")
BUDGET = re.compile(r"^(?P<assign>\s*\w+ = ).*?#\s*tests: (?P<small>.+)$", re.MULTILINE)


def _header(code: str) -> str:
    return code.lstrip().splitlines()[0] if code.strip() else ""


def _needs(code: str) -> str | None:
    first = _header(code)
    return first[2:] if first.startswith("# needs") else None


def _requires(code: str) -> re.Match[str] | None:
    return REQUIRES.match(_header(code))


def _missing(code: str) -> str | None:
    """Why a ``# requires`` block cannot run here, or None."""
    required = _requires(code)
    if required is None:
        return None
    absent = [m.strip() for m in required["modules"].split(",") if not _importable(m.strip())]
    return f"needs {', '.join(absent)}: {required['install']}" if absent else None


def _importable(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def tiny(code: str) -> str:
    """The block with its budgets cut to what its ``# tests:`` comments say."""
    return BUDGET.sub(lambda m: m["assign"] + m["small"].strip(), code)


def _run(path: Path, line: int, code: str, folder: Path) -> None:
    required = _requires(code)
    if required is not None:
        _run_apart(path, line, tiny(code), folder, required["file"])
        return
    try:
        exec(compile(code, f"{path.name}:{line}", "exec"), {"__name__": f"doc_{path.stem}"})  # noqa: S102
    except Exception as exc:
        raise AssertionError(f"{path.relative_to(REPO)}, the block at line {line} fails: {exc!r}") from exc


def _run_apart(path: Path, line: int, code: str, folder: Path, file: str | None) -> None:
    """Run a recipe in a fresh interpreter in ``folder``; or, if it is a file for what follows, write it there."""
    if file is not None:
        compile(code, f"{path.name}:{line}", "exec")  # what follows it runs it (see the SB3 agent's test)
        (folder / file).write_text(code)
        return
    result = subprocess.run(
        [sys.executable, "-c", code], cwd=folder, capture_output=True, text=True, timeout=600, check=False
    )
    if result.returncode != 0:
        raise AssertionError(
            f"{path.relative_to(REPO)}, the block at line {line} fails (exit {result.returncode}):\n{result.stderr[-3000:]}"
        )


def run_up_to(path: Path, index: int, folders: dict[Path, tuple[Path, int]]) -> Path:
    """Run a document's blocks before block ``index`` that have not run yet; return its folder."""
    folder, done = folders[path]
    mine = blocks(path)
    for earlier_line, earlier in mine[done:index]:  # a block may use what the ones above it made
        if _needs(earlier) is None and _missing(earlier) is None:
            _run(path, earlier_line, earlier, folder)
    folders[path] = (folder, max(done, index + 1))
    return folder


@pytest.mark.parametrize("path,line,code", BLOCKS, ids=[f"{p.name}:{line}" for p, line, _ in BLOCKS])
def test_every_python_block_runs(path: Path, line: int, code: str, folders, monkeypatch) -> None:
    monkeypatch.chdir(folders[path][0])
    folder = run_up_to(path, blocks(path).index((line, code)), folders)
    reason = _needs(code) or _missing(code)
    if reason is not None:
        pytest.skip(reason)
    _run(path, line, code, folder)


def test_the_sb3_agent_file_plays_through_retrokit_evaluate(folders, monkeypatch) -> None:
    """The SB3 recipe's agent file, as the document's own command evaluates it (on one level, for 64 timesteps)."""
    path = REPO / "docs" / "evaluate.md"
    mine = blocks(path)
    files = [required["file"] if (required := _requires(code)) else None for _, code in mine]
    agent = files.index("ppo_agent.py")
    reason = _missing(mine[agent][1])
    if reason is not None:
        pytest.skip(reason)
    monkeypatch.chdir(folders[path][0])
    folder = run_up_to(path, agent + 1, folders)
    command = re.search(r"^retrokit evaluate .*ppo_agent\.py:ppo.*$", path.read_text(), re.MULTILINE)
    assert command is not None, "evaluate.md shows no command that evaluates ppo_agent.py"
    argv = shlex.split(command[0])[1:] + ["--levels", "Zone1.Act2", "--timesteps", "64", "--no-progress"]
    result = subprocess.run(
        [sys.executable, "-m", "retrokit", *argv], cwd=folder, capture_output=True, text=True, timeout=600, check=False
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert (folder / "runs" / "ppo" / "summary.json").is_file()


def test_tiny_cuts_only_the_marked_budgets() -> None:
    code = "STEPS = 100_000  # tests: 64\nOTHER = 5\n    ITERATIONS = 10  #tests: 1\n"
    assert tiny(code) == "STEPS = 64\nOTHER = 5\n    ITERATIONS = 1\n"


def test_a_recipe_whose_packages_are_missing_says_which_and_how_to_install() -> None:
    code = "# requires numpy, no_such_package_here: pip install no-such-package\nimport no_such_package_here\n"
    assert _missing(code) == "needs no_such_package_here: pip install no-such-package"
    assert _missing("# requires numpy: pip install numpy\nimport numpy\n") is None
    assert _requires("# requires numpy: pip install numpy; this is agent.py\n")["file"] == "agent.py"
