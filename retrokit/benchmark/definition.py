"""A benchmark as data: its levels, their train/test split, the env rules and the budget.

Two ship: ``sonic``, the paper's 47 training and 11 test levels with 1M
timesteps each, and ``dasher``, the same protocol on retrokit's own test
cartridge (``dasher.yaml`` beside this module). Users write their own as a
YAML file of the same shape::

    name: mine
    budget: 100000              # timesteps per level
    env: {frameskip: 4, sticky_prob: 0.25, max_episode_steps: 4500, scenario: contest}
    levels:
      train: [Game-System/State, ...]
      test: [Game-System/State, ...]
    learning:                   # optional: what a learning agent (retrokit evaluate --agent ppo) plays
      actions: [[LEFT], [RIGHT], [LEFT, DOWN], [RIGHT, DOWN], [DOWN], [DOWN, B], [B]]
      x: p1_x                   # the field whose episode maximum's increase is the learner's reward

The ``sonic`` benchmark's learning block is the Sonic preset's: its seven
actions, and the contest reward's progress as the x.
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from retrokit.data.yamlfile import load_yaml
from retrokit.errors import (
    BenchmarkFileError,
    RomNotFoundError,
    StateNotFoundError,
    UnknownNameError,
    did_you_mean,
    shown,
)
from retrokit.paths import read_regular_file

# Every benchmark file beside this module is built in, by its name: each cartridge's (dasher.yaml, ...).
BUILTIN_FILES = {path.stem: path for path in sorted(Path(__file__).parent.glob("*.yaml"))}
BUILTINS = (*BUILTIN_FILES, "sonic")
SPLITS = ("test", "train", "all")
#: The RetroEnv options a benchmark may set; the action type defaults to every button.
ENV_OPTIONS = (
    "scenario", "frameskip", "sticky_prob", "max_episode_steps", "scenario_every_frame", "obs_type", "action_type",
)
MAX_FILE_BYTES = 1 << 20  # a benchmark file is a few lines; refuse to parse anything huge
LEARNING_KEYS = ("actions", "x")
MAX_ACTIONS = 64  # a learner's choices: the paper's are 7; a pad's every combination is 4096
MAX_BUTTONS = 16  # buttons of one combination: the most any system has


@dataclass(frozen=True)
class LearningTask:
    """What a learning agent plays on a benchmark: its button combinations and the x its reward follows.

    Attributes:
        actions: The button combinations, one per discrete action (the Sonic preset's seven for ``sonic``).
        x: The game's field that is the player's x: the learner's reward is the increase of the
            episode's maximum x (:class:`~retrokit.envs.sonic.MaxProgress`); ``None``: the episode's reward
            so far stands for it (the Sonic contest's reward is progress).
    """

    actions: tuple[tuple[str, ...], ...]
    x: str | None = None

    def as_dict(self) -> dict[str, Any]:
        """The block as plain data (for ``run.json`` and ``policy.json``)."""
        return {"actions": [list(combo) for combo in self.actions], "x": self.x}

    @classmethod
    def from_data(cls, data: Any) -> LearningTask:
        """Read a ``learning:`` block.

        Raises:
            ValueError: It is not of that shape (the message says how, without the file's name).
        """
        if not isinstance(data, dict):
            raise ValueError(f"'learning' must be a mapping of {' and '.join(LEARNING_KEYS)}, got {type(data).__name__}")  # noqa: TRY004 - bad data
        for key in data:
            if key not in LEARNING_KEYS:
                hint = did_you_mean(str(key), LEARNING_KEYS).strip() or f"known: {', '.join(LEARNING_KEYS)}"
                raise ValueError(f"'learning' has an unknown key {shown(key)} ({hint})")
        actions = data.get("actions")
        if not isinstance(actions, list) or not 1 <= len(actions) <= MAX_ACTIONS:
            raise ValueError(f"'learning.actions' must be a list of 1 to {MAX_ACTIONS} button lists, got {shown(actions)}")
        combos = []
        for i, combo in enumerate(actions):
            if not isinstance(combo, list) or len(combo) > MAX_BUTTONS or not all(isinstance(b, str) for b in combo):
                raise ValueError(f"'learning.actions' item {i + 1} must be a list of button names such as [RIGHT, B], "
                                 f"got {shown(combo)}")
            combos.append(tuple(combo))
        if len(set(map(frozenset, combos))) < len(combos):
            raise ValueError("'learning.actions' lists a combination twice; each action must press other buttons")
        x = data.get("x")
        if x is not None and (not isinstance(x, str) or not x):
            raise ValueError(f"'learning.x' must be the name of a field of the game, got {shown(x)}")
        return cls(tuple(combos), x)


@dataclass(frozen=True, order=True)
class Level:
    """One level: a game and a start state."""

    game: str
    state: str

    @property
    def name(self) -> str:
        """``Game-System/State``, the level's name in every output file."""
        return f"{self.game}/{self.state}"

    @classmethod
    def parse(cls, text: str) -> Level:
        """Read ``Game-System/State``."""
        game, sep, state = str(text).partition("/")
        if not sep or not game or not state:
            raise ValueError(f"Expected a level as 'Game-System/State', got {text!r}.")
        return cls(game, state)

    def seed(self, seed: int) -> int:
        """The level's own seed: from the run's seed and the level's name, so no level depends on another."""
        import numpy as np

        return int(np.random.SeedSequence([seed, zlib.crc32(self.name.encode())]).generate_state(1, np.uint64)[0] >> 1)


@dataclass(frozen=True)
class Benchmark:
    """Levels split into train and test, the env rules, and the timesteps per level.

    Attributes:
        name: The benchmark's name.
        train: The training levels.
        test: The test levels.
        budget: Timesteps per level.
        env: :class:`~retrokit.envs.env.RetroEnv` options (see :data:`ENV_OPTIONS`).
        description: One line.
        learning: The actions and x of a learning agent (``learning:``), if the benchmark has them.
    """

    name: str
    train: tuple[Level, ...]
    test: tuple[Level, ...]
    budget: int
    env: Mapping[str, Any] = field(default_factory=dict)
    description: str = ""
    learning: LearningTask | None = None

    def levels(self) -> tuple[Level, ...]:
        """Every level: the test levels, then the training ones."""
        return self.test + tuple(level for level in self.train if level not in self.test)

    def select(self, spec: str) -> list[Level]:
        """The levels named by ``--levels``: ``test``, ``train``, ``all`` or a comma-separated list.

        A level is named ``Game-System/State`` or, where only one game has it, ``State``.

        Raises:
            UnknownNameError: A name is not one of this benchmark's levels.
        """
        if spec in SPLITS:
            return list({"test": self.test, "train": self.train, "all": self.levels()}[spec])
        known = {level.name: level for level in self.levels()}
        by_state: dict[str, list[Level]] = {}
        for level in self.levels():
            by_state.setdefault(level.state, []).append(level)
        chosen: list[Level] = []
        for name in (part.strip() for part in spec.split(",")):
            if not name:
                continue
            level = known.get(name) or (by_state[name][0] if len(by_state.get(name, ())) == 1 else None)
            if level is None:
                raise UnknownNameError(
                    f"Expected a level of the {self.name} benchmark (test, train, all, or Game-System/State), "
                    f"got {name!r}; see `retrokit evaluate --benchmark {self.name} --list`."
                    + did_you_mean(name, [*known, *by_state])
                )
            if level not in chosen:
                chosen.append(level)
        if not chosen:
            raise UnknownNameError(f"Expected at least one level in --levels, got {spec!r}.")
        return chosen

    def check_levels(self, levels: list[Level]) -> None:
        """Check that every level's game and state exist, and that every ROM is there.

        Raises:
            GameNotFoundError: A game is unknown.
            StateNotFoundError: A game has no such state.
            RomNotFoundError: ROMs are missing; the message names them all and says how to import them.
        """
        from retrokit.data.games import find_game

        missing: list[str] = []
        for game_name in dict.fromkeys(level.game for level in levels):
            game = find_game(game_name)
            for level in levels:
                if level.game == game_name and level.state not in game.states:
                    raise StateNotFoundError(
                        f"Expected the level {level.name} of the {self.name} benchmark to be a state of {game_name}, "
                        f"but it has none of that name." + did_you_mean(level.state, game.states)
                    )
            if self.learning is not None:
                self._check_learning(game)
            if game.rom_path() is None:
                missing.append(game_name)
        if missing:
            raise RomNotFoundError(
                f"Expected the ROMs of the {self.name} benchmark's games, but {len(missing)} are not imported: "
                f"{', '.join(missing)}. Import your copies with `retrokit import PATH...` (a folder or zip holding "
                "them); `retrokit games --imported` lists what is there."
            )

    def _check_learning(self, game: Any) -> None:  # a retrokit.data.games.Game
        """Check the ``learning:`` block against a game: its buttons and its x field must exist.

        Raises:
            UnknownNameError: A button is not one of the game's system's, or the x is not a field of the game.
        """
        from retrokit.host.systems import get_system

        assert self.learning is not None
        system = get_system(game.system)
        names = [b for b in system.buttons if b]
        for combo in self.learning.actions:
            for button in combo:
                if button not in names:
                    raise UnknownNameError(
                        f"Expected the buttons of the {self.name} benchmark's learning.actions to be {game.system} "
                        f"buttons ({', '.join(names)}), got {button!r}; fix the benchmark's learning block."
                        + did_you_mean(button, names)
                    )
        x = self.learning.x
        if x is not None and x not in game.fields:
            raise UnknownNameError(
                f"Expected the {self.name} benchmark's learning.x to be a field of {game.name}, got {x!r}; "
                f"`retrokit games {game.name}` lists its fields." + did_you_mean(x, game.fields)
            )

    def env_options(self) -> dict[str, Any]:
        """The keyword arguments of :class:`~retrokit.envs.env.RetroEnv` for every level."""
        return {"action_type": "all", **self.env}

    def as_dict(self) -> dict[str, Any]:
        """The benchmark as plain data (for ``run.json``)."""
        return {
            "name": self.name,
            "description": self.description,
            "budget": self.budget,
            "env": dict(self.env),
            "levels": {"train": [lv.name for lv in self.train], "test": [lv.name for lv in self.test]},
            **({"learning": self.learning.as_dict()} if self.learning is not None else {}),
        }


def sonic() -> Benchmark:
    """The paper's benchmark, from the Sonic preset: its levels, rules and 1M timesteps per level."""
    from retrokit.envs import sonic as preset

    return Benchmark(
        name="sonic",
        train=tuple(Level(*level) for level in preset.train_levels()),
        test=tuple(Level(*level) for level in preset.test_levels()),
        budget=1_000_000,
        env={
            "scenario": "contest",
            "frameskip": preset.FRAMESKIP,
            "sticky_prob": preset.STICKY_PROB,
            "max_episode_steps": preset.MAX_EPISODE_STEPS,
            "scenario_every_frame": True,
        },
        description="Gotta Learn Fast: 47 training and 11 test levels of Sonic 1, 2 and 3 & Knuckles, 1M timesteps each",
        learning=LearningTask(preset.ACTIONS),
    )


def load_benchmark(name: str | os.PathLike[str]) -> Benchmark:
    """Return a built-in benchmark by name, or read one from a YAML file.

    Raises:
        UnknownNameError: Neither a built-in name nor an existing file.
        BenchmarkFileError: The file is malformed.
    """
    text = str(name)
    if text == "sonic":
        return sonic()
    if text in BUILTIN_FILES:
        return read_benchmark(BUILTIN_FILES[text])
    path = Path(text).expanduser()
    if path.is_file():
        return read_benchmark(path)
    raise UnknownNameError(
        f"Expected a benchmark ({', '.join(BUILTINS)}) or a benchmark YAML file, got {text!r}, which is neither."
        + did_you_mean(text, BUILTINS)
    )


def read_benchmark(path: str | os.PathLike[str]) -> Benchmark:
    """Read and check a benchmark YAML file.

    Raises:
        BenchmarkFileError: The file is unreadable, not YAML, or not of the benchmark shape.
    """
    path = Path(path)

    def fail(problem: str) -> BenchmarkFileError:
        return BenchmarkFileError(f"Expected a benchmark file, but {path}: {problem}. See retrokit docs evaluate for its shape.")

    try:
        # The guarded reader and the YAML reader of every retrokit file: no FIFO, device or alias bomb.
        data = load_yaml(read_regular_file(path, "a benchmark file", MAX_FILE_BYTES).decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise fail(f"cannot be read as YAML ({str(exc).splitlines()[0]})") from None
    return benchmark_from_data(data, fail, path.stem)


def benchmark_from_data(data: Any, fail: Callable[[str], Exception], default_name: str) -> Benchmark:
    """A benchmark from the data of its YAML file, or of a run's ``run.json`` (:meth:`Benchmark.as_dict`), checked.

    Args:
        data: The parsed data.
        fail: Makes the error for a problem (it names the file).
        default_name: The benchmark's name when the data gives none.

    Raises:
        Exception: ``fail``'s error, when the data is not of the benchmark shape.
    """
    if not isinstance(data, dict):
        raise fail(f"holds a {type(data).__name__}, not a mapping")
    unknown = set(data) - {"name", "description", "budget", "env", "levels", "learning"}
    if unknown:
        raise fail(f"has unknown keys {sorted(map(str, unknown))}")
    budget = data.get("budget")
    if not isinstance(budget, int) or isinstance(budget, bool) or budget < 1:
        raise fail(f"'budget' must be a whole number of timesteps of 1 or more, got {budget!r}")
    env = data.get("env") or {}
    if not isinstance(env, dict) or set(env) - set(ENV_OPTIONS):
        bad = sorted(map(str, set(env) - set(ENV_OPTIONS))) if isinstance(env, dict) else env
        raise fail(f"'env' must map options among {', '.join(ENV_OPTIONS)}; got {bad!r}")
    levels = data.get("levels")
    if not isinstance(levels, dict) or set(levels) - {"train", "test"} or not levels.get("test"):
        raise fail("'levels' must map 'test' (and optionally 'train') to lists of Game-System/State")
    split: dict[str, tuple[Level, ...]] = {}
    for key in ("train", "test"):
        names = levels.get(key) or []
        if not isinstance(names, list):
            raise fail(f"'levels.{key}' must be a list, got {type(names).__name__}")
        try:
            split[key] = tuple(dict.fromkeys(Level.parse(n) for n in names))
        except ValueError as exc:
            raise fail(f"'levels.{key}': {exc}") from None
    learning = None
    if data.get("learning") is not None:
        try:
            learning = LearningTask.from_data(data["learning"])
        except ValueError as exc:
            raise fail(str(exc)) from None
    return Benchmark(
        name=str(data.get("name") or default_name),
        train=split["train"],
        test=split["test"],
        budget=budget,
        env=dict(env),
        description=str(data.get("description") or ""),
        learning=learning,
    )
