"""Hostile game.yaml files and state recipes: every mistake is a retrokit error that names what to fix."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import retrokit
from retrokit.data.games import load_game
from retrokit.data.integrate import recipes
from retrokit.errors import DataFileError, RetrokitError

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"
GAME_YAML = (DASHER / "game.yaml").read_text()
FIELDS_AT = "  p1_lives:"
HEAD, _, _ = GAME_YAML.partition("integrate:")


def dasher_with(tmp_path: Path, text: str, states: bool = False) -> Path:
    folder = tmp_path / "Dasher-Genesis"
    folder.mkdir()
    (folder / "game.yaml").write_text(text)
    shutil.copy(DASHER / "rom.md", folder / "rom.md")
    if states:
        shutil.copy(DASHER / "Zone1.Act1.state", folder / "Zone1.Act1.state")
    return folder


def with_field(line: str) -> str:
    assert FIELDS_AT in GAME_YAML
    return GAME_YAML.replace(FIELDS_AT, f"  {line}\n{FIELDS_AT}", 1)


GAME_YAML_CASES = {
    "96-bit-mask": (with_field('big: {address: 0xFF0010, type: ">u2", mask: 0xFFFFFFFFFFFFFFFFFFFFFFFF}'),
                    "the mask of field 'big' to fit in 64 bits"),
    "duplicate-field": (with_field('p1_x: {address: 0xFF0010, type: ">u2"}'), "found the key 'p1_x' twice"),
    "duplicate-top-level-key": (GAME_YAML + "\nplayers: 1\n", "found the key 'players' twice"),
}


@pytest.mark.parametrize("case", list(GAME_YAML_CASES), ids=list(GAME_YAML_CASES))
def test_a_malformed_game_yaml_is_refused_with_what_to_fix(tmp_path: Path, case: str) -> None:
    text, message = GAME_YAML_CASES[case]
    with pytest.raises(DataFileError, match=message):
        load_game(dasher_with(tmp_path, text))


def test_a_64_bit_mask_still_loads(tmp_path: Path) -> None:
    game = load_game(dasher_with(tmp_path, with_field('wide: {address: 0xFF0010, type: ">u8", mask: 0xFFFFFFFFFFFFFFFF}')))
    assert game.fields["wide"].mask == -1  # the same 64 bits, as fields are decoded


def test_an_address_outside_ram_names_the_field(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = dasher_with(tmp_path, with_field('far: {address: 0x123456, type: ">u2"}'), states=True)
    monkeypatch.setenv("RETROKIT_GAMES", str(tmp_path))
    with pytest.raises(RetrokitError, match=r"Field 'far' \(0x123456, >u2\)"):
        retrokit.make("Dasher-Genesis", "Zone1.Act1")
    assert folder.is_dir()


RECIPE_CASES = {
    "recipe-is-a-list": ("[1, 2]", "expected a mapping with set, press, and until or frames"),
    "until-is-a-list": ("{press: [START], until: [game_mode]}", "expected 'until' to map field names"),
    "unknown-button": ("{press: [JUMP], until: {game_mode: 1}}", "found 'JUMP'"),
    "press-is-a-string": ("{press: START, until: {game_mode: 1}}", "expected press to list button names"),
    "value-is-a-word": ("{set: {zone: one}, press: [START], until: {game_mode: 1}}", "expected set 'zone' to be an integer"),
    "value-too-big-for-field": ("{set: {zone: 100000}, press: [START], until: {game_mode: 1}}", r"to fit its type \|u1"),
    "port-out-of-range": ("{press: {9: [START]}, until: {game_mode: 1}}", "expected press to name ports 1 to 2"),
    "negative-settle": ("{press: [START], until: {game_mode: 1}, settle: -5}", "expected settle to be a number of frames"),
    "unknown-field": ("{set: {zoen: 1}, until: {game_mode: 1}}", "Did you mean 'zone'"),
}


@pytest.mark.parametrize("case", list(RECIPE_CASES), ids=list(RECIPE_CASES))
def test_a_malformed_recipe_is_a_data_file_error(tmp_path: Path, case: str) -> None:
    recipe, message = RECIPE_CASES[case]
    game = load_game(dasher_with(tmp_path, f"{HEAD}integrate:\n  Zone1.Act1: {recipe}\n"))
    with pytest.raises(DataFileError, match=message):
        recipes(game)
