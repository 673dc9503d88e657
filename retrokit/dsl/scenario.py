"""Scenarios: the rewards and done condition of an environment.

A scenario is written in retrokit's expression language (``docs/scenarios.md``)
in a YAML file, or comes from a Gym Retro ``scenario.json``. Loading compiles
it once into a :class:`Scenario`; each episode runs in a :class:`Run`::

    scenario = load_scenario("games/SonicTheHedgehog-Genesis/contest.yaml", fields)
    run = scenario.start()
    run.reset(values)                         # field values after reset
    rewards, done = run.step(values, frame, step)

``values`` maps every field name to its value; ``frame`` counts emulator frames
and ``step`` env steps since reset.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from retrokit.dsl.compiler import Program
from retrokit.dsl.document import DocumentLoader, document_from_dict, load_document, plain_scenario_dict
from retrokit.dsl.gymretro import is_gym_retro, spec_from_json, spec_from_json_dict
from retrokit.dsl.spec import ScenarioSpec
from retrokit.errors import InvalidArgumentError, ScenarioError, shown

__all__ = ["Run", "Scenario", "load_scenario", "scenario_from_text"]


class Scenario:
    """A compiled scenario. Immutable; start one :class:`Run` per episode stream.

    Attributes:
        name: The scenario's name (the file's stem unless it says otherwise).
        players: How many rewards each step returns.
        actions: Gym Retro-style button combinations (a list of groups, each a
            list of button-name lists), or ``None``.
        crop: ``(x, y, width, height)`` of the screen to keep, or ``None``.
        fields: The fields the scenario reads.
        jump: The button JERK jumps with in this game, or ``None`` for the system's.
        reset_ram: What an env writes into RAM at each reset: by address, ``(type, lowest, highest)``.
    """

    def __init__(self, spec: ScenarioSpec, fields: Sequence[str]) -> None:
        self._program = Program(spec, fields)
        self.name = spec.name
        self.players = self._program.players
        self.actions = spec.actions
        self.jump = spec.jump
        self.crop = spec.crop
        self.reset_ram = dict(spec.reset_ram)
        self.fields = self._program.fields

    @property
    def source(self) -> str:
        """The Python code the scenario was compiled to."""
        return self._program.source

    def start(self) -> Run:
        """Return fresh per-episode state; Runs of one Scenario are independent."""
        return Run(self._program)

    def __repr__(self) -> str:
        return f"Scenario({self.name!r}, players={self.players})"


class Run:
    """One stream of episodes of a scenario: its memory (``prev``, ``initial``, ...).

    ``reset`` starts an episode. ``step`` returns ``(rewards, done)``: a tuple of
    ``players`` floats, and a bool; :attr:`dones` then holds each player's own
    done condition (a scenario's ``dones:``), which ``done`` includes once all
    hold. Stepping without a reset treats the first step as the reset point
    (``initial(x)`` is then the first step's value).
    """

    def __init__(self, program: Program) -> None:
        self._state: list = [None] * program.slot_count
        #: Each player's done condition after the last step (``dones:``); all False without one.
        self.dones: list[bool] = [False] * program.players
        self._first, self._next = program.bind(self._state, self.dones)
        # The hot path: after reset, ``run.step`` is the generated function itself.
        self.step = self._step_before_reset  # type: ignore[method-assign]

    def reset(self, values: Mapping[str, int]) -> None:
        """Start an episode from the field values after the emulator's reset.

        Like Gym Retro, which computes reward and done once at reset, this runs
        the scenario once with ``frame = step = 0`` and keeps only its memory.
        """
        self._first(values, 0, 0)
        self.step = self._next  # type: ignore[method-assign]

    def step(self, values: Mapping[str, int], frame: int, step: int) -> tuple[tuple[float, ...], bool]:
        """Compute this step's rewards (one per player) and done.

        Args:
            values: Every field's value after the step.
            frame: Emulator frames since reset.
            step: Env steps since reset.

        Returns:
            ``(rewards, done)``.

        Raises:
            ScenarioRuntimeError: A division by zero, or a table has no entry for a key.
        """
        # Each instance replaces this method with the generated function; this is for Run.step(run, ...).
        return self.__dict__["step"](values, frame, step)

    def _step_before_reset(self, values: Mapping[str, int], frame: int, step: int) -> tuple[tuple[float, ...], bool]:
        result = self._first(values, frame, step)
        self.step = self._next  # type: ignore[method-assign]
        return result


def load_scenario(
    source: str | os.PathLike[str] | Mapping,
    fields: Sequence[str],
    *,
    game_dir: str | os.PathLike[str] | None = None,
    name: str | None = None,
) -> Scenario:
    """Load and compile a scenario.

    Args:
        source: A ``.yaml`` file in retrokit's scenario language, a Gym Retro
            ``.json`` scenario file, or an already-parsed dict of either format
            (Gym Retro's is recognised by its ``variables`` objects).
        fields: The names of the game's RAM fields, for checking names.
        game_dir: Where ``include`` files of a dict source are looked up.
        name: The scenario's name in messages; default: the file's stem.

    Returns:
        The compiled scenario.

    Raises:
        ScenarioSyntaxError: An expression does not parse.
        ScenarioCompileError: An unknown name, a wrong argument count, a type
            error or a division by a constant zero.
        ScenarioError: The file is malformed or cannot be read.
        InvalidArgumentError: ``source`` is neither a path nor a dict.
    """
    if isinstance(source, Mapping):
        data = plain_scenario_dict(source, name or "scenario")  # first: a dict containing itself stops here
        if is_gym_retro(data):
            spec = spec_from_json_dict(data, fields, name=name or "scenario")
        else:
            spec = document_from_dict(data, name=name, game_dir=game_dir)
        return Scenario(spec, fields)
    if not isinstance(source, (str, os.PathLike)):
        raise InvalidArgumentError(
            f"Expected a scenario file's path or a scenario dict, got {shown(source)} ({type(source).__name__})."
        )
    path = Path(source)
    suffix = path.suffix.lower()
    if suffix == ".json":
        spec = spec_from_json(path, fields, name=name)
    elif suffix in (".yaml", ".yml"):
        spec = load_document(path, name=name)
    else:
        raise ScenarioError(f"{str(path)!r}: a scenario is a .yaml file (retrokit) or a .json file (Gym Retro); got {suffix or 'no suffix'!r}")
    return Scenario(spec, fields)


def scenario_from_text(
    text: str,
    fields: Sequence[str],
    *,
    source: str,
    name: str,
    game_dir: str | os.PathLike[str] | None = None,
    resolve_include: Callable[[Path, str], Path] | None = None,
) -> Scenario:
    """Compile scenario YAML given as text, such as an editor's unsaved buffer.

    It is read exactly as the file ``source`` would be: its errors name
    ``source`` and carry the same ``line`` and ``column`` attributes.

    Args:
        text: The scenario, in retrokit's YAML format.
        fields: The names of the game's RAM fields.
        source: What the text's errors call it, e.g. the path it will be saved to.
        name: The scenario's name unless the text gives one (``name:``).
        game_dir: Where its ``include`` files are looked up.
        resolve_include: Turns an ``include`` entry and the including file's folder into a path, raising a
            :class:`~retrokit.errors.RetrokitError` for one it refuses (by default: the folder / the entry).

    Raises:
        ScenarioError: The text is too large, or malformed (and its subclasses, as :func:`load_scenario`).
    """
    from retrokit.data.yamlfile import MAX_YAML_BYTES

    if not isinstance(text, str):
        raise InvalidArgumentError(f"Expected a scenario as text, got {type(text).__name__}.")
    if len(text) > MAX_YAML_BYTES:
        raise ScenarioError(
            f"{source}: expected a scenario of at most {MAX_YAML_BYTES >> 20} MiB; got {len(text):,} characters."
        )
    loader = DocumentLoader(name, resolve_include=resolve_include)
    loader.load_text(text.removeprefix("\ufeff"), source, Path(game_dir) if game_dir is not None else None)
    return Scenario(loader.spec, fields)
