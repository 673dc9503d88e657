"""Another game's state is refused wherever it enters, by what retrokit knows of it (issue 31 item 13).

Dasher's shipped states are known by their digest, whatever file holds them,
whether or not their record was stripped, and whatever a movie's header
around them says.
Each runs in a child process: another game's state may crash the core.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from childproc import run_child, run_cli

from retrokit.data.games import find_game
from retrokit.data.states import compress_state, read_state_file
from retrokit.movie import Movie, write_bk2
from retrokit.movie.model import STATE_DIGEST

REPO = Path(__file__).resolve().parent.parent
DASHER_STATE = REPO / "games" / "Dasher-Genesis" / "Zone1.Act1.state"
AIRSTRIKER = "Airstriker-Genesis"


@pytest.fixture
def data(tmp_path: Path) -> dict[str, str]:
    return {"RETROKIT_DATA": str(tmp_path / "data")}


@pytest.fixture
def dasher_data() -> bytes:
    return read_state_file(DASHER_STATE).data


def movie_for_airstriker(path: Path, state: bytes, header: dict[str, str]) -> Path:
    movie = Movie(AIRSTRIKER, "Genesis", 1, state, [(0,)] * 30)
    movie.header.update(header)
    write_bk2(path, movie)
    return path


def refused(child) -> str:
    assert child.signal is None and child.returncode == 2, child.describe()
    last = child.stderr.strip().splitlines()[-1]
    assert last.startswith("retrokit: error:") and "Traceback" not in child.stderr, child.describe()
    return last


def test_make_refuses_dashers_state_without_its_record_for_airstriker(tmp_path, data, dasher_data):
    stripped = tmp_path / "Level1.state"
    stripped.write_bytes(compress_state(dasher_data, None))  # no record: only its digest tells whose it is
    child = run_child(
        "import retrokit\nfrom retrokit.errors import StateError\n"
        f"try:\n    retrokit.make({AIRSTRIKER!r}, state={str(stripped)!r}).reset()\n    print('played')\n"
        "except StateError as exc:\n    print('refused:', exc)\n"
        f"retrokit.make('Dasher-Genesis', state={str(stripped)!r}).reset()\nprint('its own game plays it')\n",
        env=data, timeout=120,
    )
    assert child.returncode == 0, child.describe()
    assert "refused:" in child.stdout and "Dasher-Genesis's state" in child.stdout, child.describe()
    assert "its own game plays it" in child.stdout


@pytest.mark.parametrize("command", ["playback", "integrate"])
def test_a_movie_whose_core_bin_is_another_games_state_is_refused(tmp_path, data, dasher_data, command):
    movie = movie_for_airstriker(tmp_path / "m.bk2", dasher_data, {})  # a stable-retro header: no SHA1
    args = (["playback", str(movie), str(tmp_path / "out")] if command == "playback"
            else ["integrate", AIRSTRIKER, "Made", "--movie", str(movie)])  # fmt: skip
    assert "Dasher-Genesis's state" in refused(run_cli(args, env=data, timeout=120))


def test_a_movie_whose_core_bin_was_swapped_is_refused_by_its_header(tmp_path, data, dasher_data):
    game = find_game(AIRSTRIKER)
    sha1, own = game.sha1s[0], read_state_file(game.state_path()).data
    header = {"SHA1": sha1, STATE_DIGEST: hashlib.sha256(own).hexdigest()}  # the header of Airstriker's own start
    movie = movie_for_airstriker(tmp_path / "m.bk2", dasher_data, header)
    assert "Dasher-Genesis's state" in refused(
        run_cli(["playback", str(movie), str(tmp_path / "out")], env=data, timeout=120)
    )
