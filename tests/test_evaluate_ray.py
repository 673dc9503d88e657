"""``retrokit evaluate --backend ray`` on a local Ray with 2 CPUs gives the local backend's result."""

from __future__ import annotations

import subprocess
import sys

from retrokit.cli import main

ARGS = ["evaluate", "--benchmark", "dasher", "--levels", "Zone2.Act2,Zone3.Act2", "--timesteps", "400",
        "--agent", "jerk", "--seed", "3", "--no-progress"]


def test_ray_gives_the_same_summary_as_local(tmp_path) -> None:
    assert main([*ARGS, "--workers", "1", "--out", str(tmp_path / "local")]) == 0
    # Ray runs in a child, as a user runs it: importing Ray here would leave this test process a few hundred
    # MB larger, and the memory limits other tests check in their own children start from that size.
    child = subprocess.run([sys.executable, "-m", "retrokit", *ARGS, "--workers", "2", "--backend", "ray",
                            "--out", str(tmp_path / "ray")], check=False, capture_output=True, text=True, timeout=240)
    assert child.returncode == 0, child.stderr
    local, ray = ((tmp_path / name / "summary.json").read_bytes() for name in ("local", "ray"))
    assert local == ray
    streamed = (tmp_path / "ray" / "episodes.jsonl").read_text().splitlines()
    assert len(streamed) == len((tmp_path / "local" / "episodes.jsonl").read_text().splitlines()) > 2


def test_without_ray_the_error_says_how_to_install_it(tmp_path, monkeypatch, capsys) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now raises ImportError
    assert main([*ARGS, "--backend", "ray", "--out", str(tmp_path / "run")]) == 2
    assert "pip install 'retrokit-rl[ray]'" in capsys.readouterr().err
