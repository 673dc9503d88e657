"""``retrokit validate`` and ``retrokit.testing.check_game``: real games pass, planted faults fail.

Every fault is planted in a copy of Dasher's folder; each must fail naming
the check and the state, leave the other states passing, and never stop the run.
"""

from __future__ import annotations

import gzip
import json
import random
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from corrupt import random_body
from dashercopy import dasher_copy

from retrokit.cli import main
from retrokit.data.games import list_games
from retrokit.paths import repo_games_dir
from retrokit.testing import check_game
from retrokit.testing.report import FAIL, PASS, SKIP, GameReport, Result, render

DASHER = repo_games_dir() / "Dasher-Genesis"
TREKKER = repo_games_dir() / "Trekker-GameBoy"  # the cheapest own game with a ROM: for the command's own claims
FRAMES = 120  # smoke-run frames in these tests: enough to reach a division or a lookup, cheap on CPU
COMMAND_FRAMES = 8  # for the command's own claims (tables, status, JSON, which games): what the checks find is the above's


def failed(report: GameReport) -> set[tuple[str, str]]:
    """(check, state) of every failure."""
    return {(r.check, r.state) for r in report.failures}


#: game.yaml's default states (for 1 and 2 players): every copy keeps them.
DEFAULTS = ("Zone1.Act1", "Zone1.Act1.2P")


@pytest.fixture
def dasher(tmp_path: Path) -> Callable[..., Path]:
    """Makes a copy of Dasher's folder, as a game folder of its own, with its default states and the states and
    solution movies named (``dasher("Zone2.Act1", movies=["Zone1.Act1"])``).

    A planted fault needs its own state and one next to it, not all nine states' smoke runs and six movies' replays
    (a third of the CPU each); every shipped state and movie passing is test_every_game_in_games_passes_check_game's.
    """
    return lambda *states, movies=(): dasher_copy(tmp_path, (*DEFAULTS, *states), movies)


@pytest.fixture
def trekker(tmp_path: Path) -> Path:
    """A copy of Trekker-GameBoy's folder: the command's claims on a game folder, without Dasher's 9 states' runs."""
    folder = tmp_path / "Trekker-GameBoy"
    shutil.copytree(TREKKER, folder)
    return folder


# --- Every game of the project passes ------------------------------------------------------------------


SONICS = ("SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis")


@pytest.fixture(scope="module")
def shipped_dasher() -> tuple[GameReport, dict]:
    """The shipped Dasher's check_game report, and each solution movie's replay outcome from it (by file name).

    Replaying Dasher's six movies is most of its check: the tests that read the outcomes share one run.
    """
    from retrokit.testing import movies

    outcomes = {}
    real = movies.replay

    def replay(game, movie_path, *args, **kwargs):
        outcomes[Path(movie_path).stem] = outcome = real(game, movie_path, *args, **kwargs)
        return outcome

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(movies, "replay", replay)
        report = check_game("Dasher-Genesis", frames=FRAMES)
    return report, outcomes


@pytest.mark.parametrize("name", sorted(p.name for p in repo_games_dir().iterdir() if p.is_dir()))
def test_every_game_in_games_passes_check_game(name: str, request: pytest.FixtureRequest) -> None:
    report = request.getfixturevalue("shipped_dasher")[0] if name == "Dasher-Genesis" else check_game(name, frames=FRAMES)
    assert report.passed, render(report)
    checks = {r.check for r in report.results if r.status == PASS}
    assert {"data file", "scenario compiles"} <= checks
    if name == "Dasher-Genesis":  # the ROM is here: everything ran
        assert {"schema", "fields in RAM", "state loads", "smoke run", "deterministic", "movie"} <= checks
        assert len(report.find("movie start state", status=PASS)) == 6, render(report)  # loaded with the states
        assert not report.find("smoke run", status=SKIP)
    elif name in SONICS:  # without its ROM: what was checked, and what was skipped and why
        assert {"schema", "fields in RAM", "state parses", "fields decode", "table coverage"} <= checks
        skipped = {r.check: r.message for r in report.results if r.status == SKIP}
        assert "no ROM" in skipped["smoke run"] and "not loaded" in skipped["state loads"]
        assert "retrokit import" in skipped["ROM"]


def test_dasher_movies_prove_the_completion_reward_and_done(shipped_dasher: tuple[GameReport, dict]) -> None:
    """Each act's solution movie is done when the act is cleared, paid its progress plus each player's bonus."""
    from retrokit.data.games import find_game
    from retrokit.testing.movies import movie_files

    game = find_game("Dasher-Genesis")
    movies = movie_files(game)
    assert sorted(movies) == ["Zone1.Act1", "Zone1.Act2", "Zone2.Act1", "Zone2.Act2", "Zone3.Act1", "Zone3.Act2"]
    assert game.default_scenario == "scenario"  # so validate's replays, under each movie's scenario, are replay(game, path)
    outcomes = shipped_dasher[1]  # validate's replays of the shipped movies
    assert sorted(outcomes) == sorted(movies)
    ends = {0: (1600, 2000), 1: (2400, 2640), 2: (2960, 3200)}
    for name in movies:
        zone, act = int(name[4]) - 1, int(name[-1]) - 1
        outcome = outcomes[name]
        assert outcome.done_at == outcome.frames, f"{name}: done must come with the clear, the movie's last frame"
        progress = outcome.reward - 2 * 1000  # both players' rewards carry the clear bonus
        assert 0 <= progress - (ends[zone][act] - 48) <= 3, f"{name}: paid {outcome.reward}"


@pytest.mark.parametrize("game,state", [("Dasher-Genesis", "Zone2.Act1"), ("Airstriker-Genesis", "Level1")])
def test_the_ram_read_from_a_state_file_is_the_ram_the_core_loads(game: str, state: str) -> None:
    """The layout that lets validate read the fields of states whose ROM is missing (the Sonic games)."""
    import numpy as np

    from retrokit.data.games import find_game
    from retrokit.data.statecheck import vet_state
    from retrokit.data.states import read_state, state_ram
    from retrokit.host.emulator import Emulator

    found = find_game(game)
    data = read_state(found.state_path(state))
    with Emulator(found.system, found.require_rom()) as emu:
        emu.set_state(vet_state(data, found.system, found.require_rom(), shipped=found.state_path(state)))
        assert state_ram(data, "Genesis") == bytes(np.asarray(emu.ram))
    assert state_ram(data, "Snes") is None and state_ram(b"GENPLUS-GX 1.7.5" + bytes(100), "Genesis") is None


# --- Planted faults ----------------------------------------------------------------------------------------


def test_division_by_zero_on_one_state_fails_that_state_only(dasher: Callable[..., Path]) -> None:
    game = dasher("Zone2.Act1", "Zone2.Act2", "Zone3.Act2")
    (game / "broken.yaml").write_text("reward: 100 / (zone * 2 + act - 3)\ndone: level_done == 1\n")
    report = check_game(game, frames=FRAMES)
    bad = [r for r in report.failures if r.scenario == "broken"]
    assert [(r.check, r.state) for r in bad] == [("smoke run", "Zone2.Act2")], render(report)
    assert "division by zero" in bad[0].message
    others = report.find("smoke run", status=PASS)
    assert {r.state for r in others if r.scenario == "broken"} >= {"Zone1.Act1", "Zone2.Act1", "Zone3.Act2"}


def test_a_table_missing_one_act_fails_coverage_for_that_state(dasher: Callable[..., Path]) -> None:
    game = dasher("Zone3.Act1", "Zone3.Act2")
    values = "\n".join(f"      {z}, {a}: {1000 + z}" for z in range(3) for a in range(2) if (z, a) != (2, 1))
    (game / "goal.yaml").write_text(
        f"tables:\n  goal:\n    by: [zone, act]\n    values:\n{values}\n"
        "reward: delta(p1_x) if p1_x < goal[zone, act] else 0\ndone: level_done == 1\n"
    )
    report = check_game(game, frames=FRAMES)
    assert failed(report) == {("table coverage", "Zone3.Act2"), ("smoke run", "Zone3.Act2")}, render(report)
    coverage = report.find("table coverage", state="Zone3.Act2")[0]
    assert "zone=2, act=1" in coverage.message and "goal.yaml" in coverage.message


#: The faults planted in ONE copy of Dasher (:func:`planted`), by state: what each plants, and the failures it must cause.
#: Each is caught by its own state's checks, which read only that state's file, so none can mask another.
PLANTED = {
    "Zone1.Act2": ("a gzip bomb", {("state loads", "Zone1.Act2")}),
    "Zone2.Act1": ("a truncated state", {("state loads", "Zone2.Act1")}),
    "Zone2.Act2": ("Airstriker's state", {("state is the game's", "Zone2.Act2")}),
    "Zone2.Act1.2P": ("a state recorded on another ROM", {("state is the game's", "Zone2.Act1.2P")}),
    "Zone3.Act1": ("Zone1.Act1's state", {("state is the game's", "Zone3.Act1")}),
}


@pytest.fixture(scope="module")
def planted(tmp_path_factory: pytest.TempPathFactory, airstriker_dir: Path) -> GameReport:
    """The report of one check of a Dasher copy with the faults of :data:`PLANTED`, Zone3.Act2 (last) left good.

    One check instead of one per fault: each was a probe child and the default states' smoke runs.
    """
    from retrokit.data.states import StateRecord, read_state, write_state

    game = dasher_copy(tmp_path_factory.mktemp("planted"), (*DEFAULTS, *PLANTED, "Zone3.Act2"))
    member = gzip.compress(bytes(16 << 20), compresslevel=9, mtime=0)
    (game / "Zone1.Act2.state").write_bytes(member * 48)  # 768 MiB once inflated (gzip members concatenate)
    (game / "Zone2.Act1.state").write_bytes((game / "Zone2.Act1.state").read_bytes()[:300])
    shutil.copy(airstriker_dir / "Level1.state", game / "Zone2.Act2.state")
    data = read_state(airstriker_dir / "Level1.state")
    record = StateRecord.of("Airstriker-Genesis", "0" * 40, data)  # as retrokit writes a state, on another ROM
    (game / "Zone2.Act1.2P.state").unlink()
    write_state(game / "Zone2.Act1.2P.state", data, record=record)
    shutil.copy(game / "Zone1.Act1.state", game / "Zone3.Act1.state")
    return check_game(game, frames=FRAMES)


def planted_failures(report: GameReport, state: str) -> list[Result]:
    """The failures on ``state``, after checking they are the ones its planted fault must cause."""
    what, expected = PLANTED[state]
    assert {(c, s) for c, s in failed(report) if s == state} == expected, f"{what} planted in {state}:\n{render(report)}"
    return [r for r in report.failures if r.state == state]


def test_planted_faults_fail_their_own_states_only(planted: GameReport) -> None:
    everything = set().union(*(expected for _, expected in PLANTED.values()))
    assert failed(planted) == everything, render(planted)
    # the states after them were still checked
    assert planted.find("state loads", state="Zone3.Act2", status=PASS), render(planted)
    assert planted.find("smoke run", state="Zone3.Act2", status=PASS), render(planted)


@pytest.mark.parametrize("kind", ["truncated", "garbage"])
def test_a_corrupt_state_fails_without_stopping_the_run(
    dasher: Callable[..., Path], kind: str, request: pytest.FixtureRequest
) -> None:
    if kind == "truncated":
        report = request.getfixturevalue("planted")
        assert "truncated" in planted_failures(report, "Zone2.Act1")[0].message, render(report)
    else:  # a copy of its own: whether the core crashes may hang on what the child loaded before
        game = dasher("Zone2.Act1", "Zone3.Act2")
        path = game / "Zone2.Act1.state"
        data = gzip.decompress(path.read_bytes())
        # right size and signature, random inside (seed 7: the core dies of SIGSEGV on it within the 60 frames of the child)
        path.write_bytes(gzip.compress(random_body(data, random.Random(7), keep_pointers=True)))
        report = check_game(game, frames=FRAMES)
        assert failed(report) == {("state loads", "Zone2.Act1")}, render(report)
        assert "the emulator crashed (SIG" in report.failures[0].message
    # the states after it were still checked
    assert report.find("state loads", state="Zone3.Act2", status=PASS)
    assert report.find("smoke run", state="Zone3.Act2", status=PASS)


def test_a_gzip_bomb_state_fails_without_stopping_the_run(planted: GameReport) -> None:
    assert "inflates past" in planted_failures(planted, "Zone1.Act2")[0].message  # read_state's cap, in the child
    assert planted.find("state loads", state="Zone3.Act2", status=PASS)  # the state after it was still loaded


def test_a_state_that_hangs_the_core_fails_and_the_next_child_goes_on(monkeypatch: pytest.MonkeyPatch) -> None:
    from retrokit.data import probe
    from retrokit.data.games import find_game
    from retrokit.testing import states

    # A billion idle frames a state, with a second allowed for each: every state hangs on any machine. (A
    # millisecond for 60 frames raced instead: a parent busy when the child printed read the state's start and
    # its result in one read, and the first state passed.)
    monkeypatch.setattr(probe, "PROBE_TIMEOUT", 1.0)
    game = find_game("Dasher-Genesis")
    probes = states.probe_states(game, ["Zone1.Act1", "Zone1.Act2"], game.require_rom(), frames=10**9)
    assert ["hangs the core" in p.error for p in probes.values()] == [True, True]


def test_another_games_state_is_flagged(planted: GameReport) -> None:
    assert "Airstriker-Genesis" in planted_failures(planted, "Zone2.Act2")[0].message


def test_a_state_recorded_on_another_rom_is_flagged(planted: GameReport) -> None:
    assert "recorded on the ROM with SHA-1 0000" in planted_failures(planted, "Zone2.Act1.2P")[0].message


def test_a_state_made_for_another_level_is_flagged_by_its_recipe(planted: GameReport) -> None:
    message = planted_failures(planted, "Zone3.Act1")[0].message
    assert "zone=2" in message and "found zone=0" in message


@pytest.fixture(scope="module")
def planted_movies(tmp_path_factory: pytest.TempPathFactory) -> GameReport:
    """One check of a Dasher copy with Zone1's two movies, Zone1.Act2's expected reward wrong, plus a movie without an
    outcome (Loose), a broken one (Broken) and an outcome without a movie (Gone): each movie is checked on its own."""
    # Zone1's two movies only: the wrong one fails next to a right one, without replaying all six (the
    # shipped game passing with every movie is test_every_game_in_games_passes_check_game's claim)
    game = dasher_copy(tmp_path_factory.mktemp("movies"), DEFAULTS, ["Zone1.Act1", "Zone1.Act2"])
    text = (game / "game.yaml").read_text()
    assert "\n  Zone1.Act2: {scenario: scenario, done_at: 804, reward: 3952," in text and text.endswith("}\n")
    text = text.replace("reward: 3952", "reward: 3900") + "  Gone: {reward: 1}\n  Broken: {reward: 1}\n"
    (game / "game.yaml").write_text(text)  # the movies section comes last
    shutil.copy(DASHER / "movies" / "Zone1.Act1.bk2", game / "movies" / "Loose.bk2")
    (game / "movies" / "Broken.bk2").write_bytes(b"PK\x03\x04 not really a zip")
    return check_game(game, frames=FRAMES)


def test_planted_movie_faults_fail_their_own_movies_only(planted_movies: GameReport) -> None:
    assert failed(planted_movies) == {("movie", "Zone1.Act2"), ("movie", "Gone"), ("movie", "Broken")}, (
        render(planted_movies)
    )
    assert planted_movies.find("movie", state="Zone1.Act1", status=PASS), render(planted_movies)


def test_a_movie_with_the_wrong_expected_reward_fails(planted_movies: GameReport) -> None:
    wrong = planted_movies.find("movie", state="Zone1.Act2")
    assert [r.status for r in wrong] == [FAIL], render(planted_movies)
    assert "a total reward of 3900" in wrong[0].message and "found 3952" in wrong[0].message


def test_movies_without_an_outcome_warn_and_missing_or_broken_ones_fail(planted_movies: GameReport) -> None:
    report = planted_movies
    assert [r.status for r in report.find("movie", state="Gone")] == [FAIL], render(report)
    assert [r.status for r in report.find("movie", state="Broken")] == [FAIL], render(report)
    assert report.find("movie", state="Loose")[0].status == "warn"
    assert "could not be replayed" in report.find("movie", state="Broken")[0].message


def test_a_misspelled_key_in_game_yaml_fails_with_its_line(dasher: Callable[..., Path]) -> None:
    game = dasher()
    text = (game / "game.yaml").read_text()
    (game / "game.yaml").write_text(text.replace("\nintegrate:", "\nintgrate:"))
    line = text[: text.index("\nintegrate:")].count("\n") + 2
    report = check_game(game, frames=FRAMES)
    assert {check for check, _ in failed(report)} == {"schema", "data file"}, render(report)
    schema = report.find("schema", status=FAIL)[0].message
    assert f"game.yaml:{line}:1:" in schema and "Did you mean 'integrate'?" in schema
    assert "Did you mean 'integrate'?" in report.find("data file")[0].message  # loading the game refuses it too


def test_a_field_outside_ram_fails_and_overlaps_warn(dasher: Callable[..., Path]) -> None:
    game = dasher()
    text = (game / "game.yaml").read_text()
    text = text.replace('end_x:       {address: 0xFF000A', 'end_x:       {address: 0xFE0000')
    text = text.replace('start_x:     {address: 0xFF000C', 'start_x:     {address: 0xFF000D')
    (game / "game.yaml").write_text(text)
    report = check_game(game, frames=FRAMES)
    outside = report.find("fields in RAM", status=FAIL)
    assert len(outside) == 1 and "'end_x'" in outside[0].message
    overlap = report.find("field overlap")
    assert [r.status for r in overlap] == ["warn"]
    assert "start_x (0xff000d-0xff000e) and camera_x (0xff000e-0xff000f)" in overlap[0].message


# --- The command -------------------------------------------------------------------------------------------


def test_validate_command_passes_on_the_free_games(capsys, tmp_path: Path, trekker: Path) -> None:
    # an own game by folder and a wheel game by name: the command's tables, status and JSON are the claim
    # here; every shipped game passing check_game is test_every_game_in_games_passes_check_game's
    out_json = tmp_path / "results.json"
    status = main(["validate", str(trekker), "Airstriker-Genesis", "--frames", str(COMMAND_FRAMES),
                   "--json", str(out_json)])
    out = capsys.readouterr().out
    assert status == 0, out
    assert "check" in out and "result" in out and "smoke run" in out  # the tables
    assert "2 of 2 games passed" in out
    doc = json.loads(out_json.read_text())
    assert doc["passed"] and [g["game"] for g in doc["games"]] == ["Trekker-GameBoy", "Airstriker-Genesis"]


def test_validate_command_exits_1_on_a_failure(capsys, trekker: Path) -> None:
    (trekker / "Level2.state").write_bytes(b"not a state")
    status = main(["validate", str(trekker), "--frames", str(COMMAND_FRAMES), "-q"])
    out = capsys.readouterr().out
    assert status == 1
    assert "state loads" in out and "Level2" in out and "FAIL" in out and "0 of 1 game passed" in out


def test_validate_without_names_checks_the_game_yaml_here(capsys, trekker: Path, monkeypatch) -> None:
    monkeypatch.chdir(trekker)
    assert main(["validate", "--frames", str(COMMAND_FRAMES), "-q"]) == 0
    assert "Trekker-GameBoy: all" in capsys.readouterr().out
    monkeypatch.chdir(trekker.parent)
    assert main(["validate"]) == 2
    assert "Expected game names, --all, or a game.yaml" in capsys.readouterr().err


def test_validate_an_unknown_game_is_a_one_line_error(capsys) -> None:
    assert main(["validate", "Dashr-Genesis"]) == 2
    err = capsys.readouterr().err
    assert "Did you mean 'Dasher-Genesis'?" in err and "Traceback" not in err


def test_games_are_listed_for_validate_all() -> None:
    from retrokit.commands.validate import own_games

    own = own_games()
    assert "Dasher-Genesis" in own and "Airstriker-Genesis" not in own
    assert set(own) <= {g.name for g in list_games()}


def test_validate_all_says_which_games_it_means(capsys, monkeypatch) -> None:
    """Issue 20: --all is the games not from the stable-retro wheel; the help and the run's first line say so."""
    from retrokit.commands import validate

    assert main(["validate", "--help"]) == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert "each game `retrokit games` lists whose first folder is not the stable-retro wheel's" in help_text
    own = validate.own_games()
    wheel = [g.name for g in list_games() if g.name not in own]
    assert "Airstriker-Genesis" in wheel and "Dasher-Genesis" in own
    # the smallest own game (not Dasher's 17 s of states and movies): the line, not the hour
    assert "Trekker-GameBoy" in own
    monkeypatch.setattr(validate, "own_games", lambda: ["Trekker-GameBoy"])
    assert main(["validate", "--all", "--frames", str(COMMAND_FRAMES), "-q"]) == 0
    first, *rest = capsys.readouterr().out.splitlines()
    assert first == (f"--all: 1 of the {len(list_games())} games retrokit games lists, those not from the "
                     "stable-retro wheel (name one of the others to check it): Trekker-GameBoy")
    assert any(line.startswith("Trekker-GameBoy: all") for line in rest)
