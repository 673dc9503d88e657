"""Repeats in the script language (issue 44 item 2): ``(DOWN*40 _*4)*60``, one grammar for every caller.

The grammar is lark's, so a mistake is located by line and column with a
caret under it; the frames a script plays are counted before anything is
expanded or played, so a hostile one is refused at once in one line. It is
played on the NES cartridge by ``ramsearch`` and read from a state recipe.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from retrokit.data.games import load_game
from retrokit.data.integrate import recipes
from retrokit.data.script import MAX_FRAMES, parse_script, script_frames
from retrokit.errors import DataFileError, InvalidArgumentError
from retrokit.ramsearch import RamSearch

REPO = Path(__file__).resolve().parent.parent


def test_a_group_repeats_its_steps():
    steps = parse_script("(DOWN*40 _*4)*60")
    assert len(steps) == 120 and script_frames(steps) == 60 * 44
    assert [(s.buttons, s.frames) for s in steps[:4]] == [(("DOWN",), 40), ((), 4), (("DOWN",), 40), ((), 4)]
    assert steps[0] is steps[2]  # a repeated step is one object: a long repeat costs a pointer a step


def test_groups_nest_and_mix_with_steps_over_lines():
    steps = parse_script("START*2\n  ((A B*2)*2 _*3)*2\nRIGHT+B")
    assert [(s.buttons, s.frames) for s in steps] == [
        (("START",), 2),
        *[(("A",), 1), (("B",), 2), (("A",), 1), (("B",), 2), ((), 3)] * 2,
        (("RIGHT", "B"), 1),
    ]
    assert parse_script("(A)") == parse_script("A") and parse_script("(A)*1") == parse_script("A*1")


@pytest.mark.parametrize(
    ("script", "where", "message"),
    [
        ("(DOWN*40 _*4))*60", "line 1, column 14", "found ')'"),
        ("(DOWN*40 _*4", "line 1, column 12", "found the end of the script"),
        ("A\n  (B*2 C)*", "line 2, column 10", "Expected a number of frames"),
        ("A\n(B*2 C)*0", "line 2, column 9", "Expected a count from 1 to 1,000,000"),
        ("()*3", "line 1, column 2", "found ')'"),
        ("A+_*3", "line 1, column 1", "Expected button names, or _ alone"),
    ],
    ids=["extra-bracket", "unclosed", "no-count", "zero-count", "empty-group", "wait-in-buttons"],
)
def test_mistakes_name_line_and_column_with_a_caret(script, where, message):
    with pytest.raises(InvalidArgumentError) as caught:
        parse_script(script)
    first, picture, caret = str(caught.value).split("\n")
    assert first.startswith(f"In the script at {where}: ") and message in first
    column = int(where.rpartition(" ")[2])
    line = script.split("\n")[int(where.split()[1].rstrip(",")) - 1]
    assert picture == line and caret == " " * (column - 1) + "^"


@pytest.mark.parametrize(
    "script",
    ["((A*9999)*99999)*99999", "(A*2)*500001", "(((((((((A*10)*10)*10)*10)*10)*10)*10)*10)*10)*10"],
    ids=["hostile-nest", "just-over", "deep-powers"],
)
def test_a_script_over_the_frame_budget_is_refused_in_one_line_before_expanding(script):
    with pytest.raises(InvalidArgumentError) as caught:
        parse_script(script, check_buttons=lambda names: pytest.fail("checked a step of a script refused whole"))
    assert "\n" not in str(caught.value) and f"at most {MAX_FRAMES:,} frames; got one of" in str(caught.value)


def test_hostile_sizes_are_refused_or_bounded():
    with pytest.raises(InvalidArgumentError, match="nested at most 16 deep"):
        parse_script("(" * 40_000 + "A" + ")" * 40_000)
    with pytest.raises(InvalidArgumentError, match="at most 100,000 characters"):
        parse_script("A " * 50_001)
    steps = parse_script("(A _)*500000")  # the most frames a script may play, a step a frame
    assert len(steps) == MAX_FRAMES and len({id(s) for s in steps}) == 2
    with pytest.raises(InvalidArgumentError, match="Expected a script of at most"):
        parse_script(b"A*3")  # not text
    with pytest.raises(InvalidArgumentError) as caught:
        parse_script("START " + "A" * 99_000, check_buttons=lambda names: names == ("START",) or pytest.fail(str(names)))
    assert "line 1, column 7: Expected button names of at most 32 characters" in str(caught.value)
    assert len(str(caught.value)) < 400  # the name is not quoted whole


def test_ramsearch_plays_a_repeat_as_its_steps_written_out_on_the_nes_cartridge():
    with RamSearch("Hopper-Nes", "Level1-1") as repeated, RamSearch("Hopper-Nes", "Level1-1") as written:
        repeated.run_script("(RIGHT*12 A*3 _*5)*4")
        written.run_script(" ".join(["RIGHT*12 A*3 _*5"] * 4))
        assert np.array_equal(repeated.engine.snapshots[-1], written.engine.snapshots[-1])
        assert not np.array_equal(repeated.engine.snapshots[-1], repeated.engine.snapshots[0])  # the game moved
        assert repeated.inputs == written.inputs and sum(f for f, _ in repeated.inputs) == 80
        assert repeated.labels[-1] == "script (RIGHT*12 A*3 _*5)*4 (80 frames)"
        with pytest.raises(InvalidArgumentError, match=r"column 10: .*Did you mean 'RIGHT'\?\n\(RIGHT\*2 RIHGT\)\*3"):
            repeated.run_script("(RIGHT*2 RIHGT)*3")


def test_a_state_recipe_takes_repeats_and_locates_its_mistakes(tmp_path):
    folder = tmp_path / "Hopper-Nes"
    shutil.copytree(REPO / "games" / "Hopper-Nes", folder)
    text = (folder / "game.yaml").read_text()
    base = text[: text.index("integrate:")] if "integrate:" in text else text
    recipe = "integrate:\n  A: {script: '(_*10 START*2)*3', frames: 60}\n  B: {script: '_*10 START*2 _*10 START*2 _*10 START*2', frames: 60}\n"
    (folder / "game.yaml").write_text(base + recipe)
    made = recipes(load_game(folder))
    assert made["A"].script == made["B"].script and sum(f for _, f in made["A"].script) == 36
    (folder / "game.yaml").write_text(base + "integrate:\n  A: {script: '(_*10 START*2*3', frames: 60}\n")
    with pytest.raises(DataFileError, match=r"In the script at line 1, column 14: Expected"):
        recipes(load_game(folder))
