"""Writing a field into a game.yaml: one line in the style of its neighbours, every other byte kept."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest

from retrokit.data.gamefiles import read_game_yaml
from retrokit.errors import DataFileError, FileConflictError, InvalidArgumentError
from retrokit.ramsearch.gamefile import add_field, set_default_state

DASHER_YAML = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis" / "game.yaml"


def changes(before: str, after: str) -> list[str]:
    return [d for d in difflib.ndiff(before.splitlines(), after.splitlines()) if d[:1] in "+-"]


def test_a_new_field_is_one_aligned_line_after_the_last(tmp_path):
    path = tmp_path / "game.yaml"
    path.write_text(DASHER_YAML.read_text())
    assert add_field(path, "lives", "0xFF002B", "|u1") is False
    assert changes(DASHER_YAML.read_text(), path.read_text()) == ['+   lives:       {address: 0xFF002B, type: "|u1"}']
    lines = path.read_text().splitlines()
    assert lines[lines.index('  lives:       {address: 0xFF002B, type: "|u1"}') - 1].startswith("  p2_deaths:")
    assert read_game_yaml(path).fields["lives"].address == 0xFF002B


def test_replacing_keeps_the_line_comment(tmp_path):
    path = tmp_path / "game.yaml"
    path.write_text(DASHER_YAML.read_text())
    with pytest.raises(FileConflictError, match="pass --force"):
        add_field(path, "p1_y", "0xFF0022", ">u2")
    assert path.read_text() == DASHER_YAML.read_text()
    assert add_field(path, "p1_y", "0xFF0022", ">u2", force=True) is True
    assert changes(DASHER_YAML.read_text(), path.read_text()) == [
        '-   p1_y:        {address: 0xFF0022, type: ">i2"}   # feet; the usual floor is 192',
        '+   p1_y:        {address: 0xFF0022, type: ">u2"}   # feet; the usual floor is 192',
    ]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            "# a game\nsystem: Genesis\n",
            '# a game\nsystem: Genesis\nfields:\n  lives: {address: 0xFF002B, type: "|u1"}\n',
        ),
        (
            "fields:  # none yet\nplayers: 1\n",
            'fields:  # none yet\n  lives: {address: 0xFF002B, type: "|u1"}\nplayers: 1\n',
        ),
        (
            "fields:\n  score:\n    address: 0xFF0010\n    type: '>d4'\n\n# states\nstates: {}\n",
            (
                "fields:\n  score:\n    address: 0xFF0010\n    type: '>d4'\n"
                '  lives: {address: 0xFF002B, type: "|u1"}\n\n# states\nstates: {}\n'
            ),
        ),
        ("system: Genesis", 'system: Genesis\nfields:\n  lives: {address: 0xFF002B, type: "|u1"}\n'),
    ],
    ids=["no-fields", "empty-fields", "block-style-fields", "no-final-newline"],
)
def test_files_of_other_shapes(tmp_path, text, expected):
    path = tmp_path / "game.yaml"
    path.write_text(text)
    add_field(path, "lives", "0xFF002B", "|u1")
    assert path.read_text() == expected


def test_flow_style_fields_are_rewritten_with_comments_kept(tmp_path):
    path = tmp_path / "game.yaml"
    path.write_text('# top\nfields: {a: {address: 0x10, type: "|u1"}}\n')
    add_field(path, "lives", "0xFF002B", "|u1")
    text = path.read_text()
    assert text.startswith("# top\n") and "0xFF002B" in text
    assert set(read_game_yaml(path).fields) == {"a", "lives"}


@pytest.mark.parametrize(
    ("text", "name", "error", "message"),
    [
        ("fields: {}\n", "2lives", InvalidArgumentError, "field name"),
        ("fields: {}\n", "p1 lives", InvalidArgumentError, "field name"),
        ("fields: [1, 2]\n", "lives", DataFileError, "'fields' to be a mapping"),
        ("fields: {a: 1\n", "lives", DataFileError, "valid YAML"),
        ("- 1\n- 2\n", "lives", DataFileError, "mapping at the top"),
        ("fields: {}\n# \udcff\n", "lives", DataFileError, "UTF-8"),
    ],
    ids=["digit-first", "space", "fields-a-list", "broken-yaml", "top-a-list", "not-utf8"],
)
def test_bad_files_and_names_are_refused_untouched(tmp_path, text, name, error, message):
    path = tmp_path / "game.yaml"
    path.write_bytes(text.encode("utf-8", "surrogateescape"))
    with pytest.raises(error, match=message):
        add_field(path, name, "0xFF002B", "|u1")
    assert path.read_bytes() == text.encode("utf-8", "surrogateescape")


def test_a_missing_file_is_an_error(tmp_path):
    with pytest.raises(DataFileError, match="Expected a game.yaml"):
        add_field(tmp_path / "nope.yaml", "lives", "0xFF002B", "|u1")


def test_windows_line_ends_are_kept(tmp_path):
    path = tmp_path / "game.yaml"
    original = DASHER_YAML.read_text().replace("\n", "\r\n")
    path.write_bytes(original.encode())
    add_field(path, "lives", "0xFF002B", "|u1")
    add_field(path, "p1_y", "0xFF0022", ">u2", force=True)
    data = path.read_bytes().decode()
    assert data.count("\r\n") == data.count("\n") == original.count("\n") + 1
    assert '  p1_y:        {address: 0xFF0022, type: ">u2"}   # feet; the usual floor is 192\r\n' in data


# --- the default state (ramsearch savestate --default) ----------------------------------------------


@pytest.mark.parametrize(
    ("before", "after"),
    [
        ("system: Genesis\n", "system: Genesis\nstates:\n  default: Mine\n"),
        ("states:\n  default: Old   # the start\nplayers: 1\n", "states:\n  default: Mine   # the start\nplayers: 1\n"),
        ("states:\n  list: [A, B]\n", "states:\n  default: Mine\n  list: [A, B]\n"),
        ("states: {default: Old, list: [A]}  # kept\n", "states: {default: Mine, list: [A]}  # kept\n"),
        ("states:\n", "states: {default: Mine}\n"),
        (
            "states:\n  default: A\n  by_players: [A, A.2P]   # 1 and 2 players\n",
            "states:\n  default: Mine\n  by_players: [Mine, A.2P]   # 1 and 2 players\n",
        ),
    ],
    ids=["no-states", "replace-keeps-comment", "insert-before-list", "flow", "empty", "by-players-first-too"],
)
def test_the_default_state_is_one_edited_line(tmp_path, before, after):
    path = tmp_path / "game.yaml"
    path.write_text(before)
    set_default_state(path, "Mine")
    assert path.read_text() == after


def test_the_default_state_of_dasher_keeps_every_other_line(tmp_path):
    path = tmp_path / "game.yaml"
    path.write_text(DASHER_YAML.read_text())
    set_default_state(path, "Zone2.Act1")
    assert changes(DASHER_YAML.read_text(), path.read_text()) == [
        "-   default: Zone1.Act1",
        "+   default: Zone2.Act1",
        "-   by_players: [Zone1.Act1, Zone1.Act1.2P]   # the default for 1 and for 2 players",
        "+   by_players: [Zone2.Act1, Zone1.Act1.2P]   # the default for 1 and for 2 players",
    ]
    assert read_game_yaml(path).default_state == "Zone2.Act1"


def test_a_range_is_written_in_the_line(tmp_path):
    path = tmp_path / "game.yaml"
    path.write_text(DASHER_YAML.read_text())
    add_field(path, "lives", "0xFF002B", "|u1", value_range=(0, 9))
    assert changes(DASHER_YAML.read_text(), path.read_text()) == [
        '+   lives:       {address: 0xFF002B, type: "|u1", range: [0, 9]}'
    ]
