"""One level's evaluation, as a stream of typed messages: the unit every backend runs.

:func:`run_level` makes the level's env, wraps it in a
:class:`~retrokit.benchmark.monitor.Monitor`, and lets the agent play until its
budget is spent. A thread emits :class:`Progress` twice a second while the count
of timesteps grows (the watchdog's sign of life, sent also while the agent
itself is stuck), the level an :class:`EpisodeEnded` per finished episode, then
:class:`LevelDone` or :class:`LevelFailed` (with a one-line reason naming the
level and the step). A level is done only when its whole budget was spent
through the monitor: an agent that returns early fails its level. The local
processes send the messages down a pipe, Ray tasks put them on a Ray queue:
the evaluation reads them the same way.
"""

from __future__ import annotations

import io
import os
import threading
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from retrokit.benchmark.definition import Benchmark, Level
from retrokit.benchmark.monitor import BudgetSpent, Episode, Monitor
from retrokit.envs.preprocessing import OBSERVATION_OPTIONS
from retrokit.errors import AgentError, RetrokitError

#: GIF frame time: a step is 4 frames at 60 frames a second.
GIF_FRAME_MS = 67
#: A level reports its timesteps at most this often.
PROGRESS_SECONDS = 0.5


@dataclass(frozen=True)
class LevelTask:
    """What a worker needs to evaluate one level."""

    benchmark: Benchmark
    level: Level
    agent: str
    budget: int
    seed: int
    gif: bool = False
    #: A built-in learning agent's setup (retrokit.learning.setup.LearnerSetup), passed to it as ``setup=``;
    #: its ``observation`` (native preprocessing options only) is added to the level's env.
    setup: Any = None


@dataclass(frozen=True)
class Started:
    """A process has made ``level``'s env and calls its agent now."""

    level: str
    pid: int


@dataclass(frozen=True)
class Progress:
    """``level`` has taken ``timesteps`` so far."""

    level: str
    timesteps: int


@dataclass(frozen=True)
class EpisodeEnded:
    """An episode of ``level`` finished."""

    level: str
    episode: Episode


@dataclass(frozen=True)
class LevelDone:
    """``level`` spent its whole budget through the monitor.

    Attributes:
        level: The level.
        timesteps: Its budget, all spent.
        unfinished_reward: The reward of the episode under way when the budget ran out (it scores a level
            that finished no episode; see :mod:`.scores`).
        gif: The best episode as a GIF, when asked for.
        seconds: How long the agent played (from the env made to the budget spent): the level's speed.
    """

    level: str
    timesteps: int
    unfinished_reward: float
    gif: bytes | None = None
    seconds: float = 0.0


@dataclass(frozen=True)
class LevelFailed:
    """``level`` ended without spending its budget; ``error`` says why, in one line."""

    level: str
    error: str
    timesteps: int


@dataclass(frozen=True)
class LevelRestarted:
    """``level``'s play was lost with the machine playing it, and starts again from its beginning elsewhere.

    Its episodes so far are dropped, as ``--resume`` drops an unfinished level's: the level's result depends only
    on its seed, so the replay ends as an uninterrupted run does.
    """

    level: str
    reason: str


Message = Started | Progress | EpisodeEnded | LevelDone | LevelFailed | LevelRestarted


def run_level(task: LevelTask, emit: Callable[[Message], None]) -> None:
    """Evaluate ``task``'s agent on its level, emitting messages (see the module's doc)."""
    from retrokit.benchmark.agents import resolve_agent
    from retrokit.envs.env import RetroEnv

    name = task.level.name
    options = task.benchmark.env_options()
    if task.setup is not None:  # what the learner sees; the rules (frame skip, sticky, episodes, scenario) stay
        options.update({key: value for key, value in task.setup.observation.items() if key in OBSERVATION_OPTIONS})
    if task.gif:
        options["render_mode"] = "rgb_array"
    try:
        agent = resolve_agent(task.agent)
        env = RetroEnv(task.level.game, task.level.state, options.pop("scenario", None), **options)
    except Exception as exc:  # noqa: BLE001 - any failure to start a level fails that level only
        what = str(exc) if isinstance(exc, RetrokitError) else f"{type(exc).__name__}: {exc}"
        emit(LevelFailed(name, f"Expected to start level {name} (step 0), but: {what}", 0))
        return

    lock = threading.Lock()  # the agent's thread and the progress thread share the channel

    def send(message: Message) -> None:
        with lock:
            emit(message)

    monitor = Monitor(env, name, task.budget, task.level.seed(task.seed), lambda e: send(EpisodeEnded(name, e)),
                      keep_frames=task.gif)
    stop = threading.Event()

    def report_progress() -> None:
        sent = 0
        while not stop.wait(PROGRESS_SECONDS):
            if monitor.timesteps != sent:
                sent = monitor.timesteps
                send(Progress(name, sent))

    reporter = threading.Thread(target=report_progress, name=f"progress of {name}", daemon=True)
    reporter.start()
    send(Started(name, os.getpid()))
    try:
        if task.setup is None:
            agent(monitor, task.budget, task.level.seed(task.seed))
        else:
            agent(monitor, task.budget, task.level.seed(task.seed), setup=task.setup)
    except BudgetSpent:
        pass
    except AgentError as exc:
        emit(LevelFailed(name, str(exc), monitor.timesteps))
        return
    except BaseException as exc:  # noqa: BLE001 - the agent is user code, SystemExit too: report it, keep the rest
        where = traceback.extract_tb(exc.__traceback__)[-1]
        emit(LevelFailed(name, f"The agent {task.agent!r} raised {type(exc).__name__}: {exc} (level {name}, step "
                         f"{monitor.timesteps + 1}, at {where.filename}:{where.lineno}).", monitor.timesteps))
        return
    finally:
        stop.set()
        reporter.join()
        env.close()
    if monitor.timesteps < task.budget:
        emit(LevelFailed(name, (
            f"Expected the agent {task.agent!r} to play level {name} until its budget of {task.budget:,} timesteps "
            f"was spent, but it returned after {monitor.timesteps:,}; an agent loops over reset() and step() of the "
            "env it is given (not env.unwrapped, which the budget does not count) until step() ends its play."),
            monitor.timesteps))
        return
    seconds, gif = monitor.seconds, None
    if task.gif and monitor.best_frames:
        gif = encode_gif(monitor.best_frames, GIF_FRAME_MS * monitor.best_stride)
    emit(LevelDone(name, monitor.timesteps, monitor.unfinished_reward, gif, seconds))


def encode_gif(frames: list, frame_ms: int) -> bytes:  # numpy frames
    """The frames as a looping GIF, ``frame_ms`` milliseconds each."""
    from PIL import Image

    pictures = [Image.fromarray(frame) for frame in frames]
    out = io.BytesIO()
    pictures[0].save(out, "GIF", save_all=True, append_images=pictures[1:], duration=frame_ms, loop=0)
    return out.getvalue()
