"""Suggestions for done: the bytes that change at the frames the user marks (issue 44 item 6).

Deaths on the NES cartridge (Hopper falls into Level1-1's first pit at frame
133 of holding RIGHT, and again at 331 after the respawn), a level's end on the
Genesis one (Dasher's solution movie of Zone1.Act1 clears it at its frame 621).
The games' game.yaml name the bytes; the suggestions are held to them.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from incli import retrokit_in_process

from retrokit.data.games import find_game
from retrokit.errors import InvalidArgumentError
from retrokit.ramsearch import events
from retrokit.ramsearch.events import suggest_done

REPO = Path(__file__).resolve().parent.parent
DEATHS = ("--script", "RIGHT*400", "--at", "133", "--at", "331")


def field_address(game: str, name: str) -> int:
    return find_game(game).fields[name].address


@pytest.fixture
def hopper_session(tmp_path, monkeypatch) -> Path:
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    assert retrokit_in_process(tmp_path, "ramsearch", "new", "Hopper-Nes", "--state", "Level1-1").returncode == 0
    return tmp_path / "ramsearch.session"


def test_the_bytes_that_change_as_the_player_dies_come_first(hopper_session, tmp_path):
    before = hopper_session.read_bytes()
    done = retrokit_in_process(tmp_path, "ramsearch", "suggest", *DEATHS)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "10 byte(s) changing at frame(s) 133, 331 (within 2) of 400 played, best first:"
    rows = [line.split() for line in lines[2:12]]
    lives, deaths, state = (field_address("Hopper-Nes", f) for f in ("p1_lives", "p1_deaths", "p1_state"))
    # the lives and the deaths count change at both deaths and nowhere else; the HUD's digit with them
    assert rows[0][:3] == [f"0x{lives:04X}", "2/2", "0"] and rows[0][-3:] == ["NAME", "<", "prev(NAME)"]
    assert rows[0][3:7] == ["3->2", "@133,", "2->1", "@331"]
    assert rows[1][:3] == [f"0x{deaths:04X}", "2/2", "0"] and rows[1][-3:] == ["NAME", ">", "prev(NAME)"]
    assert rows[2][:3] == ["0x0221", "2/2", "0"]
    # the player's state goes 0 -> 1 (dying) at each, and back to 0 at each respawn: two changes elsewhere
    assert rows[3][:3] == [f"0x{state:04X}", "2/2", "2"] and rows[3][-3:] == ["NAME", "==", "1"]
    assert lines[-1] == f"Save one as a field to use it: retrokit ramsearch save NAME 0x{lives:04X} '|u1'"
    assert hopper_session.read_bytes() == before  # played to look, never saved


def test_a_level_end_from_a_movie_on_the_genesis_cartridge(tmp_path, monkeypatch):
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    assert retrokit_in_process(tmp_path, "ramsearch", "new", "Dasher-Genesis", "--state", "Zone1.Act1").returncode == 0
    movie = REPO / "games" / "Dasher-Genesis" / "movies" / "Zone1.Act1.bk2"
    done = retrokit_in_process(tmp_path, "ramsearch", "suggest", "--movie", str(movie), "--at", "621", "--window", "0",
                               "--limit", "3")  # fmt: skip
    assert done.returncode == 0, done.stderr
    rows = [line.split() for line in done.stdout.splitlines()[2:5]]
    mode, cleared = field_address("Dasher-Genesis", "game_mode"), field_address("Dasher-Genesis", "level_done")
    assert rows[0][:5] == [f"0x{mode:06X}", "1/1", "0", "1->2", "@621"] and rows[0][-3:] == ["NAME", "==", "2"]
    assert rows[1][:5] == [f"0x{cleared:06X}", "1/1", "0", "0->1", "@621"] and rows[1][-3:] == ["NAME", "==", "1"]


def ram_of(*frames: list[int]):
    """An iterator of RAM snapshots, as the play would give them: the start, then one per frame."""
    return (np.array(frame, dtype=np.uint8) for frame in frames)


def test_ranking_on_a_made_up_play():
    #            start  f1         f2         f3         f4         f5         f6
    play = ram_of([0, 0, 0, 5], [0, 1, 0, 6], [1, 1, 0, 7], [1, 1, 0, 8], [1, 1, 9, 9], [2, 1, 9, 10], [2, 1, 9, 11])
    found, played = suggest_done(play, [2, 5], window=0)
    assert played == 6
    # byte 0 changes at both marks and nowhere else; byte 3 at both and at every other frame too
    assert [(s.address, s.hits, s.others) for s in found] == [(0, 2, 0), (3, 2, 4)]
    assert found[0].moments == ((2, 0, 1), (5, 1, 2)) and found[0].condition == "NAME > prev(NAME)"
    # a window of one frame takes byte 1's change at frame 1 as at frame 2, byte 2's at 4 as at 5, and byte 3's
    # every change but none as elsewhere
    found, _ = suggest_done(ram_of([0, 0, 0, 5], [0, 1, 0, 6], [1, 1, 0, 7], [1, 1, 0, 8], [1, 1, 9, 9],
                                   [2, 1, 9, 10], [2, 1, 9, 11]), [2, 5], window=1)  # fmt: skip
    assert [(s.address, s.hits, s.others) for s in found] == [(0, 2, 0), (3, 2, 0), (1, 1, 0), (2, 1, 0)]


@pytest.mark.parametrize(
    ("marks", "window", "message"),
    [
        ([], 2, "Expected 1 to 16 marked frames"),
        ([0], 2, "each 1 or more"),
        (list(range(1, 200, 10)), 2, "Expected 1 to 16 marked frames"),
        ([10, 14], 2, "more than 4 frames apart"),
        ([10], 61, "a window of 0 to 60"),
        ([10], -1, "a window of 0 to 60"),
        ([7], 0, "within the 6 frames played"),
    ],
    ids=["none", "frame-zero", "too-many", "too-close", "window-too-wide", "negative-window", "past-the-end"],
)
def test_bad_marks_are_refused(marks, window, message):
    with pytest.raises(InvalidArgumentError, match=message):
        suggest_done(ram_of(*[[0]] * 7), marks, window=window)


def test_a_play_longer_than_the_bound_is_refused(monkeypatch):
    monkeypatch.setattr(events, "MAX_FRAMES", 5)
    endless = (np.zeros(4, dtype=np.uint8) for _ in iter(int, 1))  # never ends by itself
    with pytest.raises(InvalidArgumentError, match="at most 5 frames"):
        suggest_done(endless, [2])


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (("--script", "RIGHT*4"), "the following arguments are required: --at"),
        (("--at", "3"), "Expected a script or a movie to play, one of them; got neither."),
        (("--at", "3", "--script", "A", "--movie", "m.bk2"), "got both"),
        (("--at", "three", "--script", "A*5"), "Expected --at as a whole number"),
        (("--at", "3", "--script", "A*5", "--limit", "0"), "Expected --limit of 1 or more"),
        (("--at", "3", "--script", "((A*9999)*99999)*99999"), "at most 1,000,000 frames"),
        (("--at", "3", "--script", "(A*5"), "In the script at line 1, column 4"),
        (("--at", "3", "--movie", "missing.bk2"), "missing.bk2"),
    ],
    ids=["no-mark", "nothing-to-play", "both", "mark-not-a-number", "limit-zero", "hostile-script", "script-syntax",
         "missing-movie"],
)  # fmt: skip
def test_bad_suggest_arguments_get_an_error(hopper_session, tmp_path, argv, message):
    done = retrokit_in_process(tmp_path, "ramsearch", "suggest", *argv)
    assert done.returncode == 2 and message in done.stderr, done.stderr


def test_a_movie_of_another_game_is_refused(hopper_session, tmp_path):
    shutil.copy(REPO / "games" / "Dasher-Genesis" / "movies" / "Zone1.Act1.bk2", tmp_path / "dasher.bk2")
    done = retrokit_in_process(tmp_path, "ramsearch", "suggest", "--movie", "dasher.bk2", "--at", "3")
    assert done.returncode == 2 and "Expected a movie of Hopper-Nes" in done.stderr
