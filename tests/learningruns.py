"""What every learning agent's end-to-end tests share: ``retrokit evaluate`` of one Dasher level, learning from
scratch, fine-tuning a ``retrokit train`` folder, and zero-shot from its ``policy.json``."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import yaml
from incli import retrokit_in_process

from retrokit.learning.config import load_config

LEVEL = "Zone1.Act2"


def tiny_config(folder: Path, agent: str, changes: dict[str, Any]) -> Path:
    """``agent``'s shipped ``quick`` config with a tiny budget's ``changes``, written as ``folder/tiny.yaml``."""
    path = folder / "tiny.yaml"
    path.write_text(yaml.safe_dump({**load_config(agent, "quick").values, **changes}))
    return path


def evaluate(folder: Path, agent: str, timesteps: int, out: str, *args: str) -> subprocess.CompletedProcess:
    """``retrokit evaluate --agent AGENT`` (unless ``args`` name another) of Dasher's ``LEVEL`` into ``folder/out``."""
    chosen = () if "--agent" in args else ("--agent", agent)
    return retrokit_in_process(folder, "evaluate", *chosen, "--levels", LEVEL, "--timesteps", str(timesteps),
                               "--workers", "1", "--no-progress", "--out", str(folder / out), *args)


def evaluate_three_ways(folder: Path, agent: str, timesteps: int, config: Path, trained: Path) -> dict[str, Any]:
    """Evaluate with ``config`` from scratch, from ``trained`` (``--init DIR``) and zero-shot (its policy.json).

    Each must finish its level's budget and record its setup; returns each run's ``agent_setup`` by name.
    """
    setups = {}
    for out, args in (("scratch", ()), ("from-folder", ("--init", str(trained))),
                      ("zero-shot", ("--init", str(trained / "policy.json"), "--no-learn"))):
        done = evaluate(folder, agent, timesteps, out, "--agent-config", str(config), *args)
        assert done.returncode == 0, done.stderr
        run = json.loads((folder / out / "run.json").read_text())
        assert run["finished"][f"Dasher-Genesis/{LEVEL}"]["timesteps"] == timesteps
        setup = setups[out] = run["settings"]["agent_setup"]
        assert setup["learn"] == (out != "zero-shot") and (setup["init"] is None) == (out == "scratch")
    return setups
