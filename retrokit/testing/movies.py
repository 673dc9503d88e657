"""Checking a game's reference movies: each replays to the outcome ``game.yaml`` expects.

A game folder may hold solution movies, ``movies/<name>.bk2``, and its
``game.yaml`` the outcome of each under the scenario it proves::

    movies:
      Zone1.Act1: {scenario: scenario, done_at: 615, reward: 2564, tolerance: 0.5}

``done_at`` is the movie frame at which the scenario first says done (``null``:
never), ``reward`` the total of every player's reward up to then. The movie
is replayed from its own start state with the scenario evaluated after every
frame.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from retrokit.data.games import Game
from retrokit.errors import RetrokitError
from retrokit.testing.report import FAIL, PASS, SKIP, WARN, GameReport

__all__ = [
    "DEFAULT_TOLERANCE", "MOVIES_FOLDER", "Expected", "MovieOutcome", "check_movies", "expected_outcome", "movie_files",
    "replay",
]

MOVIES_FOLDER = "movies"
DEFAULT_TOLERANCE = 1e-3


@dataclass(frozen=True)
class MovieOutcome:
    """What a scenario said along a movie.

    Attributes:
        frames: The movie's length in frames.
        done_at: The first frame (1-based) at which done held, or ``None``.
        reward: The total of every player's reward up to ``done_at`` (or the end).
    """

    frames: int
    done_at: int | None
    reward: float


def movie_files(game: Game) -> dict[str, Path]:
    """The game's solution movies by name (the file's stem), from every folder of the game."""
    found: dict[str, Path] = {}
    for folder in game.folders:
        for path in sorted((folder / MOVIES_FOLDER).glob("*.bk2")):
            found.setdefault(path.stem, path)
    return found


def replay(game: Game, movie_path: Path, scenario: str | None = None, rom: Path | None = None) -> MovieOutcome:
    """Replay a movie with a scenario evaluated after every frame; return what it said.

    Raises:
        MovieError: The movie is malformed or is not of this game's system.
        ScenarioError: The scenario does not compile, or fails while running.
    """
    from retrokit.dsl.scenario import load_scenario
    from retrokit.host.emulator import Emulator
    from retrokit.movie import read_bk2
    from retrokit.movie.playback import replay as frames_of

    movie = read_bk2(movie_path)
    path = game.scenario_path(scenario)
    compiled = load_scenario(path, list(game.fields), game_dir=path.parent)
    total, done_at = 0.0, None
    with Emulator(game.system, rom or game.require_rom(), ports=max(2, movie.players)) as emu:
        reader = game.reader(emu.space)
        run = compiled.start()
        for frame in frames_of(movie, emu, source=f"{movie_path}: Core.bin"):  # its start state checked there
            if frame == 0:
                run.reset(reader.read())  # as an env's reset: the scenario starts from the movie's state
                continue
            rewards, done = run.step(reader.read(), frame, frame)
            total += sum(rewards)
            if done:
                done_at = frame
                break
    return MovieOutcome(len(movie.frames), done_at, total)


def check_movies(game: Game, report: GameReport, rom: Path | None) -> None:
    """Replay every solution movie and compare with its expected outcome; add the results to ``report``."""
    files = movie_files(game)
    expected = game.info.extra.get("movies") or {}
    if not isinstance(expected, Mapping):
        report.add("movie", FAIL, f"expected game.yaml's 'movies' to map movie names to outcomes; found "
                   f"{type(expected).__name__}. Write it as movies: {{Zone1.Act1: {{done_at: 621, reward: 3552}}}}.")
        return
    if not files and not expected:
        return
    for name in sorted(set(expected) - set(files)):
        report.add("movie", FAIL, f"expected the movie {MOVIES_FOLDER}/{name}.bk2 that game.yaml's 'movies' names; "
                   f"found no such file in {', '.join(str(f) for f in game.folders)}. Add it or remove the entry.",
                   state=name)
    for name, path in files.items():
        if name not in expected:
            report.add("movie", WARN, f"{path.name} has no expected outcome under 'movies' in game.yaml, so it "
                       "proves nothing; add {done_at: F, reward: R}", state=name)
            continue
        try:
            want = expected_outcome(name, expected[name])
        except RetrokitError as exc:
            report.add("movie", FAIL, str(exc), state=name)
            continue
        if rom is None:
            report.add("movie", SKIP, "no ROM to replay it with", state=name)
            continue
        _check_one(game, report, name, path, want, rom)


@dataclass(frozen=True)
class Expected:
    """What ``game.yaml`` expects of one solution movie (an entry of ``movies``).

    Attributes:
        reward: The total reward up to ``done_at`` (or the end).
        tolerance: How far the total may be from ``reward``.
        scenario: The scenario to replay under, or ``None`` for the game's default.
        done_at: The frame at which done first holds; ``None``: never.
        check_done: Whether ``done_at`` was given (without it, only the reward is checked).
    """

    reward: float
    tolerance: float = DEFAULT_TOLERANCE
    scenario: str | None = None
    done_at: int | None = None
    check_done: bool = False


def expected_outcome(name: str, entry: Any) -> Expected:
    """Read the entry of ``movies`` for the movie ``name``, checking every value.

    Raises:
        DataFileError: The entry is not a mapping, lacks ``reward``, or holds a value of
            the wrong type (a reward or tolerance that is not a finite number, a
            negative tolerance, a ``done_at`` that is not a frame number or null).
    """
    from retrokit.errors import DataFileError

    def wrong(expected: str, found: Any) -> DataFileError:
        shown = repr(found) if len(repr(found)) <= 60 else repr(found)[:57] + "..."
        return DataFileError(
            f"game.yaml: expected the entry of movies {name!r} to have {expected}; found {shown}. "
            f"Write it as {{scenario: scenario, done_at: 621, reward: 3552, tolerance: 0.001}}."
        )

    if not isinstance(entry, Mapping):
        raise wrong("the form {done_at: F, reward: R}", entry)
    if "reward" not in entry:
        raise wrong("a 'reward' (the expected total reward)", dict(entry))
    reward, tolerance = entry["reward"], entry.get("tolerance", DEFAULT_TOLERANCE)
    for key, value in (("reward", reward), ("tolerance", tolerance)):
        # not math.isfinite(nan) matters: abs(x - want) > nan is never true, so NaN would pass any reward
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise wrong(f"a finite number as {key!r}", value)
    if tolerance < 0:
        raise wrong("a 'tolerance' of 0 or more", tolerance)
    done_at = entry.get("done_at")
    if done_at is not None and (
        isinstance(done_at, bool) or not isinstance(done_at, int) or done_at < 1
    ):
        raise wrong("a frame number (1 or more) or null as 'done_at'", done_at)
    scenario = entry.get("scenario")
    if scenario is not None and not isinstance(scenario, str):
        raise wrong("a scenario name as 'scenario'", scenario)
    return Expected(float(reward), float(tolerance), scenario, done_at, "done_at" in entry)


def _check_one(game: Game, report: GameReport, name: str, path: Path, want: Expected, rom: Path) -> None:
    label = want.scenario or game.default_scenario or ""
    try:
        outcome = replay(game, path, want.scenario, rom)
    except RetrokitError as exc:
        report.add("movie", FAIL, f"{path.name} could not be replayed: {exc}", state=name, scenario=label)
        return
    tolerance = want.tolerance
    problems = []
    if want.check_done and want.done_at != outcome.done_at:
        found = f"frame {outcome.done_at}" if outcome.done_at else f"never, in its {outcome.frames} frames"
        problems.append(f"done at frame {want.done_at}, found done {found}")
    if abs(outcome.reward - want.reward) > tolerance:
        problems.append(f"a total reward of {want.reward:g} (within {tolerance:g}), found {outcome.reward:g}")
    if problems:
        report.add("movie", FAIL, f"expected {'; and '.join(problems)}. If the scenario changed on purpose, "
                   "update 'movies' in game.yaml; else the scenario's reward or done broke.",
                   state=name, scenario=label)
    else:
        done = f"done at frame {outcome.done_at}" if outcome.done_at else "never done"
        report.add("movie", PASS, f"{done}, total reward {outcome.reward:g}, as expected", state=name, scenario=label)
