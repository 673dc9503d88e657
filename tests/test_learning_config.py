"""Learning agents' configs: the shipped ones against the paper's table, and a user's file checked key by key."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import pytest
import yaml

from retrokit.errors import AgentConfigError, UnknownNameError
from retrokit.learning.config import CONFIG_DIR, load_config, shipped_configs
from retrokit.learning.ppo import KEYS

# "Gotta Learn Fast", Appendix A: PPO's hyper-parameters.
PAPER_PPO = {
    "horizon": 8192, "epochs": 4, "minibatch": 8192, "gamma": 0.99, "gae_lambda": 0.95, "clip": 0.2,
    "entropy": 0.001, "reward_scale": 0.005, "frame_size": 84, "frame_stack": 4, "grayscale": True,
    "network": "nature_cnn",
}  # fmt: skip


def test_ppo_paper_config_is_the_papers_table() -> None:
    config = load_config("ppo")  # the default
    assert config.name == "paper"
    for key, value in PAPER_PPO.items():
        assert config[key] == value, key
    # The paper's PPO ran one worker; the learning rate is its baseline code's (the YAML says where from).
    assert config["learning_rate"] == 2e-4
    assert "ppo2_agent.py" in (CONFIG_DIR / "ppo" / "paper.yaml").read_text()


def test_ppo_ships_paper_and_quick_with_every_key() -> None:
    assert shipped_configs("ppo") == ["paper", "quick"]
    quick = load_config("ppo", "quick")
    assert list(quick.values) == list(KEYS)
    assert quick["horizon"] < PAPER_PPO["horizon"] and quick["minibatch"] < PAPER_PPO["minibatch"]


def _user_config(tmp_path: Path, **changes) -> Path:
    values = dict(load_config("ppo", "paper").values)
    for key, value in changes.items():
        if value is ...:
            del values[key]
        else:
            values[key] = value
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(values))
    return path


def test_a_users_copy_is_read_with_its_changes(tmp_path) -> None:
    config = load_config("ppo", _user_config(tmp_path, horizon=256))
    assert config["horizon"] == 256 and config.name == str(tmp_path / "mine.yaml")


@pytest.mark.parametrize(("changes", "message"), [
    ({"horizn": 5, "horizon": ...}, "has 'horizn', which is none. Did you mean 'horizon'?"),
    ({"horizon": ...}, "but horizon is missing"),
    ({"horizon": True}, "horizon .* must be a whole number; got True"),
    ({"horizon": 2.5}, "horizon .* must be a whole number"),
    ({"gamma": 1.5}, "gamma .* must be from 0 to 1; got 1.5"),
    ({"gamma": float("nan")}, "gamma .* must be from 0 to 1"),
    ({"grayscale": "yes"}, "grayscale .* must be bool"),
    ({"network": "resnet"}, "network .* must be one of nature_cnn"),
    ({"learning_rate": "0.1"}, "learning_rate .* must be a number"),
], ids=["unknown-key", "missing-key", "bool-for-int", "float-for-int", "out-of-range", "nan", "str-for-bool",
        "unknown-choice", "str-for-float"])
def test_bad_keys_are_one_line(tmp_path, changes, message) -> None:
    with pytest.raises(AgentConfigError, match=message) as caught:
        load_config("ppo", _user_config(tmp_path, **changes))
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(("content", "message"), [
    (b"horizon: [1, 2\n", "cannot be read as YAML"),
    (b"- 1\n- 2\n", "holds a list"),
    (b"\xff\xfe\x00", "cannot be read as YAML"),
    (b"a: &a [*a, *a]\n" + b"b: 1\n", "cannot be read as YAML|holds|Expected"),
    (b"x: 1\n" * 40000, "of at most 64 KiB"),
], ids=["not-yaml", "a-list", "binary", "alias", "huge"])
def test_bad_files_are_one_line(tmp_path, content, message) -> None:
    path = tmp_path / "bad.yaml"
    path.write_bytes(content)
    with pytest.raises(AgentConfigError, match=message) as caught:
        load_config("ppo", path)
    assert "\n" not in str(caught.value)


def test_a_fifo_or_device_is_refused_without_blocking(tmp_path) -> None:
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    with pytest.raises(AgentConfigError, match="a FIFO"):
        load_config("ppo", fifo)
    zero = tmp_path / "zero.yaml"
    zero.symlink_to("/dev/zero")
    with pytest.raises(AgentConfigError, match="a device"):
        load_config("ppo", zero)


def test_unknown_names_suggest() -> None:
    with pytest.raises(UnknownNameError, match="Did you mean 'paper'"):
        load_config("ppo", "papr")
    with pytest.raises(UnknownNameError, match="Did you mean 'ppo'"):
        load_config("ppp")
    with pytest.raises(AgentConfigError, match="Expected an agent config"):
        load_config("ppo", "missing/config.yaml")


@pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is not None,
                    reason="Stable-Baselines3 is installed here: the refusal is for machines without it")
def test_without_the_library_ppo_says_how_to_install_it(tmp_path, capsys) -> None:
    from retrokit.cli import main

    for argv in (["evaluate", "--agent", "ppo", "--out", str(tmp_path / "e")],
                 ["train", "--timesteps", "10", "--out", str(tmp_path / "t")]):
        assert main([*argv, "--no-progress"]) == 2
        err = capsys.readouterr().err
        assert "download.pytorch.org/whl/cpu`, then `pip install 'retrokit-rl[train]'" in err
        assert len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())  # refused before anything was made
