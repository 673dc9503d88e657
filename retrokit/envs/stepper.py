"""One episode of one emulator, a step at a time: buttons, frames, fields, scenario.

A step presses the action's buttons, runs ``frameskip`` frames, reads every
RAM field and asks the scenario for the rewards and whether it is done. With
``every_frame`` (as Gym Retro's frame-skip wrappers do, and the Sonic preset)
the frames run one at a time, the scenario is asked after each, the rewards
add up, and the step stops at the frame that ends the episode.

:class:`Stepper` holds that logic once. It does not run frames itself: it
says how many to run next (:meth:`Stepper.prepare`) and takes over once they
ran (:meth:`Stepper.ran`), so that :func:`drive`, the one frame loop, can run
one env's frames (``RetroEnv``) or many envs' in one native call (the vector
env) with the same steps. Whoever wants to see each frame's buttons (a movie
recorder) registers as an observer.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from retrokit.envs.actions import ActionMap
from retrokit.errors import EnvError
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader


class FrameObserver(Protocol):
    """Sees the buttons of every frame a stepper runs."""

    def frames(self, first: tuple[int, ...], applied: tuple[int, ...], count: int) -> None:
        """``count`` frames ran: the first held ``first`` (a sticky draw may keep the last ones), the rest ``applied``."""


class Stepper:
    """The steps of one emulator's episodes.

    Args:
        emulator: The console.
        reader: Its game's fields.
        actions: How an action becomes button masks.
        scenario: The compiled scenario, or ``None`` for no rewards and no end.
        frameskip: Frames a step runs.
        players: Players acting; a step has one reward each.
        every_frame: Ask the scenario after every frame, not once a step.
    """

    def __init__(
        self,
        emulator: Emulator,
        reader: FieldReader,
        actions: ActionMap,
        scenario: Any,
        *,
        frameskip: int,
        players: int,
        every_frame: bool,
    ) -> None:
        self.emulator, self.reader, self.actions, self.scenario = emulator, reader, actions, scenario
        self.frameskip, self.players, self.every_frame = frameskip, players, every_frame
        #: The buttons of the step's frames, one mask per port.
        self.masks = np.zeros(emulator.ports, dtype=np.uint16)
        self.observers: list[FrameObserver] = []
        #: Frames and steps since the episode began.
        self.frame = self.steps = 0
        #: The step's outcome once its frames ran: one reward per player, done, the last fields read.
        self.rewards: tuple[float, ...] = (0.0,) * players
        self.done = False
        self.values: dict[str, int] = {}
        self._chunk = 1 if every_frame else frameskip
        self._left = 0
        self._run: Any = None  # the scenario's state for this episode
        self._before: tuple[int, ...] = ()

    @property
    def dones(self) -> tuple[bool, ...]:
        """Each player's own done condition after the last step (a scenario's ``dones:``), all False without."""
        return tuple(self._run.dones[: self.players]) if self._run is not None else (False,) * self.players

    def use_masks(self, row: np.ndarray) -> None:
        """Write the buttons into ``row`` from now on: a vector env's shared array, read by its runner."""
        row[:] = self.masks
        self.masks = row

    def start(self) -> dict[str, int]:
        """Begin an episode at the emulator's current state (the start state); return its fields."""
        self.frame = self.steps = 0
        self._left = 0
        values = self.reader.read()
        if self.scenario is not None:
            self._run = self.scenario.start()
            self._run.reset(values)
        return values

    def begin(self, action: Any) -> None:
        """Begin a step: press the action's buttons. :func:`drive` then runs its frames."""
        if self._run is None and self.scenario is not None:
            raise EnvError("Expected reset() before the first step(); call env.reset() first.")
        self.actions.write_masks(action, self.masks)
        self.steps += 1
        self._left = self.frameskip
        self.done = False

    @property
    def going(self) -> bool:
        """Whether the begun step has frames left to run."""
        return self._left > 0

    @property
    def after(self) -> int:
        """Frames of the step planned after the next ones: 0 when they are its last (unless the episode ends before)."""
        return self._left - self._chunk

    def prepare(self) -> int:
        """Before the step's next frames run: return how many to run (0 once the step is over)."""
        if self._left == 0:
            return 0
        if self._left < self.frameskip:
            self.emulator.forget_action()  # only a step's first frame may stick
        if self.observers:
            self._before = self.emulator.held()
        return self._chunk

    def ran(self) -> None:
        """After the frames :meth:`prepare` asked for ran: tell observers, read the fields, ask the scenario."""
        count = self._chunk
        first_frames = self._left == self.frameskip
        self._left -= count
        self.frame += count
        if self.observers:
            players = self.players
            applied = tuple(int(m) for m in self.masks[:players])
            first = self._before[:players] if self.emulator.stuck else applied
            for observer in self.observers:
                observer.frames(first, applied, count)
        values = self.values = self.reader.read()
        if self._run is None:
            rewards, done = (0.0,) * self.players, False
        else:
            got, done = self._run.step(values, self.frame, self.steps)
            rewards = tuple(got[: self.players])
        self.rewards = rewards if first_frames else tuple(t + r for t, r in zip(self.rewards, rewards))
        if done:
            self.done = True
            self._left = 0


#: A step's outcome, as ``gymnasium.Env.step`` returns it: observation, reward, terminated, truncated, info.
StepResult = tuple[Any, float, bool, bool, dict[str, Any]]


@dataclass(frozen=True)
class Stepping:
    """How an env's steps run together with other envs': the one stepping interface of env and vector env.

    An env offers one (``RetroEnv.stepping``). Alone, it runs its step's
    frames with :func:`step_alone` and ends it with :attr:`finish`; a vector
    env whose envs all offer one of the same :attr:`kind` begins every env's
    step (``stepper.begin``), runs all their frames in one native call per
    :func:`drive` round, and ends each with :attr:`finish`.

    Attributes:
        stepper: The env's episode logic.
        emulator: Its console.
        direct_screen: Whether an observation is the whole screen, so the last
            frame can be converted straight into a buffer of the observation's shape.
        finish: Ends a step once its frames ran: given the observation if the
            frames were converted straight into it (else ``None``), returns the step's 5-tuple.
        info: The names of the fields a step's info holds, and a view of
            their values (int64, in that order) as of the last step, when the
            info is exactly these; ``None`` when it holds more (several
            players) or values that do not fit int64.
    """

    stepper: Stepper
    emulator: Emulator
    direct_screen: bool
    finish: Callable[[np.ndarray | None], StepResult]
    info: tuple[tuple[str, ...], memoryview] | None

    @property
    def kind(self) -> tuple[int, int, bool]:
        """Envs can share native calls when this is the same: frame skip, ports, scenario every frame."""
        return self.stepper.frameskip, self.emulator.ports, self.stepper.every_frame


def step_alone(stepper: Stepper, emulator: Emulator, action: Any, out: np.ndarray | None) -> bool:
    """Run one env's step's frames on its own emulator; return whether its screen was converted into ``out``."""
    stepper.begin(action)
    run = emulator.run

    def frames(live: list[int], count: int, after: int) -> tuple[bool | None]:
        return (run(stepper.masks, count, None if after else out, after),)

    return drive((stepper,), frames)[0]


#: ``run(live, frames, after)``: run ``frames`` frames of the steppers at indices ``live``, ``after`` more
#: of the step planned past them, converting their screens if ``after`` is 0 (the step's last frames);
#: return, per index, whether its screen was converted.
RunFrames = Callable[[list[int], int, int], Sequence[Any]]


def drive(steppers: Sequence[Stepper], run: RunFrames) -> list[bool]:
    """Run every stepper's begun step to its end: the frame loop of every env.

    All steppers must have the same frameskip and ``every_frame``. A stepper
    whose episode ends on a frame runs no more frames this step; screens are
    converted with the planned last frames.

    Returns:
        Per stepper, whether its screen was converted by ``run``.
    """
    converted = [False] * len(steppers)
    live = [i for i, s in enumerate(steppers) if s.going]
    while live:
        frames = 0
        for i in live:
            frames = steppers[i].prepare()
        after = steppers[live[0]].after
        last = after == 0
        done = run(live, frames, after)
        for k, i in enumerate(live):
            steppers[i].ran()
            if last:
                converted[i] = bool(done[k])
        live = [i for i in live if steppers[i].going]
    return converted
