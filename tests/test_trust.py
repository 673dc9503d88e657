"""Trust in a state comes from this machine or the package, never from the file: forged records, the one checked load.

A corrupt state kills Genesis Plus GX (SIGSEGV); every case that could reach
the core runs in a child process (tests/childproc.py), with a fresh data
folder (no probe verdict cached), so a regression fails the test instead of
killing the suite.
"""

from __future__ import annotations

import gzip
import shutil
import zipfile
from pathlib import Path

import pytest
import yaml
from childproc import MAX_RSS_MB, REPO, run_child, run_cli, run_cli_cases
from probestore import seed_shipped

from retrokit.data.games import find_game
from retrokit.data.shipped import STATE_HASHES, WHEEL_STATE_HASHES, state_hashes, wheel_state_hashes
from retrokit.data.states import StateRecord, compress_state, read_state, read_state_file
from retrokit.errors import StateError
from retrokit.movie import Movie, write_bk2
from retrokit.movie.model import STATE_DIGEST

DASHER = REPO / "games" / "Dasher-Genesis"


@pytest.fixture(scope="module")
def forged(corrupt_state: bytes) -> StateRecord:
    """A record that vouches for the corrupt state exactly as retrokit would for one it wrote."""
    game = find_game("Dasher-Genesis")
    return StateRecord.of(game.name, game.sha1s[0], corrupt_state)


@pytest.fixture
def data(tmp_path: Path) -> dict[str, str]:
    """A fresh data folder for the child: no verdict cached, nothing written by this machine."""
    return {"RETROKIT_DATA": str(tmp_path / "data")}


def forged_movie(path: Path, state: bytes, record: StateRecord) -> Path:
    movie = Movie("Dasher-Genesis", "Genesis", 1, state, [(0,)] * 30)
    movie.header.update({"SHA1": record.rom_sha1, STATE_DIGEST: record.sha256})
    write_bk2(path, movie)
    return path


def assert_refused(child, *, status: int = 2) -> None:
    assert child.signal is None and child.returncode == status, child.describe()
    last = child.stderr.strip().splitlines()[-1]
    assert last.startswith("retrokit: error:") and "SIGSEGV" in last and "Traceback" not in child.stderr, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()


# --- a forged record vouches for nothing ----------------------------------------------------------


def test_make_probes_a_state_whose_record_is_forged(tmp_path: Path, corrupt_state: bytes, forged, data) -> None:
    path = tmp_path / "forged.state"
    path.write_bytes(compress_state(corrupt_state, forged))
    assert read_state_file(path).record.describes(corrupt_state)  # the record is as good as retrokit's own
    child = run_child(
        "import retrokit\nfrom retrokit.errors import StateError\n"
        f"try:\n    retrokit.make('Dasher-Genesis', {str(path)!r}).reset()\n    print('played')\n"
        "except StateError as exc:\n    print('refused:', exc)",
        env=data,
    )
    assert child.returncode == 0 and "refused:" in child.stdout and "SIGSEGV" in child.stdout, child.describe()


@pytest.fixture(scope="module")
def forged_commands(tmp_path_factory: pytest.TempPathFactory, corrupt_state: bytes, forged) -> tuple[Path, dict]:
    """The commands handed a forged state or movie, run in ONE child (tests/childproc.py's run_cli_cases), each
    with a fresh data folder of its own (no verdict cached): a child each was mostly its start and imports.

    Returns:
        The folder of the files, and each case's answer by name.
    """
    root = tmp_path_factory.mktemp("forged")
    state = root / "forged.state"
    state.write_bytes(compress_state(corrupt_state, forged))
    movie = forged_movie(root / "forged.bk2", corrupt_state, forged)
    session = str(root / "s.session")
    cases = {
        "playback": ["playback", str(movie), str(root / "out.gif")],
        "integrate-movie": ["integrate", "Dasher-Genesis", "Made", "--movie", str(movie)],
        "ramsearch-start-state": ["ramsearch", "new", "Dasher-Genesis", "--state", str(state), "--session",
                                  str(root / "start.session")],
        "ramsearch-new": ["ramsearch", "new", "Dasher-Genesis", "--session", session],  # then run the movie in it
        "ramsearch-run-movie": ["ramsearch", "run", "--movie", str(movie), "--session", session],
    }
    data = {name: {"RETROKIT_DATA": str(root / "data" / name)} for name in cases}
    data["ramsearch-run-movie"] = data["ramsearch-new"]
    for how in ("check", "force"):  # last: each sets RETROKIT_GAMES to its own copy of Dasher, with a forged state
        folder = root / how / "games" / "Dasher-Genesis"
        folder.mkdir(parents=True)
        for name in ("game.yaml", "rom.md", "scenario.yaml"):
            shutil.copy(DASHER / name, folder / name)
        (folder / "Zone1.Act1.state").write_bytes(compress_state(corrupt_state, forged))
        cases[f"integrate-{how}"] = ["integrate", "Dasher-Genesis", "--state", "Zone1.Act1", "--out", str(folder)] + (
            ["--force"] if how == "force" else [])
        data[f"integrate-{how}"] = {"RETROKIT_GAMES": str(folder.parent), "RETROKIT_DATA": str(root / "data" / how)}
    return root, run_cli_cases(cases, case_env=data, timeout=240)


def test_playback_probes_a_movie_whose_header_is_forged(forged_commands) -> None:
    root, answers = forged_commands
    assert_refused(answers["playback"])
    assert not (root / "out.gif").exists()


def test_integrate_movie_probes_a_movie_whose_header_is_forged(forged_commands) -> None:
    assert_refused(forged_commands[1]["integrate-movie"])


@pytest.mark.parametrize("how", ["start-state", "run-movie"])
def test_ramsearch_probes_a_forged_state_or_movie(forged_commands, how: str) -> None:
    answers = forged_commands[1]
    if how == "run-movie":
        assert answers["ramsearch-new"].returncode == 0, answers["ramsearch-new"].describe()
    assert_refused(answers[f"ramsearch-{how}"])


@pytest.fixture
def dasher_copy(tmp_path: Path) -> Path:
    folder = tmp_path / "games" / "Dasher-Genesis"
    folder.mkdir(parents=True)
    for name in ("game.yaml", "rom.md", "scenario.yaml"):
        shutil.copy(DASHER / name, folder / name)
    return folder


@pytest.mark.parametrize("force", [False, True], ids=["check", "force"])
def test_integrate_over_a_state_with_a_forged_record(forged_commands, corrupt_state: bytes, forged, force: bool) -> None:
    root, answers = forged_commands
    how = "force" if force else "check"
    child, damaged = answers[f"integrate-{how}"], root / how / "games" / "Dasher-Genesis" / "Zone1.Act1.state"
    assert child.signal is None and child.returncode == (0 if force else 1), child.describe()
    assert ("replaced" if force else "damaged") in child.stdout, child.describe()
    assert (read_state(damaged) != corrupt_state) if force else damaged.read_bytes() == compress_state(corrupt_state, forged)


# --- unchecked loads that were, and the one replay loop -------------------------------------------------


def test_validate_reports_a_solution_movie_from_a_corrupt_state(tmp_path: Path, dasher_copy: Path,
                                                                corrupt_state: bytes, forged) -> None:
    shutil.copy(DASHER / "Zone1.Act1.state", dasher_copy)
    (dasher_copy / "movies").mkdir()
    forged_movie(dasher_copy / "movies" / "Zone1.Act1.bk2", corrupt_state, forged)
    doc = yaml.safe_load((dasher_copy / "game.yaml").read_text())
    doc.setdefault("movies", {})["Zone1.Act1"] = {"done_at": None, "reward": 0}
    doc.pop("integrate", None)
    (dasher_copy / "game.yaml").write_text(yaml.safe_dump(doc))
    # 60 frames per smoke run, not 600: the claim is the movie's replay, which plays the movie whatever --frames says
    child = run_cli(["validate", str(dasher_copy), "--frames", "60"], timeout=300,
                    env={"RETROKIT_GAMES": str(dasher_copy.parent), "RETROKIT_DATA": str(tmp_path / "data")})
    assert child.signal is None, child.describe()
    words = " ".join(child.stdout.split())  # the table wraps its cells by the width of the (tmp) paths in them
    assert "could not be replayed" in words and "SIGSEGV" in words, child.describe()


def test_play_checks_the_state_it_starts_from(tmp_path: Path, dasher_copy: Path, corrupt_state: bytes) -> None:
    (dasher_copy / "Broken.state").write_bytes(compress_state(corrupt_state))
    code = (
        "from retrokit.data.games import load_game\nfrom retrokit.envs.play import PlaySession\n"
        "from retrokit.errors import StateError\n"
        f"try:\n    PlaySession(load_game({str(dasher_copy)!r}), 'Broken', {str(tmp_path)!r})\n    print('played')\n"
        "except StateError as exc:\n    print('refused:', exc)"
    )
    env = {"RETROKIT_DATA": str(tmp_path / "data"), "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    child = run_child(code, env=env)
    assert child.returncode == 0 and "refused:" in child.stdout and "SIGSEGV" in child.stdout, child.describe()


@pytest.mark.parametrize("name", ["../escape", "a/b", "", ".hidden", "bad\x01name"],
                         ids=["dot-dot", "subfolder", "empty", "hidden", "control-character"])
def test_play_refuses_a_saved_state_name_that_is_no_name(tmp_path: Path, name: str) -> None:
    from retrokit.envs.play import PlaySession
    from retrokit.errors import InvalidArgumentError

    with pytest.raises(InvalidArgumentError, match="name of saved states"):
        PlaySession(find_game("Dasher-Genesis"), None, tmp_path, name=name)


# --- trust from this machine and from the package ---------------------------------------------------


def test_a_state_retrokit_wrote_needs_no_probe(tmp_path: Path, monkeypatch) -> None:
    from retrokit.cli import main
    from retrokit.data import probe, statecheck

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    # The movie starts from the shipped Zone1.Act1: known by its bytes, as on a machine that loaded it once, so
    # its Core.bin costs no probe child (3,300 frames); the state integrate writes at frame 100 is other bytes.
    seed_shipped(tmp_path / "data" / "state-probes")
    movie = DASHER / "movies" / "Zone1.Act1.bk2"
    assert main(["integrate", "Dasher-Genesis", "Midway", "--movie", str(movie), "--frame", "100"]) == 0
    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: pytest.fail("a state this machine wrote was probed"))
    game = find_game("Dasher-Genesis")
    made = statecheck.load_state(game, tmp_path / "data" / "games" / "Dasher-Genesis" / "Midway.state")
    assert len(made) > 0


def test_a_shipped_state_needs_no_probe_and_a_shipped_path_vouches_for_no_other_bytes(
    tmp_path: Path, corrupt_state: bytes, good_state: bytes, monkeypatch
) -> None:
    from retrokit.data import probe, statecheck

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    game = find_game("Dasher-Genesis")
    calls = []
    monkeypatch.setattr(probe, "probe_state", lambda *a, **k: calls.append(1) or probe.ProbeVerdict(False, "crashed"))
    assert statecheck.load_state(game, DASHER / "Zone1.Act1.state") == good_state
    copy = tmp_path / "Copy.state"
    shutil.copy(DASHER / "Zone1.Act1.state", copy)  # the same bytes elsewhere: shipped is by content
    assert statecheck.load_state(game, copy) == good_state and calls == []
    with pytest.raises(StateError, match="crashed"):  # other bytes do not borrow a shipped file's trust
        statecheck.vet_state(corrupt_state, "Genesis", game.require_rom(), shipped=DASHER / "Zone1.Act1.state")
    assert calls == [1]


def test_validate_spares_only_states_this_machine_vouches_for_the_run_under_input(
    tmp_path: Path, corrupt_state: bytes, good_state: bytes, forged, monkeypatch
) -> None:
    from retrokit.data import probe
    from retrokit.data.states import write_state
    from retrokit.testing import states

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    game = find_game("Dasher-Genesis")
    files = {"Shipped": DASHER / "Zone1.Act1.state", "Regzipped": tmp_path / "Regzipped.state",
             "Forged": tmp_path / "Forged.state", "Remembered": tmp_path / "Remembered.state"}
    # Good bytes in another file than the shipped one: nothing vouches for them, until this machine records a verdict.
    files["Regzipped"].write_bytes(gzip.compress(read_state(DASHER / "Zone1.Act2.state"), compresslevel=1, mtime=0))
    files["Remembered"].write_bytes(gzip.compress(good_state, compresslevel=1, mtime=0))
    probe._remember(probe.probe_key(good_state, "Genesis", game.sha1s[0]), probe.ProbeVerdict(True))
    write_state(files["Forged"], corrupt_state, record=forged)  # a record vouches for nothing
    asked = {}

    def run_child(system, rom, todo, **kwargs):
        asked.update({name: input_frames for name, _, _, input_frames in todo})
        return {}, None, probe.ProbeVerdict(False, "stopped")

    monkeypatch.setattr(probe, "run_child", run_child)
    states.probe_states(game, list(files), game.require_rom(), files=files)
    full = probe.PROBE_INPUT_FRAMES  # the probe make() runs: validate asks the same one
    assert asked == {"Shipped": 0, "Regzipped": full, "Forged": full, "Remembered": 0}


def test_the_shipped_state_hashes_are_current() -> None:
    games = REPO / "games"
    assert (games / STATE_HASHES).read_text() == state_hashes(games), (
        "games/STATES.sha256 is out of date: run python -m retrokit.data.shipped"
    )


# --- integrate's arguments ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["../../escape", "../Airstriker-Genesis/Level1", "a/b", "", "bad\x07name"],
                         ids=["dot-dot", "other-game", "subfolder", "empty", "control-character"])
def test_integrate_movie_refuses_a_state_name_that_is_no_name(tmp_path: Path, monkeypatch, capsys, name: str) -> None:
    from retrokit.cli import main

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    status = main(["integrate", "Dasher-Genesis", name, "--movie", str(DASHER / "movies" / "Zone1.Act1.bk2")])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "Expected the state name to be a plain name" in err, err
    assert not any(p.suffix == ".state" for p in tmp_path.rglob("*"))


def test_integrate_refuses_state_with_movie(tmp_path: Path, capsys) -> None:
    from retrokit.cli import main

    status = main(["integrate", "Dasher-Genesis", "X", "--state", "Y", "--movie", str(DASHER / "movies" / "Zone1.Act1.bk2")])
    err = capsys.readouterr().err
    assert status == 2 and "Expected --state or --movie, not both" in err and err.count("\n") == 1


def test_integrate_movie_refuses_an_empty_core_bin(tmp_path: Path, capsys) -> None:
    from retrokit.cli import main

    path = tmp_path / "empty-core.bk2"
    with zipfile.ZipFile(DASHER / "movies" / "Zone1.Act1.bk2") as source, zipfile.ZipFile(path, "w") as out:
        for item in source.infolist():
            out.writestr(item.filename, b"" if item.filename == "Core.bin" else source.read(item.filename))
    status = main(["integrate", "Dasher-Genesis", "X", "--movie", str(path), "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert status == 2 and "'Core.bin' to hold the movie's start state; found 0 bytes" in err and err.count("\n") == 1


def test_integrate_a_shipped_state_without_its_rom_says_the_rom_is_missing(tmp_path: Path, monkeypatch, capsys) -> None:
    from retrokit.cli import main

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    status = main(["integrate", "GreenHillZone.Act1"])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1, err
    assert "found the state shipped with the game" in err and "retrokit import" in err and "recipe" not in err, err


# --- resolved once ------------------------------------------------------------------------------------


def test_an_env_takes_the_game_state_and_scenario_resolved_once(tmp_path: Path) -> None:
    from retrokit.data.resolve import State, resolve
    from retrokit.envs.env import RetroEnv
    from retrokit.host.emulator import VettedState

    game = find_game("Dasher-Genesis")
    setup = resolve("Dasher-Genesis", "Zone1.Act2")
    assert (setup.game.name, setup.rom, setup.start.name) == (game.name, game.require_rom(), "Zone1.Act2")
    assert isinstance(setup.start.state, VettedState) and setup.scenario == game.scenario_path()
    assert resolve(game, State.NONE, {"reward": "0"}).start.state is None
    env = RetroEnv(setup, obs_type="ram")
    try:
        env.reset(seed=0)
        assert env.state_name == "Zone1.Act2" and env.scenario is not None
    finally:
        env.close()


def test_find_game_is_the_one_resolver_of_names_and_folders(dasher_copy: Path, monkeypatch) -> None:
    monkeypatch.chdir(dasher_copy)
    by_name = find_game("Dasher-Genesis-v0")
    assert by_name.name == "Dasher-Genesis" and find_game(by_name) is by_name
    assert find_game(".").folders == (Path("."),) and find_game(str(dasher_copy)).name == "Dasher-Genesis"


def test_the_wheels_state_hashes_are_current() -> None:
    """The list that knows the wheel's states by what they hold (Airstriker's, Sonic's) matches the wheel installed."""
    games = REPO / "games"
    listed = (games / WHEEL_STATE_HASHES).read_text()
    assert listed == wheel_state_hashes(), (
        "games/WHEEL-STATES.sha256 is out of date: run python -m retrokit.data.shipped"
    )
    assert "stable/Airstriker-Genesis-v0/Level1.state" in listed
    assert "stable/SonicTheHedgehog-Genesis-v0/GreenHillZone.Act1.state" in listed
