"""stable-retro 1.0.1's own examples and playback script run on ``retrokit.retro`` with only their import changed.

The scripts come from stable-retro's sdist at test time (:func:`retrokit.host.sdist.cached_sdist`, the copy
``build-core`` keeps in the data folder), so none of their code is in this repository; without the sdist
(no network, no cache) the tests skip and say why. Each runs in a child, with ``import stable_retro as
retro`` made ``import retrokit.retro as retro`` and nothing else changed, except two lines (:data:`FIXES`):
``discretizer.py`` names Sonic, whose ROM no test machine has, and plays Dasher-Genesis instead; and
``determinism.py --movie-file`` reads ``num_buttons`` through a wrapper, which fails on stable-retro itself
since Gymnasium 1.0, so it reads ``env.unwrapped.num_buttons``. Their windows
(``render_mode="human"`` by default, as in stable-retro) open on SDL's dummy video driver.

Scripts that never end by themselves are bounded in the child by what they did, never by time: a
runner counts ``env.step`` calls and ends the child once the script got far enough (``trivial_random_agent``:
300 steps; ``brute``: its first best run recorded into ``best.bk2`` and the recording stopped). The
timeout of each child only catches a hang; a run that did not get that far fails.
"""

from __future__ import annotations

import json
import re
import tarfile
from pathlib import Path

import numpy as np
import pytest
from childproc import REPO, run_child

from retrokit.errors import CoreBuildError, FileSystemError

stable_retro = pytest.importorskip("stable_retro")

VERSION = "1.0.1"
SCRIPTS = {
    "brute.py": "examples/brute.py",
    "determinism.py": "examples/determinism.py",
    "random_agent.py": "examples/random_agent.py",
    "trivial_random_agent.py": "examples/trivial_random_agent.py",
    "discretizer.py": "examples/discretizer.py",
    "playback_movie.py": "scripts/playback_movie.py",
}
IMPORT = "import stable_retro as retro"
# What else changes, and why: no test machine has Sonic's ROM; and Gymnasium 1.0 stopped handing a wrapper's
# unknown attributes to the env inside, so determinism.py's --movie-file branch fails on stable-retro itself
# with every Gymnasium retrokit supports (AttributeError: 'MoreDeterministicRetroState' ... 'num_buttons').
FIXES = {
    "discretizer.py": [('"SonicTheHedgehog-Genesis"', '"Dasher-Genesis"')],
    "determinism.py": [("range(env.num_buttons)", "range(env.unwrapped.num_buttons)")],
}
HEADLESS = {"SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy", "PYTHONPATH": str(REPO)}
HANG = 300.0  # seconds after which a child is taken to hang (the runs take seconds)

# Runs a script as __main__; LIMIT ends the child after that many env.step calls, STOP right after a method of the env.
RUNNER = """
import os, runpy, sys
import retrokit.retro as retro

def leave(what):
    print("runner:", what, flush=True)
    sys.stdout.flush()
    os._exit(0)

if LIMIT:
    step, count = retro.RetroEnv.step, [0]
    def counted(self, action):
        out = step(self, action)
        count[0] += 1
        if count[0] >= LIMIT:
            leave(f"{count[0]} steps")
        return out
    retro.RetroEnv.step = counted
if STOP:
    method = getattr(retro.RetroEnv, STOP)
    def then_leave(self, *args):
        method(self, *args)
        leave(STOP)
    setattr(retro.RetroEnv, STOP, then_leave)
sys.argv = [SCRIPT, *ARGS]
runpy.run_path(SCRIPT, run_name="__main__")
"""


@pytest.fixture(scope="module")
def scripts(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """stable-retro's scripts from its sdist, each with its import changed (and discretizer's game), in a temp folder."""
    from retrokit.host.sdist import cached_sdist

    try:
        sdist = cached_sdist(VERSION)
    except (CoreBuildError, FileSystemError) as exc:
        pytest.skip(f"stable-retro {VERSION}'s sdist cannot be had here: {exc}")
    folder = tmp_path_factory.mktemp("stable-retro-scripts")
    wanted = {f"stable_retro-{VERSION}/stable_retro/{path}": name for name, path in SCRIPTS.items()}
    found: dict[str, str] = {}
    with tarfile.open(sdist, "r|gz") as tar:
        for member in tar:
            if member.name in wanted and member.isfile():
                found[wanted[member.name]] = tar.extractfile(member).read().decode()  # type: ignore[union-attr]
                if len(found) == len(wanted):
                    break
    assert set(found) == set(SCRIPTS), f"stable-retro {VERSION}'s sdist lacks {set(SCRIPTS) - set(found)}"
    out = {}
    for name, text in found.items():
        assert text.count(IMPORT) == 1, f"{name}: expected one line {IMPORT!r}"
        text = text.replace(IMPORT, "import retrokit.retro as retro")
        for old, new in FIXES.get(name, ()):
            assert old in text, f"{name}: expected {old!r}"
            text = text.replace(old, new)
        out[name] = folder / name
        out[name].write_text(text)
    return out


def run_script(script: Path, args: list[str], cwd: Path, *, limit: int = 0, stop: str = ""):
    """Run a script in a child as ``python script args`` would, bounded by ``limit`` steps or the ``stop`` method."""
    code = f"LIMIT, STOP, SCRIPT, ARGS = {limit!r}, {stop!r}, {str(script)!r}, {args!r}\n" + RUNNER
    return run_child(code, timeout=HANG, env=HEADLESS, cwd=cwd)


@pytest.fixture(scope="module")
def retrokit_movie(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[dict[str, int]]]:
    """A movie retrokit recorded (retrokit.make's record=) of 200 steps of Airstriker, and the info of each step."""
    import retrokit

    folder = tmp_path_factory.mktemp("retrokit-movie")
    env = retrokit.make("Airstriker-Genesis", action_type="all", record=folder, reset_frame=True)
    env.reset(seed=0)
    env.action_space.seed(0)
    infos = [env.step(env.action_space.sample())[4] for _ in range(200)]
    env.close()
    (movie,) = folder.glob("*.bk2")
    return movie, infos


def test_random_agent_plays_an_episode_and_records_a_movie_stable_retro_opens(scripts, tmp_path: Path) -> None:
    # It ends by itself: at the episode's end it asks for Enter, and stdin is at its end.
    child = run_script(scripts["random_agent.py"], ["--game", "Airstriker-Genesis", "--record"], tmp_path)
    assert child.returncode == 0, child.describe()
    assert re.search(r"done! total reward: time=\d+, reward=\d+", child.stdout), child.describe()
    assert "got reward" in child.stdout  # the agent scored on the way
    (movie,) = tmp_path.glob("*.bk2")
    theirs = stable_retro.Movie(str(movie))
    assert theirs.get_game() == "Airstriker-Genesis-v0"
    frames = 0
    while theirs.step():
        frames += 1
    steps = int(re.search(r"time=(\d+)", child.stdout).group(1))  # type: ignore[union-attr]
    assert frames == steps + 1  # each step's frame, and the frame reset ran


def test_trivial_random_agent_runs_300_steps(scripts, tmp_path: Path) -> None:
    child = run_script(scripts["trivial_random_agent.py"], [], tmp_path, limit=300)
    assert child.returncode == 0 and "runner: 300 steps" in child.stdout, child.describe()


def test_brute_finds_a_best_run_and_records_it(scripts, tmp_path: Path) -> None:
    child = run_script(scripts["brute.py"], ["--game", "Airstriker-Genesis"], tmp_path, stop="stop_record")
    assert child.returncode == 0 and "runner: stop_record" in child.stdout, child.describe()
    assert "new best reward -inf =>" in child.stdout, child.describe()
    theirs = stable_retro.Movie(str(tmp_path / "best.bk2"))  # the best run, as stable-retro reads it
    frames = 0
    while theirs.step():
        frames += 1
    assert frames > 100


def test_determinism_holds_on_airstriker(scripts, tmp_path: Path) -> None:
    child = run_script(scripts["determinism.py"], ["--suffix", "Airstriker-Genesis-v0"], tmp_path)
    assert child.returncode == 0, child.describe()
    assert child.stdout.splitlines()[0] == "Airstriker-Genesis-v0", child.describe()  # the game was checked
    assert "fail" not in child.stdout, child.describe()


def test_determinism_holds_on_a_retrokit_movie(scripts, retrokit_movie, tmp_path: Path) -> None:
    movie, _ = retrokit_movie
    child = run_script(scripts["determinism.py"], ["--movie-file", str(movie)], tmp_path)
    assert child.returncode == 0, child.describe()
    # 200 steps in chunks of 128: two start states, each replayed to the end ("1 2", "2 2").
    assert child.stdout.split() == ["1", "2", "2", "2"], child.describe()


def test_discretizer_makes_its_action_spaces(scripts, tmp_path: Path) -> None:
    import retrokit

    child = run_script(scripts["discretizer.py"], [], tmp_path)
    assert child.returncode == 0, child.describe()
    env = retrokit.make("Dasher-Genesis", action_type="discrete")
    expected = env.action_space.n
    env.close()
    assert f"retro.Actions.DISCRETE action_space Discrete({expected})" in child.stdout, child.describe()
    assert "SonicDiscretizer action_space Discrete(7)" in child.stdout, child.describe()


def test_playback_movie_replays_a_retrokit_movie(scripts, retrokit_movie, tmp_path: Path) -> None:
    movie, infos = retrokit_movie
    copy = tmp_path / movie.name  # the script writes its outputs beside the movie
    copy.write_bytes(movie.read_bytes())
    child = run_script(scripts["playback_movie.py"], ["-A", "-V", "-i", str(copy)], tmp_path)
    assert child.returncode == 0, child.describe()
    replayed = json.loads(copy.with_suffix(".json").read_text())
    assert replayed == infos  # every step's fields, as the episode recorded them
    assert len({info["score"] for info in infos}) > 1 or np.ptp([i["lives"] for i in infos]) > 0  # not a still game
