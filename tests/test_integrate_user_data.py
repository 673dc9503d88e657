"""``retrokit integrate`` as users call it: by state name, into their data folder, from movies.

And the user's data folder as a game folder: it extends (or overrides) a
shipped game, and a folder there that matches no game is an error, not ignored.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from probestore import seed_shipped, shared_verdicts

import retrokit
from retrokit.cli import main
from retrokit.data.games import find_game
from retrokit.data.statecheck import vet_state
from retrokit.data.states import read_state
from retrokit.errors import DataFileError
from retrokit.host.emulator import Emulator
from retrokit.movie import play, read_bk2
from retrokit.paths import repo_games_dir

DASHER = repo_games_dir() / "Dasher-Genesis"
PACKAGE = Path(retrokit.__file__).resolve().parent
SOLUTION = DASHER / "movies" / "Zone1.Act1.bk2"


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Probe verdicts as a machine that once loaded Dasher's shipped Zone1.Act1 knows them: probing is not the claim
    here, and the solution movie starts from that state."""
    return seed_shipped(tmp_path_factory.mktemp("state-probes"))


@pytest.fixture
def data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, verdicts: Path) -> Iterator[Path]:
    """A per-user data folder with nothing but those verdicts (and the ones this module's tests earn)."""
    folder = tmp_path / "data"
    monkeypatch.setenv("RETROKIT_DATA", str(folder))
    with shared_verdicts(verdicts, folder):
        yield folder


def snapshot(*folders: Path) -> dict[str, tuple[int, int]]:
    """Every file under the folders, with its size and modification time."""
    return {str(p): (p.stat().st_size, p.stat().st_mtime_ns) for f in folders for p in f.rglob("*") if p.is_file()
            and "__pycache__" not in p.parts}


def ram_of(state: bytes) -> bytes:
    with Emulator("Genesis", DASHER / "rom.md") as emu:
        emu.set_state(vet_state(state, "Genesis", DASHER / "rom.md"))
        return bytes(np.asarray(emu.ram))


def test_a_lone_state_name_is_made_into_the_data_folder_and_nowhere_else(data: Path, capsys) -> None:
    before = snapshot(DASHER, PACKAGE)
    assert main(["integrate", "Zone1.Act1"]) == 0
    made = data / "games" / "Dasher-Genesis" / "Zone1.Act1.state"
    assert made.is_file() and f"made        {made}" in capsys.readouterr().out
    assert snapshot(DASHER, PACKAGE) == before  # the checkout and the package are untouched
    assert ram_of(read_state(made)) == ram_of(read_state(DASHER / "Zone1.Act1.state"))
    stamp = made.stat().st_mtime_ns
    assert main(["integrate", "Zone1.Act1"]) == 0  # up to date: not rewritten
    assert "up to date" in capsys.readouterr().out and made.stat().st_mtime_ns == stamp
    assert find_game("Dasher-Genesis").state_path("Zone1.Act1") == made  # the user's state comes first


def test_game_and_state_and_out(tmp_path: Path, data: Path) -> None:
    assert main(["integrate", "Dasher-Genesis", "Zone2.Act2", "--out", str(tmp_path / "here")]) == 0
    assert (tmp_path / "here" / "Zone2.Act2.state").is_file()
    assert not (data / "games").exists()


def test_a_name_several_games_have_is_an_error_listing_them(tmp_path: Path, data: Path, monkeypatch, capsys) -> None:
    other = tmp_path / "games" / "Dasher2-Genesis"
    shutil.copytree(DASHER, other, ignore=shutil.ignore_patterns("movies"))
    monkeypatch.setenv("RETROKIT_GAMES", str(other.parent))
    assert main(["integrate", "Zone1.Act2"]) == 2
    err = capsys.readouterr().err
    assert "found 2: Dasher-Genesis, Dasher2-Genesis" in err and "Traceback" not in err


def test_a_state_no_game_has_is_made_for_the_game_yaml_here(tmp_path: Path, data: Path, monkeypatch) -> None:
    mine = tmp_path / "MyDasher"
    mine.mkdir()
    shutil.copy(DASHER / "rom.md", mine / "rom.md")
    text = (DASHER / "game.yaml").read_text().split("\nmovies:")[0]
    text = text.replace("integrate:\n", "integrate:\n  Custom.Start: {set: {zone: 1, act: 1}, press: [START], until: {game_mode: 1}}\n")
    (mine / "game.yaml").write_text(text)
    monkeypatch.chdir(mine)
    assert main(["integrate", "Custom.Start"]) == 0
    assert (mine / "Custom.Start.state").is_file()  # next to the user's own game.yaml
    assert main(["integrate", "Nowhere.Act9"]) == 2


def test_an_unknown_lone_name_is_a_one_line_error(tmp_path: Path, data: Path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["integrate", "Zone1.Akt1"]) == 2
    err = capsys.readouterr().err
    assert "no game.yaml" in err and "retrokit integrate GAME Zone1.Akt1" in err and "Traceback" not in err


@pytest.mark.parametrize("frame", [300, None], ids=["frame-300", "whole-movie"])
def test_a_movie_made_state_is_what_playback_reaches(data: Path, frame: int | None) -> None:
    args = ["integrate", "Dasher-Genesis", "Midway", "--movie", str(SOLUTION)]
    assert main(args + (["--frame", str(frame)] if frame else [])) == 0
    made = read_state(data / "games" / "Dasher-Genesis" / "Midway.state")
    movie = read_bk2(SOLUTION)
    movie.frames = movie.frames[:frame] if frame else movie.frames
    with Emulator("Genesis", DASHER / "rom.md") as emu:
        for _ in play(movie, emulator=emu):  # what retrokit playback runs
            pass
        reached = bytes(np.asarray(emu.ram))
    assert ram_of(made) == reached
    with Emulator("Genesis", DASHER / "rom.md") as emu:  # and it is where the movie says: cleared, or on the way
        emu.set_state(vet_state(made, "Genesis", DASHER / "rom.md"))
        assert emu.peek(0xFF0003) == (0 if frame else 1)  # level_done


def test_a_movie_frame_past_its_end_is_an_error(data: Path, capsys) -> None:
    assert main(["integrate", "Midway", "--movie", str(SOLUTION), "--frame", "99999"]) == 2
    assert "Expected a frame from 0 to 621" in capsys.readouterr().err


def test_the_user_folder_extends_a_shipped_game(data: Path) -> None:
    folder = data / "games" / "Dasher-Genesis"
    folder.mkdir(parents=True)
    shutil.copy(DASHER / "Zone3.Act2.state", folder / "Mine.state")
    (folder / "rightward.yaml").write_text("reward: delta(p1_x)\ndone: level_done == 1\n")
    game = find_game("Dasher-Genesis")
    assert game.folders[0] == folder and "Mine" in game.states and "rightward" in game.scenarios
    assert len(game.fields) == 48  # the shipped game.yaml still holds the data
    env = retrokit.make("Dasher-Genesis", "Mine", "rightward", obs_type="ram")
    env.reset(seed=0)
    _, reward, *_ = env.step(env.action_space.sample())
    env.close()
    assert isinstance(reward, float)


def test_a_game_yaml_in_the_user_folder_overrides_the_shipped_one(data: Path) -> None:
    folder = data / "games" / "Dasher-Genesis"
    folder.mkdir(parents=True)
    text = (DASHER / "game.yaml").read_text().replace("  ring_count:  {address: 0xFF00C1, type: \"|u1\"}\n", "")
    (folder / "game.yaml").write_text(text)
    game = find_game("Dasher-Genesis")
    assert game.info.source == folder / "game.yaml" and "ring_count" not in game.fields
    assert game.state_path("Zone1.Act1") == DASHER / "Zone1.Act1.state"


def test_a_user_folder_matching_no_game_is_not_ignored(data: Path, capsys) -> None:
    folder = data / "games" / "Dashr-Genesis"
    folder.mkdir(parents=True)
    shutil.copy(DASHER / "Zone1.Act1.state", folder)
    with pytest.raises(DataFileError, match="Did you mean 'Dasher-Genesis'"):
        find_game("Dashr-Genesis")
    assert main(["games", "Dashr"]) == 0
    assert "cannot be read" in capsys.readouterr().out
    assert os.listdir(folder) == ["Zone1.Act1.state"]
