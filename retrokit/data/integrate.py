"""Making and checking save states from recipes in a game's data file.

A recipe says how to reach a state from power-on: which fields to write (a
level select), which buttons to press, and the field values that mark
arrival. ``retrokit integrate GAME`` makes every state a game's ``game.yaml``
has a recipe for, and checks the ones already there::

    integrate:
      Zone1.Act1:
        set: {zone: 0, act: 0}         # written every frame until arrival
        press: [START]                 # port 1; or {1: [START], 2: [START]}
        until: {game_mode: 1}          # every field equal: arrived
        settle: 0                      # frames to run after arrival
      Level1:
        press: [START]                 # a new game has no fields yet: press START
        frames: 300                    # for 300 frames from power-on, then save
      Start:
        script: _*20 RESET*2           # played once first (ramsearch's script syntax)
        frames: 120                    # frames from power-on, the script's included

States can also be made from a movie: the state a ``.bk2`` reaches at a
frame (:func:`retrokit.movie.playback.state_from_movie`), placed with
:func:`place_state`. The format and the commands are documented in
``docs/integrate.md``.

Made states go to the user's data folder (``<data>/games/<Game>/``, which
extends the shipped game), never into the installed package. A made state is
compared with a state file by the RAM and screen they lead to, never by their
bytes: Genesis Plus GX's states hold host pointers that differ from one
process to the next; a state that is already up to date is not rewritten.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from retrokit import paths
from retrokit.data.games import Game, cached_rom_sha1, list_games
from retrokit.data.names import check_state_name
from retrokit.data.script import parse_script, port_masks
from retrokit.data.statecheck import check_state, load_state, remember_written
from retrokit.data.states import StateRecord, write_state
from retrokit.errors import (
    DataFileError,
    InvalidArgumentError,
    RetrokitError,
    RomNotFoundError,
    StateError,
    StateNotFoundError,
    did_you_mean,
)
from retrokit.host.emulator import Emulator, VettedState

HOLD_FRAMES = 2  # a press is held this long, then released as long, until arrival
CHECK_FRAMES = 60  # frames run from a state to compare two states


@dataclass(frozen=True)
class Recipe:
    """How to reach one state from power-on."""

    name: str
    set: Mapping[str, int] = field(default_factory=dict)
    press: Mapping[int, tuple[str, ...]] = field(default_factory=dict)
    until: Mapping[str, int] = field(default_factory=dict)
    settle: int = 0
    max_frames: int = 3000
    frames: int | None = None  # instead of until: play exactly this many frames
    # played once before the taps of press: each step's masks (one per port) and frames
    script: tuple[tuple[tuple[int, ...], int], ...] = ()


def recipes(game: Game) -> dict[str, Recipe]:
    """Return the game's state recipes, checked against its fields and buttons.

    Raises:
        DataFileError: A recipe is malformed or names an unknown field.
    """
    raw = game.info.extra.get("integrate") or {}
    if not isinstance(raw, Mapping):
        raise DataFileError(
            f"{game.info.source}: expected 'integrate' to map state names to recipes; found {_show(raw)}."
        )
    return {str(name): _recipe(game, str(name), spec) for name, spec in raw.items()}


_RECIPE_KEYS = ("set", "press", "script", "until", "frames", "settle", "max_frames")
MAX_RECIPE_FRAMES = 1_000_000  # about 4.6 hours of play: a recipe that needs more is a mistake


def _recipe(game: Game, name: str, spec: Any) -> Recipe:
    where = f"{game.info.source}: the recipe of state {name!r}"
    if not isinstance(spec, Mapping):
        raise DataFileError(f"{where}: expected a mapping with set, press, and until or frames; found {_show(spec)}.")
    unknown = set(map(str, spec)) - set(_RECIPE_KEYS)
    if unknown:
        key = min(unknown)
        raise DataFileError(
            f"{where}: expected only the keys {', '.join(_RECIPE_KEYS)}; found {key!r}." + did_you_mean(key, _RECIPE_KEYS)
        )
    # A game with no fields yet can only say how long to play: 'frames'; 'until' needs fields to watch.
    if spec.get("until") and "frames" in spec:
        raise DataFileError(
            f"{where}: expected either 'until' (field values that mark arrival) or 'frames' (how long to play); "
            "found both. Keep one."
        )
    if not spec.get("until") and "frames" not in spec:
        raise DataFileError(
            f"{where}: expected 'until', the field values that mark arrival, such as {{game_mode: 1}}, or 'frames', "
            "how many frames to play from power-on, such as 300 (for a game with no fields yet); found neither."
        )
    frames = _count(where, "frames", spec["frames"], 1) if "frames" in spec else None
    script = _script(game, where, spec.get("script"))
    if frames is not None and frames < sum(length for _, length in script):
        raise DataFileError(
            f"{where}: expected frames ({frames}, counted from power-on) to cover its script's "
            f"{sum(length for _, length in script)} frames; found fewer. Raise frames, or shorten the script."
        )
    return Recipe(
        name=name,
        set=_values(game, where, "set", spec.get("set")),
        press=_press(game, where, spec.get("press")),
        script=script,
        until=_values(game, where, "until", spec.get("until")),
        settle=_count(where, "settle", spec.get("settle", 0), 0),
        max_frames=_count(where, "max_frames", spec.get("max_frames", 3000), 1),
        frames=frames,
    )


def _show(value: Any) -> str:
    text = repr(value)
    return f"{type(value).__name__} {text if len(text) <= 60 else text[:57] + '...'}"


def _integer(value: Any) -> int | None:
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return value
    if isinstance(value, str):
        try:
            return int(value, 0)
        except ValueError:
            return None
    return None


def _values(game: Game, where: str, part: str, raw: Any) -> dict[str, int]:
    """``set`` or ``until``: field names to values that fit the field."""
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        raise DataFileError(f"{where}: expected {part!r} to map field names to values, such as {{zone: 0}}; found {_show(raw)}.")
    values = {}
    for key, value in raw.items():
        key = str(key)
        if key not in game.fields:
            raise DataFileError(f"{where}: {part} names no field of the game: {key!r}." + did_you_mean(key, game.fields))
        number = _integer(value)
        if number is None:
            raise DataFileError(f"{where}: expected {part} {key!r} to be an integer; found {_show(value)}.")
        low, high = game.fields[key].field_type.value_range()
        if not low <= number <= high:
            raise DataFileError(
                f"{where}: expected {part} {key!r} to fit its type {game.fields[key].type} ({low} to {high}); found {number}."
            )
        values[key] = number
    return values


def _press(game: Game, where: str, raw: Any) -> dict[int, tuple[str, ...]]:
    """``press``: a list of buttons for port 1, or ports (1, 2, ...) to lists of buttons."""
    if raw is None:
        return {}
    by_port = raw if isinstance(raw, Mapping) else {1: raw}
    system = game.system
    press = {}
    for port, buttons in by_port.items():
        number = _integer(port)
        ports = _ports(game)
        if number is None or not 1 <= number <= ports:
            raise DataFileError(f"{where}: expected press to name ports 1 to {ports}; found {_show(port)}.")
        if not isinstance(buttons, list) or not all(isinstance(b, str) for b in buttons):
            raise DataFileError(
                f"{where}: expected press to list button names, such as [START]; found {_show(buttons)}."
            )
        for button in buttons:
            if button not in system.buttons:
                known = [b for b in system.buttons if b]
                raise DataFileError(
                    f"{where}: expected {system.name} buttons ({', '.join(known)}); found {button!r}."
                    + did_you_mean(button, known)
                )
        press[number] = tuple(buttons)
    return press


def _script(game: Game, where: str, raw: Any) -> tuple[tuple[tuple[int, ...], int], ...]:
    """``script``: inputs played once from power-on, as ``ramsearch run --script`` takes them (``_*20 RESET*2``)."""
    if raw is None:
        return ()
    ports = _ports(game)
    try:
        steps = parse_script(raw, lambda names: port_masks(game.system, ports, names))
    except RetrokitError as exc:
        raise DataFileError(f"{where}: {exc}") from None
    masks: dict[int, tuple[int, ...]] = {}  # by step: a repeated step is one object, its masks one tuple
    for step in steps:
        if id(step) not in masks:
            masks[id(step)] = tuple(port_masks(game.system, ports, step.buttons))
    return tuple((masks[id(step)], step.frames) for step in steps)


def _ports(game: Game) -> int:
    """The controller ports a recipe's emulator has: one per player, and at least two, as an env's."""
    return max(2, game.players)


def _count(where: str, key: str, value: Any, least: int) -> int:
    number = _integer(value)
    if number is None or not least <= number <= MAX_RECIPE_FRAMES:
        raise DataFileError(f"{where}: expected {key} to be a number of frames from {least} to {MAX_RECIPE_FRAMES}; found {_show(value)}.")
    return number


def make_state(game: Game, recipe: Recipe) -> VettedState:
    """Play a recipe from power-on and return the state it reaches.

    An ``until`` recipe plays until its fields hold their values (at most
    ``max_frames``); a ``frames`` recipe plays exactly that many frames. Either
    plays its script first, then taps its buttons (held :data:`HOLD_FRAMES`,
    released as long), then runs ``settle`` idle frames.

    Raises:
        StateError: The recipe did not arrive within its frame budget.
    """
    with Emulator(game.system, game.require_rom(), ports=_ports(game)) as emu:
        reader = game.reader(emu.space)
        masks = [0] * emu.ports
        for port, buttons in recipe.press.items():
            if not 1 <= port <= emu.ports:
                raise InvalidArgumentError(f"Expected ports 1 to {emu.ports} in the recipe of {recipe.name!r}, got {port}.")
            masks[port - 1] = emu.system.mask(buttons)
        values: dict[str, int] = {}
        inputs = _inputs(recipe.script, masks)
        for _ in range(recipe.frames if recipe.frames is not None else recipe.max_frames):
            for name, value in recipe.set.items():
                reader.write(name, value)
            values = reader.read()
            if recipe.until and all(values[k] == v for k, v in recipe.until.items()):
                break
            emu.run(next(inputs), 1)
        else:
            if recipe.frames is None:
                _not_arrived(game, recipe, values)
        emu.run([0] * emu.ports, recipe.settle)
        return emu.get_state()


def _inputs(script: tuple[tuple[tuple[int, ...], int], ...], taps: list[int]) -> Iterator[list[int]]:
    """Each frame's buttons, one mask per port: the script's, once; then ``taps`` held and released in turn.

    A script presses a button for as long as it says: the 2600's RESET, tapped
    all along as press taps START, would restart the game every 4 frames.
    """
    for masks, frames in script:
        for _ in range(frames):
            yield list(masks)
    frame = 0
    while True:
        yield taps if (frame // HOLD_FRAMES) % 2 == 0 else [0] * len(taps)
        frame += 1


def _not_arrived(game: Game, recipe: Recipe, values: Mapping[str, int]) -> None:
    """Raise the error of an ``until`` recipe that did not arrive within ``max_frames``."""
    seen = {k: values.get(k) for k in recipe.until}
    raise StateError(
        f"Expected the recipe of {game.name} state {recipe.name!r} to reach {dict(recipe.until)} within "
        f"{recipe.max_frames} frames; it ended at {seen}. Check its set, press and until in game.yaml."
    )


def fingerprint(game: Game, state: VettedState) -> str:
    """A digest of where a state leads: RAM and screen after some idle frames."""
    with Emulator(game.system, game.require_rom()) as emu:
        emu.set_state(state)
        emu.run([0] * emu.ports, CHECK_FRAMES)
        return hashlib.sha1(np.asarray(emu.ram).tobytes() + emu.screen().tobytes()).hexdigest()


@dataclass
class Outcome:
    """What integrating one state did."""

    name: str
    status: str  # "made", "up to date", "replaced", "differs", "damaged" (unreadable, or crashes the core)
    path: Path


def integrate(
    game: Game, names: list[str] | None = None, *, force: bool = False, out: Path | None = None,
) -> list[Outcome]:
    """Make the game's states from their recipes, and check those already made.

    Args:
        game: The game.
        names: The states to integrate; all with a recipe when ``None``.
        force: Replace a state file that leads somewhere else than its recipe.
        out: The folder to write into; by default :func:`target_folder`.

    Returns:
        One outcome per state. ``"differs"`` means the file was kept although
        it does not match its recipe, ``"damaged"`` that it was kept although it
        is not a state the core can load (rerun with ``force`` to replace either).
    """
    for name in names or []:
        check_state_name(name)
    known = recipes(game)
    shipped = [n for n in names or [] if n not in known and n in game.states]
    if shipped and game.rom_path() is None:  # nothing to make: the state is there, the ROM is what is missing
        raise RomNotFoundError(
            f"Expected {game.name}'s ROM to integrate {', '.join(shipped)}; found the state shipped with the game "
            f"({game.state_path(shipped[0])}) but no ROM. Import the ROM, then the state plays as it is: "
            "retrokit import /path/to/your/roms"
        )
    unknown = [n for n in names or [] if n not in known and n not in game.states]
    if not known and unknown:  # a name that is no state at all: say so first, not that recipes are missing
        states = ", ".join(game.states) or "none"
        raise StateNotFoundError(
            f"Expected a state of {game.name}; found no state {unknown[0]!r} (its states: {states}), and no recipe "
            f"under 'integrate' in {game.info.source} to make one. Make it from a movie: retrokit integrate "
            f"{game.name} {unknown[0]} --movie FILE.bk2, or add a recipe (retrokit docs integrate)."
            + did_you_mean(unknown[0], game.states)
        )
    if not known:
        raise StateNotFoundError(
            f"Expected state recipes under 'integrate' in {game.info.source}; found none. "
            "Add one per state (the format: retrokit docs integrate), or make a state from a movie: "
            f"retrokit integrate {game.name} NAME --movie FILE.bk2."
        )
    wanted = list(known) if names is None else names
    for name in wanted:
        if name not in known:
            raise StateNotFoundError(
                f"Expected a state with a recipe in {game.info.source} ({', '.join(known)}); found {name!r}. "
                "Add its recipe under 'integrate' (retrokit docs integrate)." + did_you_mean(name, known)
            )
    folder = out if out is not None else target_folder(game)
    return [place_state(game, name, make_state(game, known[name]), folder, force=force) for name in wanted]


def place_state(game: Game, name: str, state: bytes, folder: Path, *, force: bool = False) -> Outcome:
    """Write a made state as ``folder/<name>.state`` (with its record) unless an equivalent one is there.

    Returns:
        ``"made"`` (new file), ``"up to date"`` (an equivalent file is there and was left
        alone), ``"replaced"`` (a different or damaged one was replaced: ``force``),
        ``"differs"`` (a different one was kept) or ``"damaged"`` (one that cannot be
        loaded was kept).
    """
    check_state_name(name)  # the name becomes a file name in the game's folder: no '..', '/' or control characters
    if not isinstance(state, VettedState):  # bytes from elsewhere are checked as any state
        state = check_state(game, state, source=f"the state {name} to place")
    record = StateRecord.of(game.name, cached_rom_sha1(game.require_rom(), game.system), state)
    remember_written(game, state)  # this machine wrote it: reading it back needs no probe
    path = folder / f"{name}.state"
    if not path.exists():
        write_state(path, state, record=record)
        return Outcome(name, "made", path)
    try:  # a damaged file is probed in a child first, so it cannot crash this process
        existing = load_state(game, path)
    except StateError:
        existing = None
    if existing is not None and fingerprint(game, existing) == fingerprint(game, state):
        return Outcome(name, "up to date", path)
    if force:
        write_state(path, state, overwrite=True, record=record)
        return Outcome(name, "replaced", path)
    return Outcome(name, "differs" if existing is not None else "damaged", path)


def target_folder(game: Game, data_dir: Path | None = None) -> Path:
    """Where made states of ``game`` go: its folder among the user's, ``<data>/games/<Game>``.

    A game whose only folder is outside every search folder (a game.yaml in the
    current directory) is the user's own: its states go next to its game.yaml.

    Raises:
        PlantedLinkError: ``<data>/games`` or the game's folder there is a symlink (:func:`retrokit.paths.data_path`).
    """
    searched = [d.resolve() for d in paths.game_search_dirs()]
    own = game.folders[0].resolve()
    if len(game.folders) == 1 and own.parent not in searched:
        return game.folders[0]
    return paths.data_path("games", game.name, data=data_dir)


def games_with_state(name: str) -> list[str]:
    """The known games that have a state file or a recipe called ``name``."""
    found = []
    for game in list_games():
        has = any((folder / f"{name}.state").is_file() for folder in game.folders)
        if not has and any((folder / "game.yaml").is_file() for folder in game.folders):
            try:
                has = name in game.state_recipes
            except RetrokitError:  # a broken data file is validate's business, not this search's
                has = False
        if has:
            found.append(game.name)
    return found
