"""``retrokit train``'s run folder: settings, lock, checkpoints, the learning curve and the policy.

The folder (``--out DIR``) holds:

- ``run.json``: the settings (benchmark, levels, agent, config, timesteps, seed, start policy) and the last
  checkpoint: its timesteps, its episodes, and its files in ``checkpoint/`` with their digests;
- ``checkpoint/``: the weights and the library's training state (the optimizer's) of the last checkpoint;
- ``curve.csv``: one line per finished training episode (the benchmark's reward), and ``curve.png``;
- ``policy.json`` and its weights: the policy (:mod:`.policy`), which ``retrokit evaluate --init DIR`` reads.

A checkpoint is written every ``--checkpoint-every`` seconds and at the end:
its files under new names first, then ``run.json`` naming them (the atomic
step), then the older files removed, then the policy. ``--resume`` continues
a killed run from the checkpoint ``run.json`` names, with the same settings
only; the curve's episodes after it are dropped, since the run plays them
again. A run holds the folder's lock (:func:`~retrokit.benchmark.rundir.lock_folder`,
the evaluation's) for its lifetime.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
import math
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from retrokit.benchmark.definition import Benchmark, Level
from retrokit.benchmark.monitor import Episode
from retrokit.benchmark.rundir import LOCK_FILE, check_same_settings, claim_folder, unlock_folder
from retrokit.errors import FileSystemError, RunFolderError
from retrokit.learning import DEFAULT_CHECKPOINT_SECONDS
from retrokit.learning.config import AgentConfig
from retrokit.learning.policy import MAX_WEIGHTS_BYTES, SavedPolicy, write_policy
from retrokit.learning.task import learning_task
from retrokit.paths import atomic_write, ensure_folder, read_regular_file

RUN_FILE = "run.json"
CURVE_FILE = "curve.csv"
CURVE_PLOT = "curve.png"
CHECKPOINT_DIR = "checkpoint"
OUTPUTS = (RUN_FILE, CURVE_FILE, CURVE_PLOT, "policy.json", CHECKPOINT_DIR)
CURVE_COLUMNS = ("timesteps", "level", "episode", "steps", "reward", "wall")
MAX_RUN_FILE_BYTES = 1 << 20
MAX_CURVE_BYTES = 32 << 20  # about 50 bytes an episode: 600,000 episodes, and read back whole in far under 500 MB


@dataclass(frozen=True)
class Training:
    """What one ``retrokit train`` run is asked to do.

    Attributes:
        benchmark: The benchmark.
        levels: The levels to train on (its training levels by default).
        agent: The learning agent.
        config: Its checked config.
        timesteps: Timesteps to train for, over all levels.
        seed: The run's seed.
        init: A policy to start from, if any.
        backend: ``local`` (this machine's processes) or ``ray`` (RLlib's env runners on a Ray cluster).
        env_runners: With ``ray``, the env runners (a multiple of the levels; see :mod:`.raytrain`).
    """

    benchmark: Benchmark
    levels: tuple[Level, ...]
    agent: str
    config: AgentConfig
    timesteps: int
    seed: int = 0
    init: SavedPolicy | None = None
    backend: str = "local"
    env_runners: int | None = None

    def settings(self) -> dict[str, Any]:
        """What determines the run, for ``run.json``; ``--resume`` requires the same."""
        return {
            "benchmark": self.benchmark.as_dict(),
            "levels": [level.name for level in self.levels],
            "agent": self.agent,
            "config": self.config.as_dict(),
            "timesteps": self.timesteps,
            "seed": self.seed,
            "init": None if self.init is None else {"policy": str(self.init.path.resolve()), "weights_sha256": self.init.sha256},
            # the library that trains differs with the backend (RLlib's PPO is not SB3's): a resume keeps it
            "backend": self.backend,
            "env_runners": self.env_runners,
        }


class TrainRun:
    """A training run's folder, locked while this object is open; what an algorithm reports its training to.

    Args:
        out: The folder.
        training: What to train.
        resume: Continue the run the folder holds (same settings).
        progress: Show progress: a bar on a terminal, else a line per update.
        checkpoint_seconds: Seconds between checkpoints (0: after every update).

    Raises:
        FileConflictError: Without ``resume``, the folder holds a run already.
        RunFolderError: With ``resume``, it holds none, a damaged one, or one with other settings; or another
            run is using it.
    """

    def __init__(self, out: Path, training: Training, *, resume: bool, progress: bool = True,
                 checkpoint_seconds: float = DEFAULT_CHECKPOINT_SECONDS) -> None:
        self.path, self.training = Path(out), training
        self.task = learning_task(training.benchmark)
        self.settings = training.settings()
        self.checkpoint: dict[str, Any] | None = None
        self.episodes: dict[str, list[Episode]] = {level.name: [] for level in training.levels}
        self.timesteps = 0  # trained so far (at the last update)
        self.checkpoint_seconds = checkpoint_seconds
        self._level_steps = dict.fromkeys(self.episodes, 0)
        self._started = self._saved_at = time.monotonic()
        self._bar = None
        self._lock = claim_folder(self.path, OUTPUTS, "training run", resume=resume)
        try:
            if resume:
                self._load()
            else:
                self._save_run()
                atomic_write(self.path / CURVE_FILE, (",".join(CURVE_COLUMNS) + "\n").encode(), overwrite=True)
            self._curve = open(self.path / CURVE_FILE, "a", encoding="utf-8", newline="")  # noqa: SIM115 - for the run
        except BaseException:
            unlock_folder(self.path / LOCK_FILE, self._lock)
            raise
        self._writer = csv.writer(self._curve)
        if progress:
            self._open_progress()

    # --- what the algorithm calls -----------------------------------------------------------------

    def episode(self, level: str, reward: float, steps: int, timesteps: int | None = None) -> None:
        """Record a finished training episode of ``level`` (its benchmark reward and length), at ``timesteps``
        of the run (by default those of the last update)."""
        self._level_steps[level] += steps
        episode = Episode(len(self.episodes[level]) + 1, steps, reward, self._level_steps[level],
                          round(time.monotonic() - self._started, 3))
        self.episodes[level].append(episode)
        self._writer.writerow([self.timesteps if timesteps is None else timesteps, level, episode.episode, steps, f"{reward:.6g}", episode.wall])
        self._curve.flush()

    def resume_state(self) -> tuple[bytes, bytes] | None:
        """The last checkpoint's weights and training state (checked against ``run.json``), or ``None``.

        Raises:
            RunFolderError: A file is missing or not the one ``run.json`` names.
        """
        if self.checkpoint is None:
            return None
        return self._read_checkpoint_file("weights"), self._read_checkpoint_file("state")

    def updated(self, timesteps: int) -> bool:
        """Note an update at ``timesteps`` (trained so far); return whether a checkpoint is due now."""
        self.timesteps = timesteps
        self._show()
        return time.monotonic() - self._saved_at >= self.checkpoint_seconds

    def save(self, timesteps: int, weights: bytes, state: bytes, observation: Mapping[str, Any], library: str) -> None:
        """Write a checkpoint at ``timesteps`` and the policy (see the module's doc).

        Args:
            timesteps: Timesteps trained.
            weights: The library's weights file (a ``torch.save`` of the network's ``state_dict``).
            state: The library's training state (the optimizer's), to resume.
            observation: ``{"shape", "dtype", "options"}`` of what the policy sees.
            library: The library and its version.
        """
        self.timesteps = timesteps
        folder = ensure_folder(self.path / CHECKPOINT_DIR, "for the checkpoints")
        files = {}
        for kind, data in (("weights", weights), ("state", state)):
            digest = hashlib.sha256(data).hexdigest()
            name = f"{kind}-{timesteps:012d}-{digest[:8]}.pt"
            atomic_write(folder / name, data, overwrite=True)
            files[kind] = {"file": name, "bytes": len(data), "sha256": digest}
        self._curve.flush()
        self.checkpoint = {"timesteps": timesteps, "episodes": {k: len(v) for k, v in self.episodes.items()},
                           "level_steps": dict(self._level_steps), **files}
        self._save_run()
        keep = {entry["file"] for entry in files.values()}
        for old in folder.glob("*.pt"):
            if old.name not in keep:
                old.unlink(missing_ok=True)
        training = self.training
        write_policy(self.path, {
            "agent": training.agent, "library": library, "config": training.config.as_dict(),
            "actions": [list(combo) for combo in self.task.actions], "x": self.task.x,
            "observation": {key: list(value) if isinstance(value, tuple) else value for key, value in observation.items()},
            "benchmark": training.benchmark.name, "timesteps": timesteps,
        }, weights)  # fmt: skip
        self._saved_at = time.monotonic()

    def finish(self) -> None:
        """Draw the learning curve (``curve.png``); the last checkpoint is already saved."""
        from retrokit.benchmark import plots

        per_level = max(1, self.training.timesteps // max(1, len(self.training.levels)))
        title = f"{self.training.agent} trained on {self.training.benchmark.name}: episode reward against timesteps"
        atomic_write(self.path / CURVE_PLOT, plots.learning_curves(self.episodes, per_level, title), overwrite=True)

    def close(self) -> None:
        """Close the curve and the progress, and release the folder."""
        if self._bar is not None:
            self._bar.close()
        self._curve.close()
        unlock_folder(self.path / LOCK_FILE, self._lock)

    # --- the folder ---------------------------------------------------------------------------------

    def _save_run(self) -> None:
        data = {"settings": self.settings, "checkpoint": self.checkpoint}
        atomic_write(self.path / RUN_FILE, (json.dumps(data, indent=1) + "\n").encode(), overwrite=True)

    def _damaged(self, name: str, problem: str) -> RunFolderError:
        return RunFolderError(
            f"Expected a readable {self.path / name} to resume, but {problem}; the folder is damaged: "
            "start in a new --out."
        )

    def _load(self) -> None:
        try:
            raw = read_regular_file(self.path / RUN_FILE, "a training run's run.json", MAX_RUN_FILE_BYTES)
            saved = json.loads(raw.decode("utf-8"))
        except FileSystemError as exc:
            raise RunFolderError(str(exc)) from None
        except (UnicodeDecodeError, ValueError, RecursionError) as exc:
            raise self._damaged(RUN_FILE, f"it is not JSON ({type(exc).__name__})") from None
        if not isinstance(saved, dict) or not isinstance(saved.get("settings"), dict) or "checkpoint" not in saved:
            raise self._damaged(RUN_FILE, "it does not map 'settings' and 'checkpoint'")
        # a run.json written before the backend was a setting is a local run's
        settings = {"backend": "local", "env_runners": None, **saved["settings"]}
        check_same_settings(self.path, settings, self.settings)
        checkpoint = saved["checkpoint"]
        if checkpoint is not None:
            problem = _checkpoint_problem(checkpoint, self.episodes, self.training.timesteps)
            if problem:
                raise self._damaged(RUN_FILE, problem)
            self.checkpoint = checkpoint
            self.timesteps = checkpoint["timesteps"]
            self._level_steps = dict(checkpoint["level_steps"])
        self._read_curve()

    def _read_curve(self) -> None:
        """Read back the curve's episodes up to the checkpoint; drop the later ones (the run plays them again)."""
        keep = self.checkpoint["episodes"] if self.checkpoint else dict.fromkeys(self.episodes, 0)
        try:
            raw = read_regular_file(self.path / CURVE_FILE, "a training run's curve.csv", MAX_CURVE_BYTES)
        except FileSystemError as exc:
            raise RunFolderError(str(exc)) from None
        lines = raw.decode("utf-8", "replace").splitlines()
        if not lines or lines[0] != ",".join(CURVE_COLUMNS):
            raise self._damaged(CURVE_FILE, "its first line is not its header")
        kept = [lines[0]]
        for number, row in enumerate(csv.reader(lines[1:]), 2):
            try:
                _timesteps, level, episode, steps, reward, wall = row
                entry = Episode(int(episode), int(steps), float(reward), 0, float(wall))
            except ValueError:
                if number == len(lines):
                    break  # the half-written last line of a killed run
                raise self._damaged(CURVE_FILE, f"its line {number} is not an episode") from None
            if level not in self.episodes:
                raise self._damaged(CURVE_FILE, f"its line {number} names a level not trained on")
            if len(self.episodes[level]) < keep.get(level, 0) and math.isfinite(entry.reward):
                done = sum(e.steps for e in self.episodes[level]) + entry.steps
                self.episodes[level].append(Episode(entry.episode, entry.steps, entry.reward, done, entry.wall))
                kept.append(",".join(row))
        if any(len(self.episodes[level]) != count for level, count in keep.items()):
            raise self._damaged(CURVE_FILE, "it holds fewer episodes than its checkpoint")
        atomic_write(self.path / CURVE_FILE, ("\n".join(kept) + "\n").encode(), overwrite=True)

    def _read_checkpoint_file(self, kind: str) -> bytes:
        assert self.checkpoint is not None
        entry = self.checkpoint[kind]
        path = self.path / CHECKPOINT_DIR / entry["file"]
        try:
            data = read_regular_file(path, f"a checkpoint's {kind} file", MAX_WEIGHTS_BYTES)
        except FileSystemError as exc:
            raise RunFolderError(f"{exc} Start in a new --out.") from None
        if hashlib.sha256(data).hexdigest() != entry["sha256"]:
            raise self._damaged(f"{CHECKPOINT_DIR}/{entry['file']}", "its digest is not the one run.json names")
        return data

    # --- progress -----------------------------------------------------------------------------------

    def _open_progress(self) -> None:
        self._show_lines = not sys.stderr.isatty()
        if not self._show_lines:
            from tqdm import tqdm

            self._bar = tqdm(total=self.training.timesteps, initial=self.timesteps, unit="step", unit_scale=True,
                             desc=f"train {self.training.agent}", file=sys.stderr, dynamic_ncols=True)
        self._shown = self.timesteps

    def _show(self) -> None:
        if not hasattr(self, "_show_lines"):
            return
        recent = sorted((e for episodes in self.episodes.values() for e in episodes[-10:]), key=lambda e: e.wall)[-10:]
        mean = f"{sum(e.reward for e in recent) / len(recent):,.1f}" if recent else "-"
        if self._bar is not None:
            self._bar.update(self.timesteps - self._shown)
            self._bar.set_postfix_str(f"recent episodes' reward {mean}")
        else:
            rate = self.timesteps / max(time.monotonic() - self._started, 1e-9)
            print(f"train: {self.timesteps:,}/{self.training.timesteps:,} timesteps, "
                  f"{sum(map(len, self.episodes.values())):,} episodes, recent episodes' reward {mean}, "
                  f"{rate:,.0f} steps/s", file=sys.stderr, flush=True)
        self._shown = self.timesteps


def _checkpoint_problem(checkpoint: Any, episodes: Mapping[str, Any], budget: int) -> str | None:
    """What is wrong with ``run.json``'s checkpoint entry, or ``None``."""
    def whole(value: Any) -> bool:
        return isinstance(value, int) and not isinstance(value, bool) and value >= 0

    if not isinstance(checkpoint, dict) or not whole(checkpoint.get("timesteps")):
        return "its checkpoint has no timesteps"
    for key in ("episodes", "level_steps"):
        counts = checkpoint.get(key)
        if not isinstance(counts, dict) or set(counts) != set(episodes) or not all(map(whole, counts.values())):
            return f"its checkpoint's {key} are not one count per level"
    for kind in ("weights", "state"):
        entry = checkpoint.get(kind)
        if not isinstance(entry, dict) or not isinstance(entry.get("file"), str) \
                or Path(entry["file"]).name != entry["file"] or not isinstance(entry.get("sha256"), str):
            return f"its checkpoint's {kind} is not {{file, bytes, sha256}}"
    return None


def state_bytes(save: Any, value: Any) -> bytes:
    """``value`` as the bytes of ``save(value, file)`` (``torch.save``)."""
    out = io.BytesIO()
    save(value, out)
    return out.getvalue()


def train(training: Training, out: Path, *, resume: bool = False, progress: bool = True,
          checkpoint_seconds: float = DEFAULT_CHECKPOINT_SECONDS, ray_address: str | None = None) -> TrainRun:
    """Run ``training`` into ``out`` (see the module's doc); return the finished run (closed).

    Args:
        training: What to train, and on which backend.
        out: The run folder.
        resume: Continue the run in ``out``.
        progress: Show progress.
        checkpoint_seconds: Seconds between checkpoints.
        ray_address: With the ``ray`` backend, a cluster's address (``None``: a new local Ray).

    Raises:
        RetrokitError: A level, ROM or the library is missing, the Ray cluster cannot be reached, or the folder
            cannot be used (see :class:`TrainRun`).
        KeyboardInterrupt: Interrupted; the last checkpoint stays, for ``--resume``.
    """
    from retrokit.learning.algorithms import algorithm

    module = algorithm(training.agent)
    training.benchmark.check_levels(list(training.levels))
    if training.backend == "ray":
        from retrokit.learning import raytrain

        raytrain.check(training, ray_address)  # before RLlib's import and the folder's claim: a typo leaves nothing
        raytrain.require(training.agent)
    else:
        module.require()
    # on Ray, connected (and the cluster's CPUs checked) before the folder is claimed
    with raytrain.cluster(training, ray_address) if training.backend == "ray" else contextlib.nullcontext():
        run = TrainRun(out, training, resume=resume, progress=progress, checkpoint_seconds=checkpoint_seconds)
        try:
            if training.backend == "ray":
                raytrain.train(run, ray_address)
            else:
                module.train(run)
            run.finish()
        finally:
            run.close()
    return run
