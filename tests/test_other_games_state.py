"""Another game's state is refused wherever it enters, by what retrokit knows of it (issue 31 item 13).

Dasher's shipped states are known by their digest, whatever file holds them,
whether or not their record was stripped, and whatever a movie's header
around them says.
Each runs in a child process: another game's state may crash the core.
"""

from __future__ import annotations

import hashlib
import shutil
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


# --- the stable-retro wheel's states, and those this machine saved (each known by its game) --------------------


@pytest.fixture
def airstriker_file() -> Path:
    return find_game(AIRSTRIKER).state_path()  # the wheel's Level1.state


@pytest.mark.parametrize("wrapping", ["the-wheels-file-copied", "recompressed-without-record"])
def test_make_refuses_airstrikers_wheel_state_for_dasher(tmp_path, data, airstriker_file, wrapping):
    foreign = tmp_path / "Zone1.Act1.state"  # outside any game's folder: only the state's identity tells
    if wrapping == "the-wheels-file-copied":
        foreign.write_bytes(airstriker_file.read_bytes())  # known by the file's digest in the wheel's RECORD
    else:
        foreign.write_bytes(compress_state(read_state_file(airstriker_file).data, None))  # by the state's digest
    child = run_child(
        "import retrokit\nfrom retrokit.errors import StateError\n"
        f"try:\n    retrokit.make('Dasher-Genesis', state={str(foreign)!r}).reset()\n    print('played')\n"
        "except StateError as exc:\n    print('refused:', exc)\n",
        env=data, timeout=120,
    )
    assert child.returncode == 0, child.describe()
    assert f"refused: {foreign}: expected a state of Dasher-Genesis; found {AIRSTRIKER}'s state" in child.stdout, (
        child.describe()
    )
    assert "the stable-retro wheel ships it" in child.stdout and f"Load it with {AIRSTRIKER}" in child.stdout


@pytest.mark.parametrize("command", ["playback", "integrate"])
def test_a_dasher_movie_whose_core_bin_is_airstrikers_state_is_refused(tmp_path, data, airstriker_file, command):
    movie = Movie("Dasher-Genesis", "Genesis", 1, read_state_file(airstriker_file).data, [(0,)] * 30)
    write_bk2(tmp_path / "m.bk2", movie)
    args = (["playback", str(tmp_path / "m.bk2"), str(tmp_path / "out")] if command == "playback"
            else ["integrate", "Dasher-Genesis", "Made", "--out", str(tmp_path / "made"), "--movie", str(tmp_path / "m.bk2")])  # fmt: skip
    assert f"{AIRSTRIKER}'s state" in refused(run_cli(args, env=data, timeout=120))
    assert not (tmp_path / "made").exists() or not list((tmp_path / "made").iterdir())


@pytest.mark.parametrize(("host", "owner"), [("Dasher-Genesis", AIRSTRIKER), (AIRSTRIKER, "Dasher-Genesis")])
def test_the_studio_refuses_another_games_state_put_in_the_games_folder(tmp_path, data, host, owner):
    game = shutil.copytree(find_game(host).folders[0], tmp_path / host)  # a copy of the game, its ROM found by hash
    (game / "Foreign.state").write_bytes(compress_state(read_state_file(find_game(owner).state_path()).data, None))
    child = run_child(
        "from retrokit.errors import StateError\nfrom retrokit.studio import play\n"
        "from retrokit.studio.session import Session\n"
        f"session = Session({str(game)!r})\n"
        "try:\n    session.call_blocking(play.reset, 'Foreign')\n    print('loaded')\n"
        "except StateError as exc:\n    print('refused:', exc)\n"
        "session.close()\n",
        env=data, timeout=120,
    )
    assert child.returncode == 0, child.describe()
    assert f"refused: {game / 'Foreign.state'}: expected a state of {host}; found {owner}'s state" in child.stdout, (
        child.describe()
    )


SAVE_AND_LOAD = """
from pathlib import Path

import retrokit
from retrokit.data.games import find_game
from retrokit.data.integrate import place_state
from retrokit.data.states import compress_state, read_state_file
from retrokit.errors import StateError

env = retrokit.make({saver!r})
env.reset(seed=0)
env.action_space.seed(0)
for _ in range(60):
    env.step(env.action_space.sample())
place_state(find_game({saver!r}), "Saved", env.unwrapped.emulator.get_state(), Path({folder!r}))  # as integrate, the studio
env.close()
stripped = {folder!r} + "/Stripped.state"  # its record stripped: only this machine's record of it tells whose it is
open(stripped, "wb").write(compress_state(read_state_file({folder!r} + "/Saved.state").data, None))
try:
    retrokit.make({loader!r}, state=stripped).reset()
    print("played")
except StateError as exc:
    print("refused:", exc)
retrokit.make({saver!r}, state=stripped).reset()
print("its own game plays it")
"""


@pytest.mark.parametrize(("saver", "loader"), [(AIRSTRIKER, "Dasher-Genesis"), ("Dasher-Genesis", AIRSTRIKER)])
def test_a_state_this_machine_saved_for_one_game_is_refused_for_another(tmp_path, data, saver, loader):
    folder = tmp_path / "saved"
    folder.mkdir()
    child = run_child(SAVE_AND_LOAD.format(saver=saver, loader=loader, folder=str(folder)), env=data, timeout=180)
    assert child.returncode == 0, child.describe()
    assert f"found {saver}'s state (this machine saved it for {saver}" in child.stdout, child.describe()
    assert "its own game plays it" in child.stdout, child.describe()
