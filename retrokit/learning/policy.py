"""The saved-policy format: ``policy.json`` beside the library's weights file, written atomically, read checked.

The contract every learning agent's saved policy follows (PPO's, Rainbow's, one trained by RLlib):

``policy.json`` (at most 1 MiB of JSON) holds

- ``format``: ``"retrokit-policy"``, ``version``: 1;
- ``agent``: the ``--agent`` that made it (``ppo``), ``library``: the library and its version
  (``stable-baselines3 2.9.2``);
- ``config``: the agent's config (:meth:`~retrokit.learning.config.AgentConfig.as_dict`), which rebuilds
  the network;
- ``actions``: the button combinations, one per discrete action, and ``x``: the field of the max-x reward
  (the benchmark's ``learning:`` block);
- ``observation``: the observation's ``shape`` and ``dtype`` and the env ``options`` that make it;
- ``benchmark``: the benchmark it was trained on, ``timesteps``: the timesteps it was trained for;
- ``weights``: ``{"file", "bytes", "sha256"}``: the weights file, in the same folder, its size and digest.

The weights file is the library's tensors only: for the torch-based libraries a ``torch.save`` of the
network's ``state_dict``, loaded with ``torch.load(..., weights_only=True)`` (torch's restricted
unpickler, which builds tensors and plain containers, never an arbitrary object), after its size (at most
:data:`MAX_WEIGHTS_BYTES`) and digest were checked against ``policy.json``, into a network built from
``policy.json``'s config, whose keys and shapes the tensors must match. A library's own archive (SB3's
``model.zip``) unpickles whatever it holds, so retrokit never loads one. Each save writes the weights under
a new name first, then ``policy.json`` (both through the atomic writer), then removes the older weights,
so a reader (or a killed writer) never sees ``policy.json`` name a half-written file.

A policy is given as its folder (a ``retrokit train`` folder) or its ``policy.json``. Anything else, a
damaged, huge, foreign or other agent's file, is one :class:`~retrokit.errors.PolicyFileError`.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from retrokit.errors import FileSystemError, PolicyFileError, shown
from retrokit.paths import atomic_write, read_regular_file

POLICY_FILE = "policy.json"
FORMAT = "retrokit-policy"
VERSION = 1
MAX_POLICY_BYTES = 1 << 20
#: The largest weights file read: PPO's Nature CNN is 7 MB and its optimizer state 14 MB; a load stays far under 500 MB.
MAX_WEIGHTS_BYTES = 64 << 20
_KEYS = ("format", "version", "agent", "library", "config", "actions", "x", "observation", "benchmark", "timesteps",
         "weights")


@dataclass(frozen=True)
class SavedPolicy:
    """A ``policy.json`` read and checked (its weights not yet read).

    Attributes:
        path: The ``policy.json``.
        meta: Its fields (see the module's doc).
    """

    path: Path
    meta: Mapping[str, Any]

    @property
    def weights_path(self) -> Path:
        """The weights file, beside ``policy.json``."""
        return self.path.parent / self.meta["weights"]["file"]

    @property
    def sha256(self) -> str:
        """The weights' digest: what identifies this policy in ``run.json``."""
        return self.meta["weights"]["sha256"]

    def read_weights(self) -> bytes:
        """The weights file's bytes, checked against ``policy.json``'s size and digest.

        Raises:
            PolicyFileError: The file is missing, not regular, larger than :data:`MAX_WEIGHTS_BYTES`, or not
                the one ``policy.json`` names (its digest differs).
        """
        try:
            data = read_regular_file(self.weights_path, "a policy's weights file", MAX_WEIGHTS_BYTES)
        except FileSystemError as exc:
            raise PolicyFileError(f"{exc} It is named by {self.path}.") from None
        if len(data) != self.meta["weights"]["bytes"] or hashlib.sha256(data).hexdigest() != self.sha256:
            raise PolicyFileError(
                f"Expected {self.weights_path} to be the weights {self.path} names (sha256 {self.sha256[:12]}...), "
                "but its size or digest differs: it was changed or damaged. Save the policy again."
            )
        return data


def write_policy(folder: Path, meta: Mapping[str, Any], weights: bytes, *, stem: str = "policy") -> SavedPolicy:
    """Save a policy into ``folder``: the weights under a new name, then ``policy.json``, then drop the older weights.

    Args:
        folder: Where ``policy.json`` goes.
        meta: Every field of ``policy.json`` but ``format``, ``version`` and ``weights``.
        weights: The library's weights file's bytes.
        stem: The weights file's name before its timesteps.

    Raises:
        FileSystemError: The folder cannot be written.
    """
    folder = Path(folder)
    digest = hashlib.sha256(weights).hexdigest()
    name = f"{stem}-{int(meta['timesteps']):012d}-{digest[:8]}.pt"
    atomic_write(folder / name, weights, overwrite=True)
    full = {"format": FORMAT, "version": VERSION, **meta, "weights": {"file": name, "bytes": len(weights), "sha256": digest}}
    atomic_write(folder / POLICY_FILE, (json.dumps(full, indent=1) + "\n").encode(), overwrite=True)
    for old in folder.glob(f"{stem}-*.pt"):
        if old.name != name:
            old.unlink(missing_ok=True)
    return SavedPolicy(folder / POLICY_FILE, full)


def find_policy(path: str | os.PathLike[str]) -> Path:
    """The ``policy.json`` that ``path`` means: the file itself, or the one in the folder ``path``.

    Raises:
        PolicyFileError: There is none.
    """
    path = Path(path).expanduser()
    if path.is_dir():
        path = path / POLICY_FILE
    if not path.exists():
        raise PolicyFileError(
            f"Expected a saved policy at {str(path)!r} (a `retrokit train` folder or its {POLICY_FILE}), but there "
            "is none; train one with `retrokit train`, or check the path."
        )
    return path


def read_policy(path: str | os.PathLike[str], agent: str | None = None) -> SavedPolicy:
    """Read and check the ``policy.json`` that ``path`` means (see :func:`find_policy`).

    Args:
        path: A policy's folder or its ``policy.json``.
        agent: The agent it must be of, if any.

    Raises:
        PolicyFileError: It is missing, unreadable, not JSON, not a retrokit policy, of another agent, or a
            field is missing or of the wrong type.
    """
    path = find_policy(path)

    def bad(problem: str) -> PolicyFileError:
        return PolicyFileError(
            f"Expected a retrokit policy file at {str(path)!r}, but {problem}; give the {POLICY_FILE} of a "
            "`retrokit train` folder (or the folder)."
        )

    try:
        raw = read_regular_file(path, "a policy file (policy.json)", MAX_POLICY_BYTES)
    except FileSystemError as exc:
        raise PolicyFileError(str(exc)) from None
    try:
        meta = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise bad(f"it is not JSON ({type(exc).__name__})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise bad("it is not one (no \"format\": \"retrokit-policy\")")
    if meta.get("version") != VERSION:
        raise bad(f"its version is {shown(meta.get('version'))}, and this retrokit reads version {VERSION}")
    missing = [key for key in _KEYS if key not in meta]
    if missing:
        raise bad(f"it lacks {', '.join(missing)}")
    problem = _problem(meta)
    if problem:
        raise bad(problem)
    if agent is not None and meta["agent"] != agent:
        raise PolicyFileError(
            f"Expected a policy of the agent {agent} at {str(path)!r}, but it is one of {shown(meta['agent'])}; "
            f"use --agent {meta['agent']}, or another policy."
        )
    return SavedPolicy(path, meta)


def _problem(meta: dict[str, Any]) -> str | None:
    """What is wrong with the fields of a ``policy.json``, or ``None``."""
    def whole(value: Any) -> bool:
        return isinstance(value, int) and not isinstance(value, bool) and value >= 0

    weights = meta["weights"]
    if not isinstance(weights, dict) or not isinstance(weights.get("file"), str) or not whole(weights.get("bytes")) \
            or not isinstance(weights.get("sha256"), str) or len(weights["sha256"]) != 64:
        return "its 'weights' is not {file, bytes, sha256}"
    name = weights["file"]
    if name != os.path.basename(name) or name in ("", ".", "..") or "\0" in name:
        return f"its weights file {shown(name)} is not a plain file name beside it"
    if not isinstance(meta["agent"], str) or not isinstance(meta["library"], str):
        return "its 'agent' or 'library' is not a string"
    config = meta["config"]
    if not isinstance(config, dict) or not isinstance(config.get("values"), dict):
        return "its 'config' has no 'values' mapping"
    actions = meta["actions"]
    if not isinstance(actions, list) or not actions or not all(
        isinstance(combo, list) and all(isinstance(b, str) for b in combo) for combo in actions
    ):
        return "its 'actions' is not a list of button lists"
    if meta["x"] is not None and not isinstance(meta["x"], str):
        return "its 'x' is not a field name"
    observation = meta["observation"]
    if not isinstance(observation, dict) or not isinstance(observation.get("shape"), list) \
            or not all(whole(n) for n in observation["shape"]) or not isinstance(observation.get("options"), dict):
        return "its 'observation' is not {shape, dtype, options}"
    if not whole(meta["timesteps"]):
        return "its 'timesteps' is not a whole number"
    return None
