"""The Gymnasium environment: one game, one state, one scenario.

``retrokit.make(game, state, scenario, **options)`` builds a :class:`RetroEnv`.
Each step runs ``frameskip`` frames in one native call (the sticky-action draw
happens natively), reads every RAM field in one more, then evaluates the
scenario's reward and done on those fields. ``info`` holds every field by name,
as in Gym Retro.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from retrokit.data.games import Game, find_game
from retrokit.data.resolve import Resolved, StartState, State, resolve, resolve_state
from retrokit.dsl.resetram import apply_writes, check_writes
from retrokit.envs.actions import ActionMap
from retrokit.envs.buffers import BufferPool
from retrokit.envs.compat import StableRetroCompat
from retrokit.envs.options import OPTIONS, check_crop, check_options, check_seed, make_arguments
from retrokit.envs.pickling import PicklesAsArguments
from retrokit.envs.preprocessing import OBSERVATION_OPTIONS, Preprocessing, preprocessing
from retrokit.envs.starts import check_weights, probabilities
from retrokit.envs.stepper import Stepper, Stepping, step_alone
from retrokit.envs.viewer import render_modes
from retrokit.errors import InvalidArgumentError, StateError, UnknownNameError, did_you_mean
from retrokit.host.emulator import Emulator
from retrokit.host.fields import out_of_range, ranged
from retrokit.host.memory import FieldReader
from retrokit.host.systems import get_system
from retrokit.movie.recorder import EpisodeMovies

__all__ = ["RetroEnv", "State", "make"]


class RetroEnv(StableRetroCompat, PicklesAsArguments, gymnasium.Env):
    """A game as a Gymnasium environment.

    Args:
        game: The game's name, e.g. ``"Airstriker-Genesis"``, a loaded :class:`Game`, or a
            :class:`~retrokit.data.resolve.Resolved` (game, ROM, checked state and scenario found
            once; ``state`` and ``scenario`` are then not given).
        state: A state name, a ``.state`` path, a :class:`State`, or a mapping of state names to
            weights: each reset draws one (seeded by ``reset(seed=...)``).
        scenario: A scenario name of the game, a path to a ``.yaml`` or
            Gym Retro ``.json`` scenario, or ``None`` for the game's default.
        obs_type: ``"rgb"`` (the screen) or ``"ram"`` (the RAM as stable-retro's RAM observations show it).
        action_type: ``"all"``, ``"filtered"``, ``"discrete"`` or ``"multi_discrete"``.
        frameskip: Frames emulated per step.
        sticky_prob: Probability that a step's first frame keeps the previous buttons.
        max_episode_steps: Steps after which an episode is truncated.
        players: Players acting (their actions are concatenated).
        render_mode: ``"rgb_array"`` or ``"human"``.
        record: A folder to record one ``.bk2`` movie per episode into.
        scenario_every_frame: Evaluate the scenario after every frame, summing
            rewards and stopping at the frame it is done, as Gym Retro's
            frame-skip wrappers do. Off, it runs once per step.
        options: Core options overriding the system's defaults.
        skip_video: Tell the core that only a step's last frame is seen (none
            with RAM observations and no render mode), so a core that asks
            skips drawing the rest (``retrokit build-core``); False draws all.
        grayscale, resize, resize_method, crop, frame_stack, channels_first, max_pool: The observation's
            native preprocessing (see :mod:`retrokit.envs.preprocessing`).
        noop_max: At each reset, run a random number of steps from 1 to ``noop_max`` without buttons
            (seeded); 0 runs none.
        reset_frame: At each reset, run one emulator frame without buttons after the start state (and any
            no-ops), as stable-retro's ``reset`` does, so its action sequences replay frame for frame here.
        reward_clip: ``True`` gives the reward's sign, a number ``c`` clips it to ``[-c, c]``.
        info_keys: The fields that ``info`` holds (``[]`` for none, the fastest); ``None`` for all.

    The env pickles as these arguments (see :mod:`retrokit.envs.pickling`):
    unpickled, it is a fresh env made from them, not yet reset; the
    emulator's current state and the episode are not carried over.
    """

    # Each env sets its own: render_fps is its console's frame rate over its frame skip.
    metadata = {"render_modes": render_modes(), "render_fps": 60}

    def __init__(
        self,
        game: str | Game | Resolved,
        state: str | os.PathLike[str] | State | Mapping[str, float] | None = State.DEFAULT,
        scenario: str | os.PathLike[str] | Mapping[str, Any] | None = None,
        *,
        obs_type: str = "rgb",
        action_type: str = "filtered",
        frameskip: int = 1,
        sticky_prob: float = 0.0,
        max_episode_steps: int | None = None,
        players: int = 1,
        render_mode: str | None = None,
        record: str | os.PathLike[str] | None = None,
        scenario_every_frame: bool = False,
        options: Mapping[str, str] | None = None,
        skip_video: bool = True,
        grayscale: bool = False,
        resize: tuple[int, int] | None = None,
        resize_method: str = "area",
        crop: tuple[int, int, int, int] | None = None,
        frame_stack: int = 1,
        channels_first: bool = False,
        max_pool: bool = False,
        noop_max: int = 0,
        reset_frame: bool = False,
        reward_clip: bool | float = False,
        info_keys: list[str] | None = None,
    ) -> None:
        # The keyword options are declared once, by this signature (names and defaults); OPTIONS holds
        # their checks, and a test keeps the two the same. Here they are taken as given, by name.
        given = {name: value for name, value in locals().items() if name in OPTIONS}
        PicklesAsArguments.__init__(self, game, state, scenario, **given)
        checked = check_options(given)  # the same rules as retrokit.make's, whichever way the env is made
        self.noop_max, self.reward_clip = checked["noop_max"], checked["reward_clip"]
        self.reset_frame = checked["reset_frame"]
        frameskip, sticky_prob, players = checked["frameskip"], checked["sticky_prob"], checked["players"]
        max_episode_steps, scenario_every_frame = checked["max_episode_steps"], checked["scenario_every_frame"]
        skip_video, options = checked["skip_video"], checked["options"]
        found = game.game if isinstance(game, Resolved) else find_game(game)
        if players > max(found.players, 1):
            raise InvalidArgumentError(f"Expected 1 to {found.players} players for {found.name}, got {players}.")
        self.info_keys = _check_info_keys(checked["info_keys"], list(found.fields))
        weights = check_weights(state) if isinstance(state, Mapping) and not isinstance(game, Resolved) else None
        # Game, ROM, checked state and scenario are found once, in the data layer.
        first = next(iter(weights)) if weights else state
        setup = game if isinstance(game, Resolved) else resolve(found, first, scenario, players=players)
        self.game: Game = setup.game
        #: Where episodes start, and the chance of each (``None``: always the one).
        self._starts: list[StartState] = [setup.start]
        self._start_odds: np.ndarray | None = None
        if weights and len(weights) > 1:
            self._starts += [resolve_state(self.game, name, players=players) for name in list(weights)[1:]]
            self._start_odds = probabilities(weights)
        self.obs_type, self.frameskip, self.sticky_prob = obs_type, frameskip, float(sticky_prob)
        self.max_episode_steps, self.players, self.render_mode = max_episode_steps, players, render_mode
        self.scenario_every_frame = scenario_every_frame

        self.state_name, self._state = setup.start.name, setup.start.state
        self.movies: EpisodeMovies | None = None
        self.scenario = self._compile_scenario(setup.scenario)
        self._crop = getattr(self.scenario, "crop", None)
        observation = {name: checked[name] for name in OBSERVATION_OPTIONS}
        known_screen = get_system(self.game.system).screen
        self.preprocessing: Preprocessing | None = None
        if known_screen is not None:  # checked before any core is loaded
            self.preprocessing = preprocessing(observation, known_screen, obs_type=obs_type, scenario_crop=self._crop)
        self.emulator = Emulator(self.game.system, setup.rom, options=options, ports=max(players, 2))
        self.reader = self.game.reader(self.emulator.space)
        rate = self.emulator.system.frame_rate(self.emulator.av_info()["fps"])  # the core says NTSC or PAL
        self.metadata = {"render_modes": render_modes(), "render_fps": rate / frameskip}
        self.actions = ActionMap(self.emulator.system, action_type, getattr(self.scenario, "actions", None), players)
        self.action_space = self.actions.space
        self.stepper = Stepper(
            self.emulator,
            self.reader,
            self.actions,
            self.scenario,
            frameskip=frameskip,
            players=players,
            every_frame=scenario_every_frame,
        )
        self._screen_shape = self.emulator.system.screen or self._first_frame_shape()
        check_crop(self._crop, self._screen_shape)
        if known_screen is None:
            self.preprocessing = preprocessing(
                observation, self._screen_shape, obs_type=obs_type, scenario_crop=self._crop
            )
        if self.preprocessing is not None:
            self.emulator.set_preprocess(self.preprocessing.native())
        self.observation_space = self._make_observation_space()
        self._buffers = BufferPool(self.observation_space.shape)
        self._noop = np.zeros(self.emulator.ports, dtype=np.uint16)
        self._info_index = None if self.info_keys is None else [self.reader.names.index(k) for k in self.info_keys]
        self._info_array = np.zeros(len(self._info_index or ()), dtype=np.int64)
        #: The info's fields after a step, as int64s (a vector env copies them into its batch).
        self.info_values = memoryview(self.reader.values if self._info_index is None else self._info_array)
        self._reset_ram = getattr(self.scenario, "reset_ram", None) or {}
        check_writes(self._reset_ram, self.emulator.space)
        if self._reset_ram and record is not None:  # a movie replays from its state, without the writes
            raise InvalidArgumentError(
                "Expected record= without a scenario that writes reset_ram: a movie starts from the state, and "
                "replayed would miss what reset_ram wrote. Record with another scenario."
            )
        self.record_dir = Path(record) if record is not None else None
        if self.record_dir is not None:
            stem = f"{self.game.name}-{self.state_name or 'power-on'}"
            self.movies = EpisodeMovies(
                self.record_dir, stem, self.game.name, self.emulator.system.name, players, self._state
            )
            self.stepper.observers.append(self.movies)
        self._viewer = None
        self._first_obs: np.ndarray | None = None
        self._first_frame: np.ndarray | None = None
        self._at_start = False
        seen = "last" if obs_type == "rgb" or render_mode is not None else "none"
        self.emulator.set_video_frames(seen if skip_video else "all")
        if ranged(self.game.fields.values()):
            # The start state's first frame is emulated once anyway (the first observation): do it now,
            # so that a state whose fields are out of their ranges (another game's) is refused at make().
            try:
                for start in reversed(self._starts):  # the first is the one in use after
                    self._use_start(start)
                    if self._state is not None:
                        self._start()
                        self.emulator.forget_action()
                        self._initial_observation()
            except StateError:
                self.close()
                raise

    @property
    def info_names(self) -> tuple[str, ...]:
        """The fields that ``info`` holds, in :attr:`info_values`' order."""
        return tuple(self.reader.names) if self.info_keys is None else self.info_keys

    def _use_start(self, start: StartState) -> None:
        """Start the next episodes at ``start``; later movies are recorded from it, under its name."""
        if getattr(self, "_state", None) is start.state and getattr(self, "state_name", None) == start.name:
            return
        self.state_name, self._state = start.name, start.state
        self._first_frame = self._first_obs = None  # the first observation is the new state's
        old = self.movies
        if old is not None:
            old.end()
            self.movies = EpisodeMovies(
                old.folder, f"{self.game.name}-{self.state_name or 'power-on'}", self.game.name,
                self.emulator.system.name, self.players, self._state,
            )  # fmt: skip
            self.stepper.observers[self.stepper.observers.index(old)] = self.movies

    @property
    def direct_screen(self) -> bool:
        """Whether an observation is the whole screen, so frames can be converted straight into a buffer of its shape."""
        return self.obs_type == "rgb" and self._crop is None

    # --- set-up -----------------------------------------------------------------------------------

    def _compile_scenario(self, source: Path | Mapping[str, Any] | None) -> Any:
        from retrokit.dsl.scenario import load_scenario

        if source is None:
            return None
        name = "scenario" if isinstance(source, Mapping) else None
        return load_scenario(source, list(self.game.fields), game_dir=self.game.folders[0], name=name)

    def _first_frame_shape(self) -> tuple[int, int]:
        self._start()
        self.emulator.run(0, 1)  # one frame shows the core's screen size
        return self.emulator.screen_shape()

    def _initial_observation(self) -> np.ndarray:
        """What the start state shows: its first frame, emulated once and kept.

        A state holds no picture, and the screen still shows whatever ran
        before, so the frame is made on a scratch run, then the state is
        restored: episodes still start exactly at the state.
        """
        if self._first_frame is None:
            self.emulator.run(0, 1)
            self._check_ranges()
            self._first_frame = self.emulator.screen()
            self._first_obs = self.observe() if self.preprocessing is None else None
            self._start()
            self.emulator.forget_action()
        if self.obs_type == "ram":
            return self.observe()
        if self.preprocessing is not None:  # each episode's stack starts anew
            return self._observe_first(self._first_frame)
        return self._first_obs.copy()  # type: ignore[union-attr]

    def _check_ranges(self) -> None:
        """Refuse a start state whose fields, one frame in, are outside the ranges game.yaml declares.

        Raises:
            StateError: Some field is out of its range: the state is another game's, or broken.
        """
        specs = ranged(self.game.fields.values())
        if not specs or self._state is None:
            return
        wrong = out_of_range(specs, FieldReader(specs, self.emulator.space).read())
        if wrong:
            raise StateError(
                f"Expected the state {self.state_name!r} of {self.game.name} to hold its fields within the ranges "
                f"its game.yaml declares; found, one frame in, {', '.join(wrong)}. The state is another game's or "
                f"broken: pick another, or remake it (retrokit integrate, or ramsearch savestate)."
            )

    def _observe_first(self, frame: np.ndarray | None = None) -> np.ndarray:
        """An episode's first observation, of the last frame or of ``frame``: preprocessed, with the stack filled."""
        if self.preprocessing is None:
            return self.observe()
        return self.emulator.observe(self._buffers.take(), restart=True, frame=frame)

    def _make_observation_space(self) -> spaces.Box:
        if self.preprocessing is not None:
            return self.preprocessing.space()
        if self.obs_type == "ram":
            return spaces.Box(0, 255, (self.emulator.space.ram_size,), np.uint8)
        height, width = self._screen_shape
        if self._crop is not None:
            x, y, w, h = self._crop
            # A width or height of 0 reaches the screen's edge, as in Gym Retro's data files.
            width, height = min(w or width - x, width - x), min(h or height - y, height - y)
        return spaces.Box(0, 255, (height, width, 3), np.uint8)

    def _start(self) -> None:
        """Put the console at the episode's start state."""
        if self._state is None:
            self.emulator.reset()
        else:
            self.emulator.set_state(self._state)

    # --- the Gymnasium API -----------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=check_seed(seed))
        if self._start_odds is not None:
            self._use_start(self._starts[int(self.np_random.choice(len(self._starts), p=self._start_odds))])
        self._start()
        self.emulator.forget_action()
        self.emulator.set_sticky(self.sticky_prob, int(self.np_random.integers(0, 2**63)))
        noops = int(self.np_random.integers(1, self.noop_max + 1)) if self.noop_max else 0
        apply_writes(self._reset_ram, self.emulator.space, self.np_random)  # after the other draws: see resetram
        frames = noops * self.frameskip + self.reset_frame
        if frames:
            self.emulator.run(self._noop, frames)  # one call: only its last frame is drawn
            self.emulator.forget_action()
            values = self.stepper.start()
            obs = self._observe_first()  # the screen the last of those frames drew
        else:
            values = self.stepper.start()
            obs = self._initial_observation()
        self._at_start = not frames
        if self.movies is not None:
            self.movies.start()
            if frames:
                none = (0,) * self.players
                self.movies.frames(none, none, frames)
        if self.info_keys is not None:
            values = {key: values[key] for key in self.info_keys}
        if self.render_mode == "human":
            self.render()
        return obs, values

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        out = self._buffers.take() if self.direct_screen else None
        # What Stepping.step does, without making a Stepping each step.
        return self.finish_step(out if step_alone(self.stepper, self.emulator, action, out) else None)

    @property
    def jump_button(self) -> str | None:
        """The button that jumps in this game (JERK's): the scenario's ``jump``, else the system's."""
        return getattr(self.scenario, "jump", None) or self.emulator.system.jump

    @property
    def stepping(self) -> Stepping | None:
        """This env's steps as a vector env runs them with others' (see :class:`~retrokit.envs.stepper.Stepping`).

        ``None`` for a subclass that overrides :meth:`step`: its steps are its
        own, so a vector env calls them. Made anew on each access, so that the
        env holds no reference to itself.
        """
        if type(self).step is not RetroEnv.step:
            return None
        info = (self.info_names, self.info_values) if self.players == 1 and self.reader.fits_int64 else None
        return Stepping(self.stepper, self.emulator, self.direct_screen, self.finish_step, info)

    def finish_step(self, obs: np.ndarray | None = None) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """End a step once its frames ran (see :func:`~retrokit.envs.stepper.drive`): the step's 5-tuple.

        Args:
            obs: The observation, if the frames were converted straight into
                it (see :attr:`direct_screen`); else it is made here.
        """
        self._at_start = False
        stepper = self.stepper
        rewards, done, values = stepper.rewards, stepper.done, stepper.values
        if obs is None:
            obs = self.observe()
        if self._info_index is not None:
            self._info_array[:] = self.reader.values[self._info_index]
            values = {key: values[key] for key in self.info_keys}  # type: ignore[union-attr]
        truncated = self.max_episode_steps is not None and stepper.steps >= self.max_episode_steps and not done
        if self.players > 1:
            values["rewards"] = rewards
            values["dones"] = stepper.dones
        if (done or truncated) and self.movies is not None:
            self.movies.end()
        if self.render_mode == "human":
            self.render()
        return obs, self._clipped(float(sum(rewards))), done, truncated, values

    def _clipped(self, reward: float) -> float:
        """The reward as ``reward_clip`` says: itself (False), its sign (True), or within ``[-c, c]``."""
        clip = self.reward_clip
        if clip is False:
            return reward
        return float(np.sign(reward)) if clip is True else min(max(reward, -clip), clip)

    def observe(self) -> np.ndarray:
        """The observation now: the screen (cropped as the scenario says, in the fixed shape, or preprocessed) or the RAM."""
        if self.preprocessing is not None:
            return self.emulator.observe(self._buffers.take())
        if self.obs_type == "ram":
            return self.emulator.retro_ram(self._buffers.take())
        if self.emulator.screen_shape() == self._screen_shape and self._crop is None:
            return self.emulator.screen(self._buffers.take())
        frame = self.emulator.screen()
        out = np.zeros(self.observation_space.shape, dtype=np.uint8)
        if self._crop is not None:
            x, y, _, _ = self._crop
            frame = frame[y : y + out.shape[0], x : x + out.shape[1]]
        h, w = min(frame.shape[0], out.shape[0]), min(frame.shape[1], out.shape[1])
        out[:h, :w] = frame[:h, :w]  # the game changed resolution: pad or clip to the fixed space
        return out

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gymnasium.logger.warn("render() was called without a render_mode; pass render_mode='rgb_array' to make().")
            return None
        at_start = self._at_start and self._first_frame is not None
        frame = self._first_frame.copy() if at_start else self.emulator.screen()  # type: ignore[union-attr]
        if self.render_mode == "rgb_array":
            return frame
        if self._viewer is None:
            from retrokit.envs.viewer import Viewer

            self._viewer = Viewer(self.game.name, self.metadata["render_fps"])
        self._viewer.show(frame)
        return None

    def close(self) -> None:
        if self.movies is not None:
            self.movies.end()
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None
        if hasattr(self, "emulator"):
            self.emulator.close()


def _check_info_keys(keys: tuple[str, ...] | None, fields: list[str]) -> tuple[str, ...] | None:
    """Refuse an ``info_keys`` name that is no field of the game, with the closest one.

    Raises:
        UnknownNameError: A name is no field.
    """
    for key in keys or ():
        if key not in fields:
            raise UnknownNameError(
                f"Expected info_keys to name fields of the game ({', '.join(fields) or 'it has none'}), got {key!r}."
                + did_you_mean(key, fields)
            )
    return keys


def make(
    game: str | Game,
    state: str | os.PathLike[str] | State | None = State.DEFAULT,
    scenario: str | os.PathLike[str] | Mapping[str, Any] | None = None,
    **options: Any,
) -> RetroEnv:
    """Make the Gymnasium environment of a game: see :class:`RetroEnv` for the options."""
    return RetroEnv(**make_arguments(game, state, scenario, options))
