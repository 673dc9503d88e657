"""The one check of a state name: nothing that names a state can write outside its game's folder."""

from __future__ import annotations

import pytest

from retrokit.data.names import MAX_NAME_BYTES, check_state_name
from retrokit.errors import InvalidArgumentError


@pytest.mark.parametrize("name", ["Level1", "Zone1.Act2", "GreenHillZone.Act1", "boss-fight_2", "Niveau é"])
def test_plain_names_pass(name):
    assert check_state_name(name) == name


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("", "is empty"),
        ("..", "names a folder"),
        (".", "names a folder"),
        ("../Airstriker-Genesis/Level1", "starts with a dot"),
        ("../../escape", "starts with a dot"),
        ("a/b", "path separator"),
        ("a\\b", "path separator"),
        ("/etc/passwd", "path separator"),
        ("Level\n1", "control character"),
        ("Level\x001", "control character"),
        ("Level\x1b[31m", "control character"),
        ("Level\u202e1", "control character"),
        ("bad\udcff", "undecodable"),
        (" Level1", "space"),
        ("Level1.state", "ends in .state"),
        ("x" * (MAX_NAME_BYTES + 1), "longer than"),
        (".hidden", "starts with a dot"),
    ],
    ids=["empty", "dotdot", "dot", "sibling-game", "escape", "subfolder", "backslash", "absolute", "newline", "nul",
         "escape-code", "bidi", "surrogate", "leading-space", "suffix", "too-long", "hidden"],
)
def test_names_that_are_not_plain_are_refused(name, why):
    with pytest.raises(InvalidArgumentError, match="Expected the state name") as caught:
        check_state_name(name)
    assert why in str(caught.value)
    assert "\n" not in str(caught.value)


def test_a_name_that_is_not_a_string_is_refused():
    with pytest.raises(InvalidArgumentError, match="got NoneType"):
        check_state_name(None)
