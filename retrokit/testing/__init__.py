"""Checking a game integration end to end, as Gymnasium's ``check_env`` checks an env.

``check_game(game)`` runs every check on one game and returns a
:class:`~retrokit.testing.report.GameReport`; ``retrokit validate`` prints it.
The checks, one module each:

- :mod:`~retrokit.testing.schema`: ``game.yaml`` and scenario files against the shipped JSON Schemas;
- :mod:`~retrokit.testing.fields`: fields inside the system's RAM, usual type codes, overlaps;
- :mod:`~retrokit.testing.states`: every state loads (in a child process), is the game's own, decodes;
- :mod:`~retrokit.testing.scenarios`: every scenario compiles, covers the states' table keys, and
  survives a deterministic smoke run on every state;
- :mod:`~retrokit.testing.movies`: solution movies replay to their expected outcome.

Without the ROM a game is checked as far as its files allow (schema, fields
against the RAM a state holds, states parsed, scenarios compiled, tables);
what was skipped is in the report, with why.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from retrokit.lazy import lazy_names
from retrokit.testing.report import FAIL, PASS, SKIP, GameReport, Result

if TYPE_CHECKING:
    from retrokit.data.games import Game

__all__ = ["STAGES", "GameReport", "Result", "check_game"]

#: The stages of :func:`check_game`, in order (each reported to ``progress``).
STAGES = ("schema", "data file", "ROM", "fields", "states", "scenarios", "movies")


def check_game(
    game: Game | str | os.PathLike[str],
    *,
    frames: int | None = None,
    progress: Callable[[str, str], None] | None = None,
) -> GameReport:
    """Check a game's integration; return every result.

    Args:
        game: A :class:`~retrokit.data.games.Game`, a game's name, or a path to a game folder.
        frames: Frames per smoke run (default :data:`retrokit.testing.scenarios.SMOKE_FRAMES`).
        progress: Called as ``progress(stage, "")`` when each of :data:`STAGES` starts, and as
            ``progress(stage, detail)`` along the long ones (e.g. the state a smoke run is on).

    Returns:
        The report; ``report.passed`` is false if any check failed.

    Raises:
        GameNotFoundError: No game of that name is known.
    """
    from retrokit.errors import RetrokitError, RomMismatchError
    from retrokit.testing.movies import check_movies
    from retrokit.testing.scenarios import SMOKE_FRAMES, check_scenarios
    from retrokit.testing.schema import check_schemas
    from retrokit.testing.states import check_states

    def step(stage: str, detail: str = "") -> None:
        if progress is not None:
            progress(stage, detail)

    from retrokit import paths
    from retrokit.data.games import Game, find_game

    game = find_game(game, check=False)  # its data file is checked below, as a step of the report
    made = paths.user_games_dir() / game.name  # where integrate and savestate write: its states are the game's too
    if made.is_dir() and all(made.resolve() != f.resolve() for f in game.folders):
        game = Game(game.name, (*game.folders, made))
    report = GameReport(game.name)

    step("schema")
    check_schemas(game, report)
    step("data file")
    try:
        game.check()
    except RetrokitError as exc:
        report.add("data file", FAIL, str(exc))
        for stage in STAGES[2:]:
            step(stage)
        report.add("game", SKIP, "the data file cannot be read, so nothing else was checked")
        return report
    report.add("data file", PASS, f"{game.info.source.name}: {len(game.fields)} fields, {len(game.states)} states, "
               f"{len(game.scenarios)} scenarios")

    step("ROM")
    rom = game.rom_path()
    if rom is not None:
        report.add("ROM", PASS, f"{rom}")
    else:
        try:
            game.require_rom()
        except RomMismatchError as exc:
            report.add("ROM", FAIL, str(exc))
        except RetrokitError as exc:
            report.add("ROM", SKIP, f"not available, so states were parsed, not loaded, and scenarios not run: {exc}")

    step("fields")
    _check_fields(game, report, rom)
    step("states")
    probes = check_states(game, report, rom)  # and the solution movies' start states
    step("scenarios")
    starts = {name: probe.start for name, probe in probes.items() if probe.start}
    check_scenarios(game, report, starts, rom=rom is not None, frames=frames or SMOKE_FRAMES,
                    progress=lambda detail: step("scenarios", detail))
    step("movies")
    check_movies(game, report, rom)
    return report


def _check_fields(game: Game, report: GameReport, rom: Path | None) -> None:
    from retrokit.data.states import read_state
    from retrokit.errors import RetrokitError
    from retrokit.testing.fields import check_fields
    from retrokit.testing.states import state_space

    if rom is not None:
        from retrokit.host.emulator import Emulator

        try:
            with Emulator(game.system, rom) as emu:
                check_fields(game, report, emu.space, "the core's memory map")
        except RetrokitError as exc:
            report.add("fields in RAM", FAIL, f"the core could not load the ROM: {exc}")
        return
    for name in game.states:  # the RAM a state holds tells its extent
        try:
            space = state_space(game, read_state(game.state_path(name)))
        except RetrokitError:
            continue
        if space is not None:
            size = space.regions[0].length
            check_fields(game, report, space, f"the {size // 1024} KiB of RAM its states hold")
            return
    check_fields(game, report, None)


__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.testing.<module>
