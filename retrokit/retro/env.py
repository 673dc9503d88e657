"""stable-retro's ``RetroEnv`` and ``make``, by its arguments and behaviours, over retrokit's env.

The env is :class:`retrokit.envs.env.RetroEnv` (the same resolver, checked states,
scenario and native steps), made with stable-retro's arguments and doing what
stable-retro's does where the two differ:

- ``reset()`` runs one frame without buttons after the start state (``reset_frame=True``);
- from power-on (``State.NONE``, or a game without a default state) nothing presses the
  console's reset: the console is as the core loaded it, two frames in at ``make`` (stable-retro's
  emulator runs one as it loads the game, its env one more), and a ``reset()`` goes on from where
  the console is, as stable-retro's does;
- with ``players=2`` the reward is a list, one per player (``env.multi_rewards = False``
  gives stable-retro 1.0.1's default, the first player's reward);
- ``render_mode`` defaults to ``"human"``, and its window, as stable-retro's, shows frames as fast as they come.
"""

from __future__ import annotations

import inspect
import os
from pathlib import Path
from typing import Any

import numpy as np

from retrokit.data.resolve import StartState
from retrokit.data.resolve import State as BaseState
from retrokit.envs.env import RetroEnv as BaseEnv
from retrokit.envs.options import OPTIONS
from retrokit.envs.pickling import PicklesAsArguments
from retrokit.errors import InvalidArgumentError
from retrokit.movie.recorder import EpisodeMovies
from retrokit.retro.data import Integrations
from retrokit.retro.emulator import EmulatorFace
from retrokit.retro.enums import ACTION_TYPES, OBS_TYPES, Actions, Observations, State
from retrokit.retro.gamedata import GameData
from retrokit.retro.movie import open_recorder

__all__ = ["POWER_ON_FRAMES", "RetroEnv", "make"]

#: Frames stable-retro has run when its env is made: one as its emulator loads the game, one in the env's constructor.
POWER_ON_FRAMES = 2


class RetroEnv(BaseEnv):
    """A game as stable-retro's ``RetroEnv`` makes it (its arguments, in its order).

    Args:
        game: The game's name (``"Airstriker-Genesis"`` or stable-retro's ``"Airstriker-Genesis-v0"``).
        state: ``State.DEFAULT``, ``State.NONE`` (power-on), a state's name or a ``.state`` path.
        scenario: A scenario's name or a ``.json`` (or retrokit ``.yaml``) path; ``None``: the game's.
        info: The game's data file: ``None`` or ``"data"`` (the game folder's own).
        use_restricted_actions: An :class:`Actions` value.
        record: ``True`` (the current folder), a folder, or ``False``: one ``.bk2`` per episode.
        players: Players acting.
        inttype: An :class:`~retrokit.retro.data.Integrations` value (retrokit finds a game in any folder).
        obs_type: An :class:`Observations` value.
        render_mode: ``"human"`` (the default, as stable-retro's), ``"rgb_array"`` or ``None``.
    """

    def __init__(
        self,
        game: str,
        state: State | BaseState | str | os.PathLike[str] | None = State.DEFAULT,
        scenario: str | os.PathLike[str] | None = None,
        info: str | os.PathLike[str] | None = None,
        use_restricted_actions: Actions = Actions.FILTERED,
        record: bool | str | os.PathLike[str] = False,
        players: int = 1,
        inttype: Integrations = Integrations.STABLE,
        obs_type: Observations = Observations.IMAGE,
        render_mode: str | None = "human",
    ) -> None:
        action_type = _member(use_restricted_actions, ACTION_TYPES, "use_restricted_actions", "Actions.FILTERED")
        observation = _member(obs_type, OBS_TYPES, "obs_type", "Observations.IMAGE")
        if not isinstance(inttype, Integrations):
            raise InvalidArgumentError(
                f"Expected inttype to be a retrokit.retro.data.Integrations value; got {inttype!r}. "
                "Pass retro.data.Integrations.ALL, or leave it out (retrokit finds a game in every folder)."
            )
        folder = Path.cwd() if record is True else None if record in (False, None) else Path(record)  # type: ignore[arg-type]
        super().__init__(
            game, _start(state), scenario, obs_type=observation, action_type=action_type, players=players,
            render_mode=render_mode, record=folder, reset_frame=True,
        )  # fmt: skip
        _check_info(info, self.game.folders)
        # It pickles as stable-retro's arguments, so a copy is this class again.
        PicklesAsArguments.__init__(
            self, game, state, scenario, info, use_restricted_actions, record, players, inttype, obs_type, render_mode
        )
        self.gamename = game
        self.use_restricted_actions = use_restricted_actions
        self.multi_rewards = True
        self.em = EmulatorFace(self.emulator, self.game)
        self.data = GameData(self)
        self._one: EpisodeMovies | None = None  # the movie record_movie() started
        if self._state is None and self.emulator.frame < POWER_ON_FRAMES:
            # From power-on the console is where stable-retro's is at make: its emulator runs a frame when it loads
            # the game, and its env one more (the base env may have run one to learn the screen's size).
            self.emulator.run(self._noop, POWER_ON_FRAMES - self.emulator.frame)

    # --- stable-retro's attributes ------------------------------------------------------------

    @property
    def system(self) -> str:
        """The console's name, as stable-retro's (``"Genesis"``, ``"Nes"``)."""
        return self.emulator.system.name

    @property
    def num_buttons(self) -> int:
        """How many buttons an action of ``Actions.ALL`` has per player."""
        return len(self.buttons)

    @property
    def statename(self) -> str | None:
        """The start state's file name (``Level1.state``), ``None`` from power-on."""
        return f"{self.state_name}.state" if self.state_name else None

    @property
    def initial_state(self) -> bytes | None:
        """The state each ``reset()`` starts from (uncompressed bytes), ``None`` from power-on."""
        return self._state

    @initial_state.setter
    def initial_state(self, state: bytes | None) -> None:
        # Bytes from elsewhere (a movie's, a file's) go through the checked load before any reset uses them.
        if not state:
            self._use_start(StartState(None, None))
            return
        checked = self.em.checked(state, "the state given to env.initial_state")
        self._use_start(StartState(self.state_name or "initial_state", checked))

    def load_state(self, statename: str | os.PathLike[str], inttype: Integrations = Integrations.DEFAULT) -> None:
        """Start the next episodes at a state of the game (a name, with or without ``.state``, or a path)."""
        super().load_state(statename)

    def set_value(self, name: str, val: int) -> None:
        """Write a field's value into the RAM."""
        self.data.set_value(name, val)

    def get_screen(self, player: int = 0, apply_rotation: bool = False) -> np.ndarray:
        """The screen now, cropped as the scenario says."""
        frame = self.emulator.screen()
        if self._crop is None:
            return frame
        x, y, w, h = self._crop
        return frame[y : y + h if h else None, x : x + w if w else None]

    def render(self) -> np.ndarray | None:
        if self.render_mode == "human" and self._viewer is None:
            from retrokit.envs.viewer import Viewer

            # stable-retro's window shows each frame as soon as it is made, at no frame rate (retrokit's keeps the game's).
            self._viewer = Viewer(self.game.name, 0)
        return super().render()

    # --- stepping -----------------------------------------------------------------------------

    def _start(self) -> None:
        # From power-on, stable-retro's reset restores nothing and presses no reset: the console goes on.
        if self._state is not None:
            super()._start()

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = super().reset(seed=seed, options=options)
        if self._one is not None:  # stable-retro's movie holds the frame reset ran, as record= movies do
            none = (0,) * self.players
            self._one.frames(none, none, 1)
        return obs, info

    def step(self, action: Any) -> tuple[np.ndarray, Any, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = super().step(action)
        if self.players > 1:
            rewards = [float(r) for r in self.stepper.rewards]
            return obs, rewards if self.multi_rewards else rewards[0], terminated, truncated, info
        return obs, reward, terminated, truncated, info

    # --- movies -------------------------------------------------------------------------------

    def record_movie(self, path: str | os.PathLike[str]) -> None:
        """Record the frames from now on into the movie ``path``, from the start state, until :meth:`stop_record`.

        Raises:
            FileConflictError: A file this process did not record is at ``path``.
        """
        self._end_one()
        one = EpisodeMovies(Path(path).parent, Path(path).stem, self.game.name, self.system, self.players, self._state)
        one.recorder = open_recorder(path, self.game.name, self.players, self._state)
        self._one = one
        self.stepper.observers.append(one)

    def stop_record(self) -> None:
        """Write and end the movie :meth:`record_movie` began, and stop recording episodes (``record=``)."""
        self._end_one()
        if self.movies is not None:
            self.movies.end()
            self.stepper.observers.remove(self.movies)
            self.movies = self.record_dir = None

    def auto_record(self, path: str | os.PathLike[str] | None = None) -> None:
        """Record each episode from the next ``reset()`` into a movie of its own in ``path`` (the current folder)."""
        self.stop_record()
        self.record_dir = Path(path) if path else Path.cwd()
        stem = f"{self.game.name}-{self.state_name or 'power-on'}"
        self.movies = EpisodeMovies(self.record_dir, stem, self.game.name, self.system, self.players, self._state)
        self.stepper.observers.append(self.movies)

    def _end_one(self) -> None:
        if self._one is not None:
            self._one.end()
            self.stepper.observers.remove(self._one)
            self._one = None

    def close(self) -> None:
        if hasattr(self, "stepper"):
            self._end_one()
        super().close()


def _member(value: Any, names: dict[Any, str], argument: str, example: str) -> str:
    """retrokit's name for one of stable-retro's enum values.

    Raises:
        InvalidArgumentError: ``value`` is no member of that enum.
    """
    if value in names:
        return names[value]
    kind = type(next(iter(names))).__name__
    raise InvalidArgumentError(
        f"Expected {argument} to be retro.{kind}.<member> ({', '.join(m.name for m in names)}); got {value!r}. "
        f"Pass e.g. retro.{example}."
    )


def _start(state: Any) -> Any:
    """retrokit's start state for stable-retro's ``state`` argument."""
    if state is State.DEFAULT:
        return BaseState.DEFAULT
    if state is State.NONE or state is None:
        return BaseState.NONE
    return state


def _check_info(info: Any, folders: tuple[Path, ...]) -> None:
    """Accept ``info`` only where it names the game's own data file, which retrokit reads.

    Raises:
        InvalidArgumentError: It names another file.
    """
    if info is None or info == "data":
        return
    path = Path(info)
    if path.suffix == ".json" and path.is_file() and any(path.resolve() == (f / "data.json").resolve() for f in folders):
        return
    raise InvalidArgumentError(
        f"Expected info to be None or 'data' (the game's own data.json or game.yaml); got {info!r}. retrokit reads a "
        "game's fields from its folder: copy the folder with that file as data.json and make that game instead."
    )


_STABLE_RETRO_ARGUMENTS = set(inspect.signature(RetroEnv.__init__).parameters)


def make(
    game: str,
    state: State | BaseState | str | os.PathLike[str] | None = State.DEFAULT,
    inttype: Integrations = Integrations.DEFAULT,
    **kwargs: Any,
) -> RetroEnv:
    """Make the env of a game, as ``stable_retro.make``: see :class:`RetroEnv` for the arguments.

    Raises:
        InvalidArgumentError: An argument is retrokit's (``frameskip``, ...), not stable-retro's.
        GameNotFoundError, RomNotFoundError, StateNotFoundError, StateError: As ``retrokit.make``.
    """
    ours = sorted(name for name in kwargs if name in OPTIONS and name not in _STABLE_RETRO_ARGUMENTS)
    if ours:
        raise InvalidArgumentError(
            f"Expected stable-retro's arguments in retrokit.retro.make; got retrokit's {', '.join(ours)}. "
            f"Use retrokit.make({game!r}, ..., {ours[0]}=...) for them."
        )
    return RetroEnv(game, state, inttype=inttype, **kwargs)
