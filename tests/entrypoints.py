"""Every entry point a state reaches a core through, driven with one state for one game, all cases in one child.

:func:`entry_cases` builds, for one game and one state, a case for each entry
point: ``make(state=...)``, an env's ``load_state`` (which sets the state at the
next reset), ``playback`` and ``integrate --movie`` of a movie whose
``Core.bin`` is the state, ``validate`` of a copy of the game folder holding
the state, and the studio loading it from that folder. :func:`run_cases` runs
any number of them in ONE child (an interpreter and retrokit's imports are most
of a case's cost), each with a data folder of its own, its answer printed as
one JSON line as it ends, so a crash names its case.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

from childproc import REPO, Child, run_child

from retrokit.data.games import find_game
from retrokit.data.states import compress_state
from retrokit.movie import Movie, write_bk2

ENTRY_POINTS = ["make", "load_state", "playback", "integrate", "validate", "studio"]

RUN_CASES = """
import contextlib, io, json, os, traceback
from retrokit.cli import main
for name, data, kind, what in CASES:
    os.environ["RETROKIT_DATA"] = data
    out, err = io.StringIO(), io.StringIO()
    answer = {"case": name}
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            if kind == "cli":
                answer["status"] = main(what)
            else:
                exec(what, {})
    except Exception:
        answer["error"] = traceback.format_exc()
    answer.update(stdout=out.getvalue(), stderr=err.getvalue())
    print(json.dumps(answer), flush=True)
"""

_MAKE = """
import retrokit
from retrokit.errors import StateError
try:
    retrokit.make(GAME, state=STATE).reset()
    print("played")
except StateError as exc:
    print("refused:", exc)
"""

_LOAD_STATE = """
import retrokit
from retrokit.errors import StateError
env = retrokit.make(GAME)
try:
    env.unwrapped.load_state(STATE)
    env.reset()
    print("played")
except StateError as exc:
    print("refused:", exc)
env.close()
"""

STUDIO_LOAD = """
from retrokit.errors import StateError
from retrokit.studio import play
from retrokit.studio.session import Session
session = Session(GAME)
try:
    session.call_blocking(play.reset, NAME)
    print("played")
except StateError as exc:
    print("refused:", exc)
session.close()
"""

Case = tuple[str, str, str, Any]  # (name, data folder, kind, what): one line of RUN_CASES's CASES


def game_copy(game: str, folder: Path, state: bytes) -> Path:
    """A copy of our game's folder (its ROM too) with only its default state (the studio opens it; ``validate``
    checks it as well), holding ``state`` as ``Hostile.state``."""
    source = REPO / "games" / game
    copy = folder / game
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("*.state"))
    default = find_game(source).state_path()
    shutil.copyfile(default, copy / default.name)
    (copy / "Hostile.state").write_bytes(compress_state(state, None))
    return copy


def entry_cases(prefix: str, game: str, system: str, state: bytes, folder: Path) -> list[Case]:
    """A case for each of :data:`ENTRY_POINTS` that loads ``state`` for ``game``, named ``<prefix>-<entry point>``."""
    folder.mkdir(parents=True, exist_ok=True)
    copy = game_copy(game, folder, state)
    file = copy / "Hostile.state"
    movie = folder / "hostile.bk2"
    write_bk2(movie, Movie(game, system, 1, state, [(0,)] * 30))
    header = f"GAME = {str(copy)!r}\nSTATE = {str(file)!r}\n"
    whats: dict[str, tuple[str, Any]] = {
        "make": ("code", header + _MAKE),
        "load_state": ("code", header + _LOAD_STATE),
        "playback": ("cli", ["playback", str(movie), str(folder / "out")]),
        "integrate": ("cli", ["integrate", game, "Made", "--out", str(folder / "made"), "--movie", str(movie)]),
        "validate": ("cli", ["validate", str(copy), "--frames", "5", "-q", "--json", str(folder / "report.json")]),
        "studio": ("code", header + "NAME = 'Hostile'\n" + STUDIO_LOAD),
    }
    return [(f"{prefix}-{entry}", str(folder / f"data-{entry}"), *whats[entry]) for entry in ENTRY_POINTS]


def run_cases(cases: list[Case], timeout: float = 600) -> tuple[dict[str, dict], Child]:
    """Run ``cases`` in one child; each case's answer (an ``error`` if the child ended before it), and the child."""
    child = run_child(f"CASES = {cases!r}\n" + RUN_CASES, timeout=timeout)
    answers = {answer["case"]: answer for answer in map(json.loads, child.stdout.splitlines()) if answer}
    ended = {"error": f"the child ended before this case's answer: {child.describe()}"}
    return {name: answers.get(name, ended) for name, *_ in cases}, child


def refusal(entry: str, answer: dict, folder: Path) -> str:
    """The line with which an entry point refused its state (fails the test if it ran the state instead)."""
    assert "error" not in answer, answer["error"]
    if entry in ("make", "load_state", "studio"):
        said = answer["stdout"]
        assert "refused:" in said and "played" not in said, answer
        return said
    if entry == "validate":
        report = json.loads((folder / "report.json").read_text())
        (result,) = [r for g in report["games"] for r in g["results"] if r["state"] == "Hostile"]
        assert result["status"] == "fail", result
        return result["message"]
    assert answer.get("status") == 2, answer  # playback, integrate: a one-line error
    last = answer["stderr"].strip().splitlines()[-1]
    assert last.startswith("retrokit: error:") and "Traceback" not in answer["stderr"], answer
    made = folder / "made"
    assert not made.exists() or not list(made.iterdir())
    return last
