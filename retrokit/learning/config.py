"""An agent's config: its hyper-parameters as data, a shipped YAML by name or a user's copy by path.

Each learning agent ships its configs in ``configs/<agent>/``: ``paper`` (the
default: the paper's settings) and ``quick`` (tuned so that learning shows
within a short budget). ``--agent-config NAME|FILE`` picks one: a name of a
shipped config, or a YAML file (a user's copy of one, changed). Every config
is checked key by key against the table its algorithm declares
(:data:`~retrokit.learning.algorithms.Key`): every key present, none unknown,
each of its type and range; a mistake is one line, with a did-you-mean.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from retrokit.data.yamlfile import load_yaml
from retrokit.errors import AgentConfigError, FileSystemError, UnknownNameError, did_you_mean, shown
from retrokit.learning.algorithms import algorithm

CONFIG_DIR = Path(__file__).parent / "configs"
DEFAULT = "paper"
MAX_CONFIG_BYTES = 64 << 10  # a config is a few dozen lines


@dataclass(frozen=True)
class AgentConfig:
    """A checked config.

    Attributes:
        agent: The agent it is for (``ppo``).
        name: A shipped config's name, or the path of the user's file.
        values: Every key of the algorithm's table, with its value.
    """

    agent: str
    name: str
    values: Mapping[str, Any]

    def as_dict(self) -> dict[str, Any]:
        """As plain data, for ``run.json`` and ``policy.json``."""
        return {"agent": self.agent, "name": self.name, "values": dict(self.values)}

    def __getitem__(self, key: str) -> Any:
        return self.values[key]


def shipped_configs(agent: str) -> list[str]:
    """The names of the configs shipped for ``agent``."""
    return sorted(path.stem for path in (CONFIG_DIR / agent).glob("*.yaml"))


def load_config(agent: str, spec: str | os.PathLike[str] | None = None) -> AgentConfig:
    """Load ``agent``'s config ``spec``: a shipped name, or a YAML file; ``None`` is :data:`DEFAULT`.

    Raises:
        UnknownNameError: ``agent`` is no learning agent, or ``spec`` is neither a shipped name nor a file.
        AgentConfigError: The file is unreadable, not YAML, or a key or value is wrong (the message says which).
    """
    keys = algorithm(agent).KEYS
    text = DEFAULT if spec is None else os.fspath(spec)
    names = shipped_configs(agent)
    if text in names:
        path, name = CONFIG_DIR / agent / f"{text}.yaml", text
    else:
        path = Path(text).expanduser()
        if not (path.exists() or path.suffix in (".yaml", ".yml") or os.sep in text):
            raise UnknownNameError(
                f"Expected --agent-config to name a config of {agent} ({', '.join(names)}) or a YAML file, "
                f"got {text!r}, which is neither." + did_you_mean(text, names)
            )
        name = str(path)
    return AgentConfig(agent, name, check_config(agent, read_config_file(path), keys, path))


def read_config_file(path: Path) -> Any:
    """The YAML data of a config file, read through the guarded reader (no FIFO, device or huge file).

    Raises:
        AgentConfigError: The file cannot be read or parsed.
    """
    from retrokit.paths import read_regular_file

    try:
        return load_yaml(read_regular_file(path, "an agent config (YAML)", MAX_CONFIG_BYTES).decode("utf-8-sig"))
    except FileSystemError as exc:
        raise AgentConfigError(str(exc)) from None
    except (UnicodeDecodeError, yaml.YAMLError, ValueError) as exc:
        raise AgentConfigError(
            f"Expected an agent config in YAML at {str(path)!r}, but it cannot be read as YAML "
            f"({str(exc).splitlines()[0] if str(exc) else type(exc).__name__}); fix it, or copy a shipped one."
        ) from None


def check_config(agent: str, data: Any, keys: Mapping[str, Any], path: Path | str) -> dict[str, Any]:
    """Check ``data`` against the algorithm's key table; return the values in the table's order.

    Raises:
        AgentConfigError: Not a mapping, an unknown or missing key, or a value of the wrong type or range.
    """
    where = f"the {agent} config {str(path)!r}"
    if not isinstance(data, dict):
        raise AgentConfigError(f"Expected {where} to map keys to values, but it holds a {type(data).__name__}.")
    for key in data:
        if key not in keys:
            raise AgentConfigError(
                f"Expected only keys of a {agent} config in {where}, but it has {shown(key)}, which is none."
                + (did_you_mean(str(key), keys) or f" Known keys: {', '.join(keys)}.")
            )
    missing = [key for key in keys if key not in data]
    if missing:
        raise AgentConfigError(
            f"Expected every key of a {agent} config in {where}, but {', '.join(missing)} "
            f"{'is' if len(missing) == 1 else 'are'} missing; copy the shipped paper.yaml and change it."
        )
    for key, spec in keys.items():
        problem = spec.problem(data[key])
        if problem is not None:
            raise AgentConfigError(
                f"Expected {key} in {where} to be {spec.help}: it {problem}; got {shown(data[key])}."
            )
    problem = getattr(algorithm(agent), "check_values", lambda _: None)(data)
    if problem is not None:
        raise AgentConfigError(f"Expected {where} to fit together, but {problem}.")
    return {key: data[key] for key in keys}
