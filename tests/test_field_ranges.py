"""Field ranges in game.yaml: read, checked by ``retrokit validate`` on every state, and by ``make(state=...)``.

Another game's state that no record knows (played on, and saved by a tool that records
nothing), dropped into a game's folder, plays garbage: Dasher's fields read out of their
ranges one frame in. A state that is known (the wheel's, even re-gzipped) is named first.
"""

from __future__ import annotations

import dataclasses
import gzip
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from probestore import seed_shipped, shared_verdicts

import retrokit
from retrokit.data.gamefiles import read_game_yaml
from retrokit.data.games import find_game
from retrokit.data.states import StateRecord, read_state, write_state
from retrokit.errors import DataFileError, StateError
from retrokit.host.fields import FieldSpec, out_of_range
from retrokit.paths import repo_games_dir
from retrokit.testing import check_game
from retrokit.testing.report import FAIL, PASS

DASHER = repo_games_dir() / "Dasher-Genesis"
GAME = "Dashcopy-Genesis"


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """State-probe verdicts shared by this module's tests: probing is not what they test.

    Seeded as on a machine that once loaded Dasher's shipped Zone1.Act1 (which needs no probe and is then
    known): the copy's re-gzipped Zone1.Act1 is the same state on the same ROM.
    """
    return seed_shipped(tmp_path_factory.mktemp("state-probes"))


@pytest.fixture
def data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, verdicts: Path) -> Iterator[Path]:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    with shared_verdicts(verdicts, tmp_path / "data") as folder:
        yield folder


def dasher_copy(root: Path) -> Path:
    """Dasher under another name in ``root/games``, with its ROM, its Zone1.Act1 state and its ranges (no recipes,
    no movies)."""
    folder = root / "games" / GAME
    folder.mkdir(parents=True)
    text = (DASHER / "game.yaml").read_text()
    (folder / "game.yaml").write_text(text[: text.index("integrate:")].replace("by_players: [Zone1.Act1, Zone1.Act1.2P]", ""))
    for name in ("rom.md", "scenario.yaml"):
        shutil.copy(DASHER / name, folder / name)
    # re-gzipped: the game's own state, not a byte-for-byte copy of Dasher's (which validate flags)
    (folder / "Zone1.Act1.state").write_bytes(gzip.compress(read_state(DASHER / "Zone1.Act1.state"), 1, mtime=0))
    return folder


@pytest.fixture
def copy(tmp_path: Path, data: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """:func:`dasher_copy` in the test's folder, found by name through RETROKIT_GAMES."""
    folder = dasher_copy(tmp_path)
    monkeypatch.setenv("RETROKIT_GAMES", str(folder.parent))
    return folder


def airstriker_regzipped(airstriker_dir: Path) -> bytes:
    return gzip.compress(gzip.decompress((airstriker_dir / "Level1.state").read_bytes()), mtime=0)


def results(report, check: str) -> dict[str, tuple[str, str]]:
    return {r.state: (r.status, r.message) for r in report.results if r.check == check}


def test_ranges_are_read_from_game_yaml_and_checked_against_the_type(tmp_path):
    game = find_game("Dasher-Genesis")
    assert game.fields["p1_lives"].range == (0, 9) and game.fields["zone"].range == (0, 2)
    assert game.fields["p1_x"].range is None
    spec = FieldSpec("lives", 0xFF002B, "|u1", range=(0, 9))
    assert out_of_range([spec], {"lives": 26}) == ["lives=26 (range 0 to 9)"]
    assert out_of_range([spec], {"lives": 9}) == [] and out_of_range([spec], {}) == []
    for bad, message in [("[9, 0]", "lo <= hi"), ("[0, 300]", "0 to 255"), ("[0]", "to be \\[lo, hi\\]"),
                         ("5", "a list \\[lo, hi\\]"), ("[0, x]", "an integer")]:
        path = tmp_path / "game.yaml"
        path.write_text(f"system: Genesis\nfields:\n  lives: {{address: 0xFF002B, type: '|u1', range: {bad}}}\n")
        with pytest.raises(DataFileError, match=message):
            read_game_yaml(path)
    path.write_text("system: Genesis\nfields:\n  lives: {address: 0xFF002B, type: '|u1', range: ['0x0', '0x09']}\n")
    assert read_game_yaml(path).fields["lives"].range == (0, 9)


def airstriker_played(airstriker_dir: Path, airstriker_rom: Path) -> bytes:
    """Airstriker's state 10 frames on, saved by a tool that records nothing: no record or shipped list knows it."""
    from retrokit.data.statecheck import load_state

    with retrokit.Emulator("Genesis", airstriker_rom) as emu:
        emu.set_state(load_state(find_game("Airstriker-Genesis"), airstriker_dir / "Level1.state"))
        emu.run([0, 0], 10)
        return bytes(emu.get_state())


@pytest.fixture(scope="module")
def played(airstriker_dir: Path, airstriker_rom: Path) -> bytes:
    """:func:`airstriker_played`, made once for the module."""
    return airstriker_played(airstriker_dir, airstriker_rom)


def test_make_refuses_another_games_state_with_a_state_error(copy, played):
    # (the wheel's own Airstriker state, even re-gzipped, is refused before this by its hash: test_other_games_state)
    write_state(copy / "Level1.state", played)
    with pytest.raises(StateError, match=r"found, one frame in, .*game_mode=\d+ \(range 0 to 3\)"):
        retrokit.make(GAME, state="Level1")
    env = retrokit.make(GAME, state="Zone1.Act1", obs_type="ram")  # the game's own state is fine
    try:
        obs, info = env.reset(seed=0)
        assert info["game_mode"] == 1 and obs.shape == env.observation_space.shape
    finally:
        env.close()


@dataclasses.dataclass
class Shared:
    """The copy validated once for the tests that each check their own state of it (a validate each was a
    probe child and the smoke runs of every state each), and its environment."""

    folder: Path
    env: dict[str, str]
    report: object


@pytest.fixture(scope="module")
def shared(tmp_path_factory: pytest.TempPathFactory, verdicts: Path, played: bytes, airstriker_dir: Path) -> Shared:
    """One copy holding each test's state under its own name, validated once:

    - ``Known``: the wheel's Airstriker state, re-gzipped (known by its hash);
    - ``Played`` and ``Saved``: Airstriker's state played on, saved by a tool that records nothing (ranges only);
    - ``Mine``: the game's own state with retrokit's record;
    - movies ``Good.bk2`` (Dasher's) and ``Foreign.bk2`` (Airstriker's start state).
    """
    from retrokit.movie import read_bk2, write_bk2

    root = tmp_path_factory.mktemp("shared")
    folder = dasher_copy(root)
    (folder / "Known.state").write_bytes(airstriker_regzipped(airstriker_dir))
    write_state(folder / "Played.state", played)
    write_state(folder / "Saved.state", played)
    state = read_state(folder / "Zone1.Act1.state")
    write_state(folder / "Mine.state", state, record=StateRecord.of(GAME, find_game(folder).sha1s[0], state))
    movie = read_bk2(DASHER / "movies" / "Zone1.Act1.bk2")
    (folder / "movies").mkdir()
    write_bk2(folder / "movies" / "Good.bk2", movie)
    foreign = gzip.decompress((airstriker_dir / "Level1.state").read_bytes())
    write_bk2(folder / "movies" / "Foreign.bk2", dataclasses.replace(movie, state=foreign))
    env = {"RETROKIT_DATA": str(root / "data"), "RETROKIT_GAMES": str(folder.parent)}
    with pytest.MonkeyPatch.context() as patch, shared_verdicts(verdicts, root / "data"):
        for name, value in env.items():
            patch.setenv(name, value)
        return Shared(folder, env, check_game(GAME, frames=30))


def test_validate_names_the_game_a_known_state_belongs_to(shared):
    """The wheel's Airstriker state, re-gzipped: validate knows it by its hash, as make(state=...) does."""
    status, message = results(shared.report, "state is the game's")["Known"]
    assert status == FAIL and "found Airstriker-Genesis's state" in message and "Load it with Airstriker-Genesis" in message
    assert "Known" not in results(shared.report, "fields in range") and not shared.report.passed


def test_validate_names_the_fields_of_another_games_state_out_of_range(shared):
    ranges = results(shared.report, "fields in range")
    assert ranges["Zone1.Act1"][0] == PASS
    status, message = ranges["Played"]
    assert status == FAIL and "game_mode=" in message and "(range 0 to 3)" in message
    assert results(shared.report, "state is the game's")["Played"][0] == PASS  # no other check sees it
    assert not shared.report.passed


def test_validate_catches_a_state_saved_on_another_games_rom(shared):
    """Saved with Airstriker's ROM by a tool that records nothing: only the ranges can tell."""
    assert results(shared.report, "fields in range")["Saved"][0] == FAIL


def test_validate_covers_the_states_in_the_data_folder_of_a_game_given_by_folder(copy, data, played):
    made = data / "games" / GAME
    made.mkdir(parents=True)
    write_state(made / "Dropped.state", played)
    report = check_game(copy, frames=30)  # validate FOLDER, as docs/integrate.md runs it in the game's folder
    assert results(report, "fields in range")["Dropped"][0] == FAIL
    assert results(report, "state loads")["Dropped"][0] == PASS


def test_validate_flags_a_default_that_names_no_state(copy):
    text = (copy / "game.yaml").read_text()
    (copy / "game.yaml").write_text(text + "integrate:\n  Zone2.Act1: {set: {zone: 1, act: 0}, press: [START], "
                                    "until: {game_mode: 1}}\n")
    (copy / "game.yaml").write_text((copy / "game.yaml").read_text().replace("default: Zone1.Act1", "default: Zone2.Act1"))
    report = check_game(GAME, frames=30)
    status, message = results(report, "default state")["Zone2.Act1"]
    assert status == FAIL and f"retrokit integrate {GAME} Zone2.Act1" in message


def test_validate_checks_each_movies_start_state(shared):
    ranges = results(shared.report, "fields in range")
    assert ranges["Good.bk2 start"][0] == PASS and ranges["Foreign.bk2 start"][0] == FAIL


def test_a_state_recorded_on_this_rom_in_range_is_trusted_as_before(shared, monkeypatch):
    """The range check adds no refusal of the game's own states (make() and validate agree)."""
    for name, value in shared.env.items():
        monkeypatch.setenv(name, value)
    env = retrokit.make(GAME, state="Mine")
    env.close()
    assert results(shared.report, "fields in range")["Mine"][0] == PASS
