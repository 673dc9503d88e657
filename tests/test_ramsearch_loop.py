"""A game's first state, movie and fields from a RAM search (issue 21 items 2-5), from the CLI and the API, on Dasher.

``savestate`` writes where ``retrokit integrate`` does and ``--default`` makes
``make(game)`` start there; ``movie`` writes the inputs played, which
``retrokit integrate --movie`` replays to the same RAM; ``run --script`` plays
taps, holds and waits in one run; ``filter --than N`` compares with any
earlier snapshot; ``save --range`` writes a field's range.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from incli import retrokit_in_process

from retrokit import cli
from retrokit.data.games import find_game
from retrokit.data.script import parse_script
from retrokit.data.statecheck import vet_state
from retrokit.data.states import read_state_file
from retrokit.errors import FileConflictError, InvalidArgumentError, MovieError, RamSearchError
from retrokit.host.emulator import Emulator
from retrokit.ramsearch import RamSearch

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis"
LIVES, X = 0xFF002B, 0xFF0020  # Dasher's lives and x (games/Dasher-Genesis/game.yaml)


@pytest.fixture
def data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty data folder (for this process and the commands it starts), and the cwd in tmp_path."""
    folder = tmp_path / "data"
    monkeypatch.setenv("RETROKIT_DATA", str(folder))
    monkeypatch.chdir(tmp_path)
    return folder


def ramsearch(cwd: Path, *argv: str) -> subprocess.CompletedProcess:
    """One command, as a child would run it (with this process's RETROKIT_DATA), but in this process."""
    return retrokit_in_process(cwd, "ramsearch", *argv)


def ok(done: subprocess.CompletedProcess) -> str:
    assert done.returncode == 0, done.stderr
    return done.stdout


def ram_after(state: bytes) -> bytes:
    with Emulator("Genesis", DASHER / "rom.md") as emu:
        emu.set_state(vet_state(state, "Genesis", DASHER / "rom.md"))
        return bytes(np.asarray(emu.ram))


# --- savestate and movie, from the command line ----------------------------------------------------


def test_savestate_default_and_movie_from_the_command_line(tmp_path, data):
    ok(ramsearch(tmp_path, "new", "Dasher-Genesis", "--state", "Zone1.Act1"))
    out = ok(ramsearch(tmp_path, "run", "--script", "RIGHT*40 RIGHT+B*2 _*20 LEFT*5"))
    assert out == "Snapshot 1: script RIGHT*40 RIGHT+B*2 _*20 LEFT*5 (67 frames).\n"
    with RamSearch.load(tmp_path / "ramsearch.session") as search:
        ram, state = bytes(np.asarray(search.emulator.ram)), search.emulator.get_state()

    out = ok(ramsearch(tmp_path, "savestate", "Runner.Start", "--default"))
    made = data / "games" / "Dasher-Genesis" / "Runner.Start.state"
    assert out.splitlines() == [
        f"Saved state Runner.Start of Dasher-Genesis: {made}.",
        f"Default state of Dasher-Genesis is now Runner.Start ({made.parent / 'game.yaml'}).",
    ]
    saved = read_state_file(made)
    assert saved.record is not None and saved.record.game == "Dasher-Genesis" and saved.record.describes(saved.data)
    assert ram_after(saved.data) == ram_after(state)
    overlay = (made.parent / "game.yaml").read_text()
    assert "states:\n  default: Runner.Start\n" in overlay or "  default: Runner.Start\n" in overlay
    assert overlay.startswith("# Dasher: retrokit's own test cartridge")  # a copy of the game's, comments kept
    assert find_game("Dasher-Genesis").default_state == "Runner.Start"
    assert (DASHER / "game.yaml").read_text() != overlay  # the shipped file is untouched

    import retrokit

    def first_ram(**state: str) -> bytes:
        with retrokit.make("Dasher-Genesis", **state) as env:
            env.reset(seed=0)
            return bytes(np.asarray(env.unwrapped.emulator.ram))

    default = first_ram()  # make(game) starts from the new default
    assert default == first_ram(state="Runner.Start") and default != first_ram(state="Zone1.Act1")

    # The movie of the inputs played, from Zone1.Act1: integrate --movie reproduces the session's RAM.
    out = ok(ramsearch(tmp_path, "movie", "runner.bk2"))
    assert out == "Wrote 67 frames played since the start state to runner.bk2.\n"
    ok(retrokit_in_process(tmp_path, "integrate", "Dasher-Genesis", "FromMovie", "--movie", "runner.bk2"))
    replayed = read_state_file(data / "games" / "Dasher-Genesis" / "FromMovie.state").data
    assert ram_after(replayed) == ram


def test_savestate_and_movie_refusals_are_one_line(tmp_path, data):
    ok(ramsearch(tmp_path, "new", "Dasher-Genesis", "--state", "Zone1.Act1"))
    ok(ramsearch(tmp_path, "run", "--frames", "10", "--press", "RIGHT"))
    ok(ramsearch(tmp_path, "savestate", "Mine"))
    ok(ramsearch(tmp_path, "run", "--frames", "30", "--press", "RIGHT", "--no-snapshot"))
    for argv, message in [
        (("savestate", "sub/escape"), "holds a path separator"),
        (("savestate", "Mine"), "found a different state"),
        (("run", "--script", "RIGHT*30 RIHGT*2"), "line 1, column 10: "),  # one line, then the caret's picture
        (("movie", "runner.bk2"), None),
        (("movie", "runner.bk2"), None),  # the same movie again: nothing to replace
    ]:
        done = ramsearch(tmp_path, *argv)
        if message is None:
            assert done.returncode == 0, done.stderr
            continue
        lines = 3 if argv[0] == "run" else 1
        assert done.returncode == 2 and done.stderr.count("\n") == lines and message in done.stderr, done.stderr
    assert not list(data.rglob("escape.state"))
    ok(ramsearch(tmp_path, "savestate", "Mine", "--force"))
    ok(ramsearch(tmp_path, "poke", "0xFF002B", "9"))
    done = ramsearch(tmp_path, "movie", "poked.bk2")
    assert done.returncode == 2 and "poke 0xFF002B 9" in done.stderr and not (tmp_path / "poked.bk2").exists()
    ok(ramsearch(tmp_path, "run", "--state", "Zone1.Act1", "--frames", "5"))  # a state loaded: the inputs start anew
    ok(ramsearch(tmp_path, "movie", "poked.bk2"))


def test_a_movie_from_a_start_the_core_made_here_replays_without_a_probe(tmp_path, data, monkeypatch):
    """The start state of a movie the session recorded was written by this process's core: no child probes it at
    replay (2 CPU-s). The same bytes read from a session file are probed, as any state from a file is."""
    from retrokit.data import probe
    from retrokit.movie import read_bk2
    from retrokit.movie.playback import replay

    probed: list[bytes] = []
    monkeypatch.setattr(probe, "probe_state", lambda state, *_: probed.append(state) or probe.ProbeVerdict(True))

    def replayed(search: RamSearch, movie: Path) -> None:
        for _ in replay(read_bk2(movie), search.emulator, source=movie.name):
            pass

    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.step(["RIGHT"], 5)
        search.restart_inputs()  # a start state the core made here
        search.step(["RIGHT"], 10)
        search.save(tmp_path / "s.session")
        with RamSearch.load(tmp_path / "s.session") as loaded:  # the same start, read from the file
            loaded.write_movie(tmp_path / "from-file.bk2")
            replayed(loaded, tmp_path / "from-file.bk2")
        assert len(probed) == 1
        search.step([], 3)
        search.restart_inputs()
        search.step(["LEFT"], 5)
        search.write_movie(tmp_path / "made.bk2")
        replayed(search, tmp_path / "made.bk2")
    assert len(probed) == 1  # the movie's start was remembered as this machine's when the movie was written


# --- the same, through the API -----------------------------------------------------------------------


def test_savestate_and_movie_through_the_api(tmp_path, data):
    from retrokit.movie import read_bk2

    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:
        search.run_script("START*1 _*10 RIGHT*30", snapshot=False)
        search.run(["RIGHT", "B"], 3, snapshot=False)
        assert len(search.labels) == 1  # no snapshot taken
        outcome = search.save_state("Api.Start")
        assert outcome.status == "made" and outcome.path == data / "games" / "Dasher-Genesis" / "Api.Start.state"
        assert search.save_state("Api.Start").status == "up to date"
        search.write_movie(tmp_path / "api.bk2")
        movie = read_bk2(tmp_path / "api.bk2")
        right, both = (search.emulator.system.mask(b) for b in (["RIGHT"], ["RIGHT", "B"]))
        start = search.emulator.system.mask(["START"])
        assert movie.players == 2  # Dasher is a two-player game: the movie holds both pads, as its own do
        assert movie.frames == [(start, 0)] + [(0, 0)] * 10 + [(right, 0)] * 30 + [(both, 0)] * 3
        assert movie.state == search.start_state
        search.step(["RIGHT"], 2)
        with pytest.raises(FileConflictError, match="different state"):
            search.save_state("Api.Start")
        with pytest.raises(InvalidArgumentError, match="state name"):
            search.save_state("")
        search.inputs.append((1_000_000, (0, 0)))  # as if a long script had run: the movie would be too long
        with pytest.raises(MovieError, match="at most 1,000,000 frames"):
            search.movie()
        search.poke(LIVES, 5)
        with pytest.raises(MovieError, match="poke 0xFF002B 5"):
            search.movie()


# --- input scripts -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("script", "message"),
    [
        ("", "got an empty one"),
        ("RIGHT*0", "line 1, column 7: Expected a count from 1 to 1,000,000 after '*'; found '0'.\nRIGHT*0\n      ^"),
        ("START _*x", "line 1, column 9: Expected a number of frames; found 'x'."),
        ("RIGHT+*2", "line 1, column 6: Expected"),
        ("RIGHT RIHGT*3", "line 1, column 7: Expected one of Genesis's buttons"),
        ("3:START", "port of 1 to 2"),
        ("_*999999 _*2", "at most 1,000,000 frames; got one of 1,000,001"),
    ],
    ids=["empty", "zero-frames", "frames-not-a-number", "empty-button", "button-typo", "port-3", "too-long"],
)
def test_script_mistakes_are_located(script, message):
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search, pytest.raises(InvalidArgumentError) as caught:
        search.run_script(script)
    assert message.lower() in str(caught.value).lower()


def test_a_script_taps_holds_and_waits_as_steps_would():
    steps = parse_script("START*1 _*60 RIGHT*30 RIGHT+B*2 2:START")
    assert [(s.buttons, s.frames) for s in steps] == [
        (("START",), 1),
        ((), 60),
        (("RIGHT",), 30),
        (("RIGHT", "B"), 2),
        (("2:START",), 1),
    ]
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as scripted, RamSearch("Dasher-Genesis", "Zone1.Act1") as stepped:
        scripted.run_script("RIGHT*30 _*10 RIGHT+B*2")
        for press, frames in ((["RIGHT"], 30), ([], 10), (["RIGHT", "B"], 2)):
            stepped.step(press, frames)
        stepped.snapshot()
        assert np.array_equal(scripted.engine.snapshots[-1], stepped.engine.snapshots[-1])


# --- --than N and history --------------------------------------------------------------------------


def test_than_any_earlier_snapshot_on_the_command_line(tmp_path, data):
    ok(ramsearch(tmp_path, "new", "Dasher-Genesis", "--state", "Zone1.Act1"))
    ok(ramsearch(tmp_path, "run", "--press", "RIGHT", "--frames", "60"))
    ok(ramsearch(tmp_path, "run", "--press", "LEFT", "--frames", "60"))
    out = ok(ramsearch(tmp_path, "filter", "greater", "--than", "0"))  # x: 48, 133, 68: still right of the start
    assert out.startswith("greater --than 0: ")
    ok(ramsearch(tmp_path, "filter", "less", "--than", "1"))  # ...and left of where it went
    out = ok(ramsearch(tmp_path, "history"))
    assert out.splitlines()[:4] == [
        "3 snapshots (--than N compares with snapshot N):",
        "  0  new Zone1.Act1",
        "  1  RIGHT for 60 frames",
        "  2  LEFT for 60 frames",
    ]
    assert "  greater --than 0" in out and "  less --than 1" in out
    found = json.loads(ok(ramsearch(tmp_path, "show", "--json", "--limit", "0")))
    assert {"address": X, "type": ">i2"} in [{k: c[k] for k in ("address", "type")} for c in found]
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search:  # the API says the same
        search.run(["RIGHT"], 60)
        search.run(["LEFT"], 60)
        search.filter("greater", than="0")
        search.filter("less", than="1")
        assert [{"address": c.address, "type": c.type, "values": list(c.values)} for c in search.candidates()] == found
    for than, message in [("2", "0 to 1"), ("7", "0 to 1"), ("0xFF0000000", "Expected an address in RAM")]:
        done = ramsearch(tmp_path, "filter", "increased", "--than", than)
        assert done.returncode == 2 and message in done.stderr and done.stderr.count("\n") == 1, done.stderr


def test_than_a_snapshot_needs_an_earlier_one():
    with RamSearch("Dasher-Genesis", "Zone1.Act1") as search, pytest.raises(RamSearchError, match="only snapshot 0"):
        search.filter("changed", than="0")


def test_filter_help_shows_every_form_of_than(capsys):
    assert cli.main(["ramsearch", "filter", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    for form in ("previous", "first", "N (snapshot N, numbered from 0", "0xADDRESS", "changes"):
        assert form in text


def test_run_help_documents_the_script_syntax(capsys):
    assert cli.main(["ramsearch", "run", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "START*1 _*60 RIGHT*30 RIGHT+B*2" in text and "--no-snapshot" in text


# --- save --range ------------------------------------------------------------------------------------


def test_save_writes_a_range_the_game_reads(tmp_path, data, monkeypatch):
    games = tmp_path / "games"
    shutil.copytree(DASHER, games / "Dasher-Genesis", ignore=shutil.ignore_patterns("movies"))
    game_yaml = games / "Dasher-Genesis" / "game.yaml"
    monkeypatch.setenv("RETROKIT_GAMES", str(games))
    ok(ramsearch(tmp_path, "new", "Dasher-Genesis", "--state", "Zone1.Act1"))
    out = ok(ramsearch(tmp_path, "save", "lives_too", "0xFF002B", "|u1", "--range", "0", "9"))
    assert out == f"Wrote field lives_too (0xFF002B, |u1, range [0, 9]) into {game_yaml}.\n"
    assert re.search(r'\n  lives_too: +\{address: 0xFF002B, type: "\|u1", range: \[0, 9\]\}\n', game_yaml.read_text())
    assert find_game("Dasher-Genesis").fields["lives_too"].address == LIVES  # the game still reads
    for bad, message in [(("9", "0"), "LO <= HI"), (("0", "300"), "HI <= 255"), (("a", "2"), "--range")]:
        done = ramsearch(tmp_path, "save", "other", "0xFF002B", "|u1", "--range", *bad)
        assert done.returncode == 2 and message in done.stderr and done.stderr.count("\n") == 1, done.stderr


def test_the_inputs_of_a_played_movie_begin_at_its_start(tmp_path):
    from retrokit.data.states import read_state
    from retrokit.movie import Movie, write_bk2

    right = (1 << 7, 0)
    state = read_state(DASHER / "Zone1.Act1.state")
    write_bk2(tmp_path / "right.bk2", Movie("Dasher-Genesis", "Genesis", 2, state, [right] * 45))
    with RamSearch("Dasher-Genesis", "Zone2.Act1") as search:
        search.run(["LEFT"], 10)  # before the movie: not part of its inputs
        search.play(tmp_path / "right.bk2", until=30)
        search.run(["B"], 2)
        movie = search.movie()
    assert movie.state == state and movie.frames == [right] * 30 + [(1 << 0, 0)] * 2


# --- fields of a shipped game: copy first, as the default state does ------------------------------------


def test_a_field_of_a_shipped_game_goes_to_its_copy_in_the_data_folder(tmp_path, data):
    """Issue 42: ``ramsearch save`` on a checkout's game wrote into the tracked games/<Game>/game.yaml."""
    shipped = (DASHER / "game.yaml").read_bytes()
    ok(ramsearch(tmp_path, "new", "Dasher-Genesis", "--state", "Zone1.Act1"))
    out = ok(ramsearch(tmp_path, "save", "probe_lives", "0xFF002B", "|u1"))
    copy = data / "games" / "Dasher-Genesis" / "game.yaml"
    assert out == f"Wrote field probe_lives (0xFF002B, |u1) into {copy}.\n"
    assert (DASHER / "game.yaml").read_bytes() == shipped  # the checkout's file is untouched
    assert copy.read_text().startswith("# Dasher: retrokit's own test cartridge")  # a copy, comments kept
    assert find_game("Dasher-Genesis").fields["probe_lives"].address == LIVES  # and it is the game's now
    # the default state goes to the same file by the same rule: the copy is edited, not made again
    ok(ramsearch(tmp_path, "savestate", "Mine", "--default"))
    game = find_game("Dasher-Genesis")
    assert game.default_state == "Mine" and "probe_lives" in game.fields
