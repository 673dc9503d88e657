"""Movies under stress: processes recording into one folder at once, and exports of long movies."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from bombs import zip_bytes
from childproc import MAX_RSS_MB, Child, run_cli, run_cli_cases

from retrokit.movie import read_bk2
from retrokit.movie.recorder import record_numbered

# One interpreter imports what make() needs, then forks the recorders, all before waiting for any: what races
# is the recording into one folder (each makes its own env and emulator), not 4 interpreters' imports.
RECORD = """
import os, sys, traceback
import retrokit, retrokit.envs.env, retrokit.movie.recorder, retrokit.data.statecheck, retrokit.dsl.scenario
folder, episodes, processes = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
pids = []
for _ in range(processes):
    pid = os.fork()
    if pid == 0:
        status = 1
        try:
            env = retrokit.make("Dasher-Genesis", record=folder, max_episode_steps=2)
            for episode in range(episodes):
                env.reset(seed=episode)
                done = False
                while not done:
                    _, _, terminated, truncated, _ = env.step(env.action_space.sample())
                    done = terminated or truncated
            env.close()
            status = 0
        except BaseException:
            traceback.print_exc()
        finally:
            sys.stderr.flush()
            os._exit(status)
    pids.append(pid)
print([os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) for pid in pids])
"""


def test_processes_recording_into_one_folder_never_conflict(tmp_path: Path) -> None:
    # 4 writers race for the numbered names: every pair of them races as 2 alone would (2 was a case of its own)
    processes, episodes = 4, 6
    done = subprocess.run(
        [sys.executable, "-c", RECORD, str(tmp_path), str(episodes), str(processes)],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert done.returncode == 0 and done.stdout.strip() == str([0] * processes), done.stdout + done.stderr
    movies = sorted(tmp_path.glob("*.bk2"))
    assert len(movies) == processes * episodes
    assert all(len(read_bk2(m).frames) == 2 * 1 for m in movies)  # each a whole movie (2 steps of 1 frame)


def test_a_numbered_name_is_taken_by_a_whole_movie_never_an_empty_file(tmp_path: Path) -> None:
    first = record_numbered(tmp_path, "Game-State", "Dasher-Genesis", "Genesis")
    assert read_bk2(first.path).frames == []  # the name is taken by a movie that plays, header and all
    (tmp_path / "Game-State-000001.bk2").write_bytes(b"someone else's")
    second = record_numbered(tmp_path, "Game-State", "Dasher-Genesis", "Genesis")
    assert second.path.name == "Game-State-000002.bk2"
    first.record([0])
    assert first.close() == tmp_path / "Game-State-000000.bk2" and len(read_bk2(first.path).frames) == 1
    assert (tmp_path / "Game-State-000001.bk2").read_bytes() == b"someone else's"
    second.close()


# --- exporting long movies ----------------------------------------------------------------------

GENESIS_FPS = 59.922743  # Genesis Plus GX's NTSC frame rate (its av_info)


@pytest.fixture(scope="module")
def long_movie(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """2,400 frames (40 s) of Dasher running right and jumping: 2,400 RGB frames would take over 500 MB."""
    from retrokit.data.games import find_game
    from retrokit.data.states import read_state
    from retrokit.host.systems import get_system
    from retrokit.movie import Movie, write_bk2

    genesis = get_system("Genesis")
    run, jump = genesis.mask(["RIGHT"]), genesis.mask(["RIGHT", "B"])
    frames = [(jump if i % 90 < 20 else run,) for i in range(2400)]
    state = read_state(find_game("Dasher-Genesis").state_path("Zone1.Act1"))
    path = tmp_path_factory.mktemp("long") / "long.bk2"
    write_bk2(path, Movie("Dasher-Genesis", "Genesis", 1, state, frames))
    return path


def test_a_long_gif_export_streams_its_frames_at_30_fps(long_movie: Path, tmp_path: Path) -> None:
    from PIL import Image, ImageSequence

    out = tmp_path / "long.gif"
    child = run_cli(["playback", str(long_movie), str(out)], timeout=240)
    assert child.returncode == 0, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB / 2, child.describe()  # Pillow's save_all held every frame: over 500 MB
    assert "2400/2400" in child.stderr  # the progress bar reached the end
    assert "Wrote 1200 frames" in child.stdout
    with Image.open(out) as gif:
        delays = [frame.info["duration"] for frame in ImageSequence.Iterator(gif)]
    assert len(delays) == 1200
    assert set(delays) == {30, 40}  # 30 fps: every other frame of the console's 59.92
    assert abs(sum(delays) - 2400 / GENESIS_FPS * 1000) <= 10  # the movie's true length, to the hundredth


@pytest.mark.parametrize(("fps", "step", "delays"), [(60, 2, [30, 40, 30]), (12, 1, [80, 90, 80]), (50, 2, [40, 40, 40])],
                         ids=["60fps", "12fps", "50fps"])
def test_gif_frame_delays_add_up_to_the_true_time(fps: float, step: int, delays: list[int]) -> None:
    import io

    from retrokit.movie.gif import GifWriter, gif_step

    assert gif_step(fps) == step
    writer = GifWriter(io.BytesIO(), fps / step)
    assert [writer.delay_ms(i) for i in range(3)] == delays
    assert sum(writer.delay_ms(i) for i in range(300)) == round(300 * 1000 * step / fps, -1)


BOMBS = {"input-log-bomb": "Input Log.txt", "header-bomb": "Header.txt"}


@pytest.fixture(scope="module")
def bomb_playbacks(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Child]:
    """Each bomb played back by its own command, all in one child under the memory cap (its peak bounds each)."""
    folder = tmp_path_factory.mktemp("bombs")
    small = {
        "Input Log.txt": b"[Input]\nP1 B|\n|..|.|\n[/Input]",
        "Header.txt": b"Platform GEN\nGameName Dasher-Genesis-v0\n",
    }
    commands = {}
    for case, member in BOMBS.items():
        members = [(name, [1024] if name == member else [data], True) for name, data in small.items()]
        path = folder / f"{case}.bk2"
        path.write_bytes(zip_bytes(members))
        commands[case] = ["playback", str(path), str(folder / f"{case}.out")]
    return run_cli_cases(commands)


@pytest.mark.parametrize("case", list(BOMBS))
def test_a_movie_member_that_inflates_to_a_gigabyte_is_refused(bomb_playbacks: dict[str, Child], case: str) -> None:
    child = bomb_playbacks[case]
    assert child.returncode == 2, child.describe()
    assert f"expected {BOMBS[case]!r} to hold at most" in child.stderr, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()


@pytest.mark.parametrize("count", [200, 4096], ids=["200-close-colours-kept-exactly", "4096-colours-reduced"])
def test_a_gif_frame_keeps_its_colours_exactly_when_a_palette_can_hold_them(count: int) -> None:
    import io

    import numpy as np
    from PIL import Image

    from retrokit.movie.gif import GifWriter

    rng = np.random.default_rng(count)
    colours = rng.integers(0, 256, (count, 3)).astype(np.uint8)
    colours[:50] = [[100 + i // 10, 100 + i % 10, 100] for i in range(50)]  # neighbours differing in the low bits
    colours = np.unique(colours, axis=0)
    frame = colours[np.arange(224 * 320) % len(colours)].reshape(224, 320, 3)
    stream = io.BytesIO()
    writer = GifWriter(stream, 30)
    writer.add(frame)
    writer.close()
    with Image.open(io.BytesIO(stream.getvalue())) as gif:
        shown = np.asarray(gif.convert("RGB"))
    if len(colours) <= 256:
        assert np.array_equal(shown, frame)
    else:  # more than a GIF frame holds: an adaptive palette of 256, every pixel near its colour
        assert len(np.unique(shown.reshape(-1, 3), axis=0)) <= 256 and np.abs(shown.astype(int) - frame).mean() < 16
