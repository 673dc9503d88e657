"""One level's evaluation, as a stream of messages: the unit every backend runs.

:func:`run_level` makes the level's env, wraps it in a
:class:`~retrokit.benchmark.monitor.Monitor`, and lets the agent play until its
budget is spent. It emits an ``episode`` message per finished episode, then
``done`` (with the level's result) or ``failed`` (with a one-line reason naming
the level and the step). The local processes put the messages on a queue, Ray
tasks on a Ray queue: the evaluation reads them the same way.
"""

from __future__ import annotations

import io
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from retrokit.benchmark.definition import Benchmark, Level
from retrokit.benchmark.monitor import BudgetSpent, Episode, Monitor
from retrokit.errors import AgentError, RetrokitError

#: GIF frame time: a step is 4 frames at 60 frames a second.
GIF_FRAME_MS = 67


@dataclass(frozen=True)
class LevelTask:
    """What a worker needs to evaluate one level."""

    benchmark: Benchmark
    level: Level
    agent: str
    budget: int
    seed: int
    gif: bool = False


@dataclass(frozen=True)
class Message:
    """A worker's report: ``kind`` is ``episode``, ``done`` or ``failed``."""

    kind: str
    level: str
    data: dict[str, Any] = field(default_factory=dict)


def run_level(task: LevelTask, emit: Callable[[Message], None]) -> None:
    """Evaluate ``task``'s agent on its level, emitting messages (see the module's doc)."""
    from retrokit.benchmark.agents import resolve_agent
    from retrokit.envs.env import RetroEnv

    name = task.level.name
    options = task.benchmark.env_options()
    if task.gif:
        options["render_mode"] = "rgb_array"
    try:
        agent = resolve_agent(task.agent)
        env = RetroEnv(task.level.game, task.level.state, options.pop("scenario", None), **options)
    except Exception as exc:  # noqa: BLE001 - any failure to start a level fails that level only
        what = str(exc) if isinstance(exc, RetrokitError) else f"{type(exc).__name__}: {exc}"
        emit(Message("failed", name, {"error": f"Expected to start level {name} (step 0), but: {what}", "timesteps": 0}))
        return

    def on_episode(episode: Episode) -> None:
        emit(Message("episode", name, {
            "level": name, "episode": episode.episode, "steps": episode.steps, "reward": episode.reward,
            "timesteps": episode.timesteps, "wall": episode.wall,
        }))

    monitor = Monitor(env, name, task.budget, task.level.seed(task.seed), on_episode, keep_frames=task.gif)
    try:
        agent(monitor, task.budget, task.level.seed(task.seed))
    except BudgetSpent:
        pass
    except AgentError as exc:
        emit(Message("failed", name, {"error": str(exc), "timesteps": monitor.timesteps}))
        return
    except Exception as exc:  # noqa: BLE001 - the agent is user code: report it, keep the others' results
        where = traceback.extract_tb(exc.__traceback__)[-1]
        emit(Message("failed", name, {
            "error": f"The agent {task.agent!r} raised {type(exc).__name__}: {exc} (level {name}, step "
            f"{monitor.timesteps + 1}, at {where.filename}:{where.lineno}).",
            "timesteps": monitor.timesteps,
        }))
        return
    finally:
        env.close()
    data: dict[str, Any] = {"timesteps": monitor.timesteps}
    if task.gif and monitor.best_frames:
        data["gif"] = encode_gif(monitor.best_frames, GIF_FRAME_MS * monitor.best_stride)
        data["gif_reward"] = monitor.best_reward
    emit(Message("done", name, data))


def encode_gif(frames: list[Any], frame_ms: int) -> bytes:
    """The frames as a looping GIF, ``frame_ms`` milliseconds each."""
    from PIL import Image

    pictures = [Image.fromarray(frame) for frame in frames]
    out = io.BytesIO()
    pictures[0].save(out, "GIF", save_all=True, append_images=pictures[1:], duration=frame_ms, loop=0)
    return out.getvalue()
