"""Movies under stress: processes recording into one folder at once, and exports of long movies."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from retrokit.movie import read_bk2
from retrokit.movie.recorder import MovieRecorder, claim_movie_path

RECORD = """
import sys, retrokit
env = retrokit.make("Dasher-Genesis", record=sys.argv[1], max_episode_steps=2)
for episode in range(int(sys.argv[2])):
    env.reset(seed=episode)
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        done = terminated or truncated
env.close()
"""


@pytest.mark.parametrize("processes", [2, 4], ids=["2-processes", "4-processes"])
def test_processes_recording_into_one_folder_never_conflict(tmp_path: Path, processes: int) -> None:
    episodes = 6
    children = [
        subprocess.Popen([sys.executable, "-c", RECORD, str(tmp_path), str(episodes)], stderr=subprocess.PIPE, text=True)
        for _ in range(processes)
    ]
    errors = []
    for child in children:
        try:
            _, err = child.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            child.kill()
            raise
        if child.returncode:
            errors.append(err)
    assert errors == []
    movies = sorted(tmp_path.glob("*.bk2"))
    assert len(movies) == processes * episodes
    assert all(len(read_bk2(m).frames) == 2 * 1 for m in movies)  # each a whole movie (2 steps of 1 frame)


def test_a_claimed_name_is_reserved_on_disk(tmp_path: Path) -> None:
    first = claim_movie_path(tmp_path, "Game-State")
    assert first.is_file() and first.stat().st_size == 0  # another process now skips it
    (tmp_path / "Game-State-000001.bk2").write_bytes(b"someone else's")
    second = claim_movie_path(tmp_path, "Game-State")
    assert second.name == "Game-State-000002.bk2"
    recorder = MovieRecorder(first, "Dasher-Genesis", "Genesis")
    recorder.record([0])
    assert recorder.close() == first and len(read_bk2(first).frames) == 1
    assert (tmp_path / "Game-State-000001.bk2").read_bytes() == b"someone else's"
