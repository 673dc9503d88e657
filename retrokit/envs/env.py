"""The Gymnasium environment: one game, one state, one scenario.

``retrokit.make(game, state, scenario, **options)`` builds a :class:`RetroEnv`.
Each step runs ``frameskip`` frames in one native call (the sticky-action draw
happens natively), reads every RAM field in one more, then evaluates the
scenario's reward and done on those fields. ``info`` holds every field by name,
as in Gym Retro.
"""

from __future__ import annotations

import enum
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from retrokit.data.games import Game, find_game
from retrokit.data.statecheck import load_state
from retrokit.envs.actions import ActionMap
from retrokit.envs.buffers import BufferPool
from retrokit.errors import EnvError, FileConflictError, InvalidArgumentError, did_you_mean
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader

OBS_TYPES = ("rgb", "ram")


class State(enum.Enum):
    """Special start states, as in Gym Retro."""

    DEFAULT = "default"  #: the game's default state
    NONE = "none"  #: power on, no state


class RetroEnv(gymnasium.Env):
    """A game as a Gymnasium environment.

    Args:
        game: The game's name, e.g. ``"Airstriker-Genesis"``.
        state: A state name, a ``.state`` path, or a :class:`State`.
        scenario: A scenario name of the game, a path to a ``.yaml`` or
            Gym Retro ``.json`` scenario, or ``None`` for the game's default.
        obs_type: ``"rgb"`` (the screen) or ``"ram"`` (the system RAM).
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
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 60}

    def __init__(
        self,
        game: str,
        state: str | os.PathLike[str] | State | None = State.DEFAULT,
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
    ) -> None:
        self.game: Game = find_game(game)
        _check_choice("obs_type", obs_type, OBS_TYPES)
        _check_choice("render_mode", render_mode, (None, *self.metadata["render_modes"]))
        if not isinstance(frameskip, int) or frameskip < 1:
            raise InvalidArgumentError(f"Expected frameskip to be a whole number of 1 or more, got {frameskip!r}.")
        if not 0.0 <= sticky_prob <= 1.0:
            raise InvalidArgumentError(f"Expected sticky_prob in [0, 1], got {sticky_prob!r}.")
        if max_episode_steps is not None and max_episode_steps < 1:
            raise InvalidArgumentError(f"Expected max_episode_steps of 1 or more (or None), got {max_episode_steps!r}.")
        if not 1 <= players <= max(self.game.players, 1):
            raise InvalidArgumentError(
                f"Expected 1 to {self.game.players} players for {self.game.name}, got {players}."
            )
        self.obs_type, self.frameskip, self.sticky_prob = obs_type, frameskip, float(sticky_prob)
        self.max_episode_steps, self.players, self.render_mode = max_episode_steps, players, render_mode
        self.scenario_every_frame = scenario_every_frame

        self.state_name, self._state = self._resolve_state(state)
        self.scenario = self._load_scenario(scenario)
        self.emulator = Emulator(self.game.system, self.game.require_rom(), options=options, ports=max(players, 2))
        self._emu = self.emulator._emu  # the native object, for the hot path
        self.reader = FieldReader(self.game.fields, self.emulator.space)
        self.actions = ActionMap(self.emulator.system, action_type, getattr(self.scenario, "actions", None), players)
        self.action_space = self.actions.space
        self._masks = np.zeros(self.emulator.ports, dtype=np.uint16)
        self._crop = getattr(self.scenario, "crop", None)
        self._screen_shape = self.emulator.system.screen or self._first_frame_shape()
        self.observation_space = self._make_observation_space()
        self._buffers = BufferPool(self.observation_space.shape)
        self._direct = obs_type == "rgb" and self._crop is None
        self.record_dir = Path(record) if record is not None else None
        self._recorder = None
        self._run = None
        self._viewer = None
        self._frame = self._steps = 0
        self._first_obs: np.ndarray | None = None
        self._first_frame: np.ndarray | None = None
        self._at_start = False

    # --- set-up -----------------------------------------------------------------------------------

    def _resolve_state(self, state: str | os.PathLike[str] | State | None) -> tuple[str | None, bytes | None]:
        if state is None or state is State.DEFAULT:
            by_players = self.game.default_player_states
            name = by_players[self.players - 1] if len(by_players) >= self.players else self.game.default_state
            return (name, load_state(self.game, self.game.state_path(name))) if name else (None, None)
        if state is State.NONE:
            return None, None
        path = Path(state)
        if path.suffix == ".state" and path.is_file():
            return path.stem, load_state(self.game, path)
        return str(state), load_state(self.game, self.game.state_path(str(state)))

    def _load_scenario(self, scenario: str | os.PathLike[str] | Mapping[str, Any] | None) -> Any:
        from retrokit.dsl.scenario import load_scenario

        fields = list(self.game.fields)
        if isinstance(scenario, Mapping):
            return load_scenario(scenario, fields, game_dir=self.game.folders[0], name="scenario")
        if scenario is None:
            if self.game.default_scenario is None:
                return None
            return load_scenario(self.game.scenario_path(), fields, game_dir=self.game.folders[0])
        path = Path(scenario)
        if path.suffix in (".yaml", ".yml", ".json") and path.is_file():
            return load_scenario(path, fields, game_dir=self.game.folders[0])
        return load_scenario(self.game.scenario_path(str(scenario)), fields, game_dir=self.game.folders[0])

    def _first_frame_shape(self) -> tuple[int, int]:
        self._start()
        self.emulator.run(self._masks, 1)  # one frame shows the core's screen size
        return self.emulator.screen_shape()

    def _initial_observation(self) -> np.ndarray:
        """What the start state shows: its first frame, emulated once and kept.

        A state holds no picture, and the screen still shows whatever ran
        before, so the frame is made on a scratch run, then the state is
        restored: episodes still start exactly at the state.
        """
        if self._first_frame is None:
            self._emu.run(np.zeros_like(self._masks), 1)
            self._first_frame = self.emulator.screen()
            self._first_obs = self._observe()
            self._start()
            self.emulator.forget_action()
        if self.obs_type == "ram":
            return self._observe()
        return self._first_obs.copy()  # type: ignore[union-attr]

    def _make_observation_space(self) -> spaces.Box:
        if self.obs_type == "ram":
            return spaces.Box(0, 255, (len(self.emulator.ram),), np.uint8)
        height, width = self._screen_shape
        if self._crop is not None:
            x, y, w, h = self._crop
            width, height = min(w, width - x), min(h, height - y)
        return spaces.Box(0, 255, (height, width, 3), np.uint8)

    def _start(self) -> None:
        """Put the console at the episode's start state."""
        if self._state is None:
            self.emulator.reset()
        else:
            self.emulator.set_state(self._state)

    # --- the Gymnasium API -----------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        self._start()
        self.emulator.forget_action()
        self.emulator.set_sticky(self.sticky_prob, int(self.np_random.integers(0, 2**63)))
        self._frame = self._steps = 0
        values = self.reader.read()
        obs = self._initial_observation()
        self._at_start = True
        if self.scenario is not None:
            self._run = self.scenario.start()
            self._run.reset(values)
        self._begin_movie()
        if self.render_mode == "human":
            self.render()
        return obs, values

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        before = self.prepare_step(action)
        if self.scenario_every_frame:
            for i in range(self.frameskip):
                before = self.start_frame(i)
                self._emu.run(self._masks, 1)
                if self.end_frame(before):
                    break
            return self.finish_frames()
        if self._direct:  # the host converts the screen right after the frames
            obs = self._buffers.take()
            return self.finish_step(before, obs if self._emu.run(self._masks, self.frameskip, obs) else None)
        self._emu.run(self._masks, self.frameskip)
        return self.finish_step(before)

    # The vector env runs many envs' frames in one native call between these two
    # (or, with the scenario evaluated every frame, one frame at a time between
    # start_frame and end_frame, then finish_frames).

    def prepare_step(self, action: Any) -> tuple[int, ...] | None:
        """Set the buttons for a step's frames; return what a movie needs to know of the last frame."""
        if self._run is None and self.scenario is not None:
            raise EnvError("Expected reset() before the first step(); call env.reset() first.")
        self.actions.write_masks(action, self._masks)
        self._steps += 1
        self._at_start = False
        return self._emu.held() if self._recorder is not None else None

    def finish_step(
        self, before: tuple[int, ...] | None, obs: np.ndarray | None = None
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Account for a step's frames once they ran: fields, scenario, observation."""
        self._frame += self.frameskip
        if before is not None:
            self._record_step(before, self.frameskip)
        values = self.reader.read()
        rewards, done = self._evaluate(values)
        return self._end_step(rewards, done, values, self._observe() if obs is None else obs)

    def _end_step(
        self, rewards: tuple[float, ...], done: bool, values: dict[str, Any], obs: np.ndarray
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        truncated = self.max_episode_steps is not None and self._steps >= self.max_episode_steps and not done
        if self.players > 1:
            values["rewards"] = rewards
        if (done or truncated) and self._recorder is not None:
            self._end_movie()
        if self.render_mode == "human":
            self.render()
        return obs, float(sum(rewards)), done, truncated, values

    def _evaluate(self, values: dict[str, int]) -> tuple[tuple[float, ...], bool]:
        if self._run is None:
            return (0.0,) * self.players, False
        rewards, done = self._run.step(values, self._frame, self._steps)
        return tuple(rewards[: self.players]), bool(done)

    def start_frame(self, i: int) -> tuple[int, ...] | None:
        """Before frame ``i`` of a step whose scenario runs every frame; return what a movie needs."""
        if i == 0:
            self._frame_rewards, self._frame_done, self._frame_values = [0.0] * self.players, False, {}
        before = self._emu.held() if self._recorder is not None else None
        if i > 0:
            self._emu.forget_action()  # only a step's first frame may stick
        return before

    def end_frame(self, before: tuple[int, ...] | None) -> bool:
        """After one frame of such a step: read the fields and add the frame's rewards; return done."""
        self._frame += 1
        if before is not None:
            self._record_step(before, 1)
        values = self._frame_values = self.reader.read()
        rewards, done = self._evaluate(values)
        self._frame_rewards = [t + r for t, r in zip(self._frame_rewards, rewards)]
        self._frame_done = done
        return done

    def finish_frames(self, obs: np.ndarray | None = None) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """End such a step once its frames ran (all of them, or up to the one that ended the episode)."""
        rewards = tuple(self._frame_rewards)
        return self._end_step(rewards, self._frame_done, self._frame_values, self._observe() if obs is None else obs)

    def _observe(self) -> np.ndarray:
        if self.obs_type == "ram":
            out = self._buffers.take()
            out[:] = self.emulator.ram
            return out
        shape = self._emu.screen_shape()
        if shape == self._screen_shape and self._crop is None:
            out = self._buffers.take()
            self._emu.screen(out)
            return out
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
        if self._recorder is not None:
            self._end_movie()
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None
        if hasattr(self, "emulator"):
            self.emulator.close()

    # --- movies ----------------------------------------------------------------------------------

    def _begin_movie(self) -> None:
        if self.record_dir is None:
            return
        from retrokit.movie.recorder import MovieRecorder, claim_movie_path

        if self._recorder is not None:
            self._end_movie()
        self.record_dir.mkdir(parents=True, exist_ok=True)
        self._recorder = MovieRecorder(
            claim_movie_path(self.record_dir, self._movie_stem),
            self.game.name,
            self.emulator.system.name,
            self.players,
            self._state,
        )

    def _record_step(self, before: tuple[int, ...], frames: int) -> None:
        """Record the buttons each frame of the last run really saw."""
        applied = tuple(int(m) for m in self._masks[: self.players])
        first = before[: self.players] if self._emu.stuck else applied
        self._recorder.record(first)
        for _ in range(frames - 1):
            self._recorder.record(applied)

    @property
    def _movie_stem(self) -> str:
        return f"{self.game.name}-{self.state_name or 'power-on'}"

    def _end_movie(self) -> None:
        from retrokit.movie.recorder import claim_movie_path

        recorder, self._recorder = self._recorder, None
        try:
            recorder.close()
        except FileConflictError:  # another process wrote a movie of that name meanwhile
            recorder.path = claim_movie_path(self.record_dir, self._movie_stem)
            recorder.close()


def _check_choice(name: str, value: object, choices: tuple[object, ...]) -> None:
    if value not in choices:
        raise InvalidArgumentError(
            f"Expected {name} to be one of {choices}, got {value!r}."
            + (did_you_mean(value, [c for c in choices if isinstance(c, str)]) if isinstance(value, str) else "")
        )


def make(
    game: str,
    state: str | os.PathLike[str] | State | None = State.DEFAULT,
    scenario: str | os.PathLike[str] | Mapping[str, Any] | None = None,
    **options: Any,
) -> RetroEnv:
    """Make the Gymnasium environment of a game: see :class:`RetroEnv` for the options."""
    return RetroEnv(game, state, scenario, **options)
