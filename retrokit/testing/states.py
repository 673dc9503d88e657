"""Checking a game's save states: each loads, is the game's own, and its fields decode.

States are loaded in the crash probe's child process (:mod:`retrokit.data.probe`),
so that a corrupt state that crashes or hangs the core costs one result, not
the run: the parent sees the child die or time out, blames the state it was
on, and starts a new child for the rest.

Without the ROM no core can load a state; the files are then parsed: the
gzip stream, the core's signature and, where the layout is known
(:func:`retrokit.data.states.state_ram`), the fields read from the RAM inside.

A state is flagged as not the game's own when retrokit recorded it on another
ROM (:class:`~retrokit.data.states.StateRecord`), when it is a copy of another
game's state file, when it does not reach what its recipe in ``game.yaml``
(``integrate``) says it should (the recipe's ``set`` and ``until`` values), or
when, one frame in, a field is outside the ``range`` game.yaml declares for it:
that is how another game's state is caught however it was copied (re-gzipped,
or saved on the other game's ROM by a tool that records nothing). The start
states of the solution movies are checked the same way.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from retrokit.data.games import Game, list_games
from retrokit.data.probe import ChildResult
from retrokit.data.states import read_state, state_format, state_ram
from retrokit.errors import RetrokitError
from retrokit.testing.report import FAIL, PASS, SKIP, WARN, GameReport

if TYPE_CHECKING:
    from retrokit.host.memory import AddressSpace

__all__ = ["IDLE_FRAMES", "StateProbe", "check_states", "parse_states", "probe_states", "state_space"]

IDLE_FRAMES = 60  # frames run after loading a state the probe vouches for already (others run the probe's)


@dataclass
class StateProbe(ChildResult):
    """What loading (or parsing) one state showed: the probe child's result (see
    :class:`~retrokit.data.probe.ChildResult` for the values), or what a state's file alone tells.

    Attributes:
        parsed_only: No core was run: the values come from the file.
    """

    parsed_only: bool = False


# --- Parent side ---------------------------------------------------------------------------------


def probe_states(
    game: Game, names: Sequence[str], rom: Path, *, frames: int = IDLE_FRAMES, files: Mapping[str, Path] | None = None,
) -> dict[str, StateProbe]:
    """Load each state in a child process with the game's ROM; return what each showed.

    Each state goes through the crash probe (:func:`retrokit.data.probe.probe_files`),
    the one rule by which any state loads: a state this machine vouches for
    (shipped, or probed here before) is loaded and run ``frames`` idle frames;
    any other is probed as ``make()`` would probe it, and its verdict kept, so
    validate never passes a state that ``make()`` then refuses. A child that
    dies or hangs fails the state it was on, and a new child carries on.
    """
    from retrokit.data.games import cached_rom_sha1
    from retrokit.data.probe import probe_files

    paths = {name: files[name] if files is not None else game.state_path(name) for name in names}
    fields = [{"name": f.name, "address": f.address, "type": f.type, "mask": f.mask} for f in game.fields.values()]
    rom_sha1 = cached_rom_sha1(rom, game.system)
    done = probe_files(game.system.name, rom, rom_sha1, paths, frames=frames, fields=fields)
    return {name: StateProbe(**vars(done[name])) for name in names}


def state_space(game: Game, data: bytes) -> AddressSpace | None:
    """The console addresses of the RAM inside a serialized state, where its layout is known (else ``None``)."""
    from retrokit.host.memory import AddressSpace, Region

    ram = state_ram(data, game.system.name)
    if ram is None:
        return None
    return AddressSpace([Region(game.system.ram_base, len(ram), memoryview(bytearray(ram)), game.system.ram_swap)])


def parse_states(game: Game, names: Sequence[str]) -> dict[str, StateProbe]:
    """Parse each state file without a core: gzip, signature, and the fields where the RAM layout is known."""
    from retrokit.host.memory import FieldReader

    probes = {}
    for name in names:
        path = game.state_path(name)
        probe = StateProbe(name, str(path), parsed_only=True)
        probes[name] = probe
        try:
            data = read_state(path)
        except RetrokitError as exc:
            probe.error = str(exc)
            continue
        probe.detail = f"{state_format(data) or 'no core signature'}, {len(data)} bytes"
        space = state_space(game, data)
        if space is None:
            continue
        mapped = [f for f in game.fields.values() if space.holds(f.address, f.field_type.width)]
        probe.start = FieldReader(mapped, space).read()
    return probes


# --- Results -----------------------------------------------------------------------------------------


_MOVIE = "movies/"  # before a movie's start state's label among the states probed: no state file's name holds a "/"


def check_states(game: Game, report: GameReport, rom: Path | None) -> dict[str, StateProbe]:
    """Check every state of the game, and each solution movie's start state as one of its states (it loads, and its
    fields are in range); add the results to ``report``; return the probes of the game's states that loaded.

    With the ROM, one child loads them all (a child of their own cost the movies' start states a second start).
    """
    import tempfile

    _check_default(game, report)
    names = []
    for name in game.states:
        try:
            game.state_path(name)
            names.append(name)
        except RetrokitError as exc:
            report.add("state file", FAIL, str(exc), state=name)
    if rom is None:  # nothing loads: the states are parsed, and movies' start states are left alone
        movies, probes = {}, parse_states(game, names)
    else:
        with tempfile.TemporaryDirectory(prefix="retrokit-movie-states-") as scratch:
            movies = _movie_state_files(game, Path(scratch))
            files = {name: game.state_path(name) for name in names}
            files |= {_MOVIE + label: path for label, path in movies.items()}
            probes = probe_states(game, list(files), rom, files=files)
    good = _check_loaded(game, report, rom, names, {name: probes[name] for name in names})
    _check_movie_states(game, report, {label: probes[_MOVIE + label] for label in movies})
    return good


def _check_loaded(
    game: Game, report: GameReport, rom: Path | None, names: list[str], probes: dict[str, StateProbe],
) -> dict[str, StateProbe]:
    """Report what loading (or parsing) each state showed; return the probes of those that loaded."""
    if not names:
        report.add("states", WARN if game.state_recipes else SKIP, "the game has no state files")
        return {}
    if rom is None:
        report.add("state loads", SKIP, f"{len(names)} state{'s' * (len(names) != 1)} parsed, not loaded: "
                   "no ROM to load them with (import it: retrokit import /path/to/roms)")
    copies = _copies_elsewhere(game, names)
    recipes = game.state_recipes
    good = {}
    for name, probe in probes.items():
        if probe.error:
            report.add("state loads" if rom is not None else "state parses", FAIL, probe.error, state=name)
            continue
        if rom is None:
            report.add("state parses", PASS, probe.detail, state=name)
        else:
            report.add("state loads", PASS, "loaded and ran in a child process (the crash probe)", state=name)
        foreign = _recorded_elsewhere(game, Path(probe.path))
        if foreign:
            report.add("state is the game's", FAIL, foreign, state=name)
            continue
        if name in copies:
            report.add("state is the game's", FAIL,
                       f"expected a state made with {game.name}'s ROM; found a copy of {copies[name]}. "
                       "Replace the file with one made for this game (retrokit integrate, or retrokit play).",
                       state=name)
            continue
        if name in recipes and probe.start and _expected_values(recipes[name]):
            mismatch = _recipe_mismatch(recipes[name], probe.start)
            if mismatch:
                report.add("state is the game's", FAIL,
                           f"expected the values its recipe in game.yaml reaches ({mismatch[0]}); found {mismatch[1]}: "
                           "the file is another state's, another game's, or made with another ROM. "
                           f"Remake it: retrokit integrate {game.name} {name} (add --force to replace it).",
                           state=name)
                continue
            report.add("state is the game's", PASS, f"reaches its recipe's {_recipe_text(recipes[name])}", state=name)
        else:
            report.add("state is the game's", PASS, "not a copy of another game's state (no recipe values to compare with)",
                       state=name)
        if not check_ranges(game, report, probe, name):
            continue
        if probe.start:
            report.add("fields decode", PASS, f"{len(probe.start)} fields: " + _sample(probe.start), state=name)
        elif game.fields:
            report.add("fields decode", SKIP, "the RAM layout of this core's states is not known without the ROM",
                       state=name)
        good[name] = probe
    return good


def _check_default(game: Game, report: GameReport) -> None:
    """Flag a default state (``states: default:``, or one per player count) that names no state file."""
    defaults = [name for name in (game.default_state, *game.default_player_states) if name]
    for name in dict.fromkeys(defaults):
        try:
            path = game.state_path(name)
        except RetrokitError as exc:
            report.add("default state", FAIL, f"game.yaml's default names no state file: {exc}", state=name)
            continue
        report.add("default state", PASS, f"{path}", state=name)


def check_ranges(game: Game, report: GameReport, probe: StateProbe, label: str) -> bool:
    """Report whether the state's fields, one frame in, are within their declared ranges; return whether they are.

    A parsed state (no ROM) is judged by the values in its file.
    """
    from retrokit.host.fields import out_of_range, ranged

    specs = ranged(game.fields.values())
    values = probe.first or probe.start
    if not specs or not values:
        return True
    wrong = out_of_range(specs, values)
    when = "one frame in" if probe.first else "in the file"
    if wrong:
        report.add("fields in range", FAIL,
                   f"expected every field within the range game.yaml declares; found, {when}, {', '.join(wrong)}: "
                   "the state is another game's, made with another ROM, or broken. Replace it with one made for "
                   f"this game (retrokit integrate {game.name} NAME, or ramsearch savestate).", state=label)
        return False
    checked = [s.name for s in specs if s.name in values]
    report.add("fields in range", PASS, f"{len(checked)} ranged fields {when}: " + _sample({k: values[k] for k in checked}),
               state=label)
    return True


def _movie_state_files(game: Game, scratch: Path) -> dict[str, Path]:
    """Write the start state of each solution movie that has one into ``scratch``; return the files by label."""
    from retrokit.data.states import write_state
    from retrokit.movie import read_bk2
    from retrokit.testing.movies import movie_files

    files = {}
    for name, path in movie_files(game).items():
        try:
            state = read_bk2(path).state
        except RetrokitError:  # the movies stage says why it cannot be read
            continue
        if state is None:  # a movie from power-on: nothing to check
            continue
        label = f"{path.name} start"
        files[label] = scratch / f"{name}.state"
        write_state(files[label], state)
    return files


def _check_movie_states(game: Game, report: GameReport, probes: Mapping[str, StateProbe]) -> None:
    """Report what loading each solution movie's start state showed."""
    for label, probe in probes.items():
        if probe.error:
            report.add("movie start state", FAIL, probe.error, state=label)
        else:
            report.add("movie start state", PASS, "loaded and ran in a child process (the crash probe)", state=label)
            check_ranges(game, report, probe, label)


def _recorded_elsewhere(game: Game, path: Path) -> str:
    """Why a state is another ROM's (by the record in its file, or by the one rule of what states are known), or ``""``."""
    from retrokit.data.statecheck import check_identity
    from retrokit.data.states import read_state_file
    from retrokit.errors import StateError

    try:
        state = read_state_file(path)
    except RetrokitError:
        return ""  # an unreadable file already failed to load
    record = state.record
    if record is None or not game.sha1s or record.rom_sha1 in game.sha1s:
        try:  # the check make(state=...) applies: a state this machine wrote, or the wheel shipped, for another game
            check_identity(game, state.data, "", str(path), path)
        except StateError as exc:
            return str(exc)
        return ""
    of = f" (a state of {record.game})" if record.game != game.name else ""
    return (f"expected a state made with {game.name}'s ROM ({', '.join(game.sha1s)}); found one retrokit recorded "
            f"on the ROM with SHA-1 {record.rom_sha1}{of}. Remake it with this game's ROM.")


def _sample(values: Mapping[str, int], limit: int = 6) -> str:
    shown = ", ".join(f"{k}={v}" for k, v in list(values.items())[:limit])
    return shown + (", ..." if len(values) > limit else "")


def _expected_values(recipe: Any) -> dict[str, int]:
    if not isinstance(recipe, Mapping):
        return {}
    expected: dict[str, int] = {}
    # After arrival a recipe may run more frames ('settle'): then only what it set must still hold.
    parts = ("set", "until") if not recipe.get("settle") else ("set",)
    for part in parts:
        values = recipe.get(part)
        if isinstance(values, Mapping):
            expected.update({str(k): v for k, v in values.items() if isinstance(v, int)})
    return expected


def _recipe_text(recipe: Any) -> str:
    """The values a recipe reaches, as ``zone=0, act=1, game_mode=1``."""
    return ", ".join(f"{k}={v}" for k, v in _expected_values(recipe).items())


def _recipe_mismatch(recipe: Any, values: Mapping[str, int]) -> tuple[str, str] | None:
    expected = {k: v for k, v in _expected_values(recipe).items() if k in values}
    wrong = {k: v for k, v in expected.items() if values[k] != v}
    if not wrong:
        return None
    return (", ".join(f"{k}={v}" for k, v in wrong.items()), ", ".join(f"{k}={values[k]}" for k in wrong))


_state_index: dict[tuple[str, ...], dict[int, list[tuple[str, Path]]]] = {}


def _copies_elsewhere(game: Game, names: Sequence[str]) -> dict[str, str]:
    """States of ``game`` whose file is byte for byte another game's state: name -> "Game's State"."""
    games = list_games()
    key = tuple(sorted(g.name for g in games))
    if key not in _state_index:
        by_size: dict[int, list[tuple[str, Path]]] = {}
        for other in games:
            for folder in other.folders:
                try:
                    entries = list(os.scandir(folder))
                except OSError:
                    continue
                for entry in entries:
                    if entry.name.endswith(".state") and _is_file(entry):
                        by_size.setdefault(entry.stat().st_size, []).append((other.name, Path(entry.path)))
        _state_index.clear()
        _state_index[key] = by_size
    by_size = _state_index[key]
    found = {}
    for name in names:
        path = game.state_path(name)
        if not path.is_file():  # a FIFO, a device or a loop: its own check says so
            continue
        size = path.stat().st_size
        others = [(g, p) for g, p in by_size.get(size, []) if g != game.name]
        if not others:
            continue
        digest = _sha1(path)
        for other, other_path in others:
            if _sha1(other_path) == digest:
                found[name] = f"{other}'s state {other_path.name[: -len('.state')]} ({other_path})"
                break
    return found


def _is_file(entry: os.DirEntry[str]) -> bool:
    try:
        return entry.is_file()
    except OSError:  # a symlink loop is no state file
        return False


def _sha1(path: Path) -> str:
    from retrokit.data.states import MAX_STATE_FILE_SIZE
    from retrokit.paths import read_regular_file

    return hashlib.sha1(read_regular_file(path, "a save state file", MAX_STATE_FILE_SIZE)).hexdigest()


