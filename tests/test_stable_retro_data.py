"""stable-retro's data files load as stable-retro loads them: what it skips, retrokit skips, in one warning line.

stable-retro's own test data (its tests/dummy.json) names a field at each system's RAM address, for every system,
and its tests use one such file with every system's ROM: a field outside the system's memory is left out of
``info`` (its ``lookup_all`` skips it). retrokit used to refuse the whole file. A scenario key neither knows is
tests/test_dsl_json_errors.py's. retrokit's own game.yaml stays strict.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from stable_retro_game import found_by_both, write_integration

import retrokit
from retrokit.data.games import find_game
from retrokit.errors import InvalidArgumentError, SkippedDataWarning
from retrokit.host.systems import all_systems

stable_retro = pytest.importorskip("stable_retro")

GAME = "Hopper-Nes"
REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def every_systems_field(tmp_path_factory: pytest.TempPathFactory):
    """Hopper-Nes's stable-retro integration whose data.json also names a field at each system's RAM base."""
    root = tmp_path_factory.mktemp("dummy-data")
    integration = write_integration(find_game(GAME), root)
    data = json.loads((integration.folder / "data.json").read_text())
    data["info"].update({f"at_{name}": {"address": s.ram_base, "type": "|u1"} for name, s in all_systems().items()})
    (integration.folder / "data.json").write_text(json.dumps(data))
    with found_by_both(root):
        yield integration


def test_a_data_json_naming_other_systems_fields_loads_with_one_line_saying_what_was_skipped(every_systems_field):
    with pytest.warns(SkippedDataWarning) as caught:
        ours = retrokit.make(GAME, state=every_systems_field.after_reset, action_type="all")
    (warning,) = caught
    message = str(warning.message)
    assert "\n" not in message and message.startswith(f"{every_systems_field.folder / 'data.json'}: skipped ")
    assert "at_Genesis (0xff0000)" in message and "at_Snes (0x7e0000)" in message and "at_Nes " not in message
    theirs = stable_retro.make(every_systems_field.name, inttype=stable_retro.data.Integrations.CUSTOM_ONLY,
                               render_mode=None, use_restricted_actions=stable_retro.Actions.ALL)  # fmt: skip
    try:
        ours.reset(seed=0)
        theirs.reset(seed=0)
        action = [0] * len(ours.buttons)
        info, their_info = ours.step(action)[4], theirs.step(action)[4]
        assert info == their_info  # the same fields kept (the NES's, and those at 0 or 0x80: in its RAM) and values
        assert {"at_Nes", "at_Atari2600"} <= set(info) and "at_Genesis" not in info
    finally:
        ours.close()
        theirs.close()


def test_retrokits_own_game_yaml_stays_strict(tmp_path, monkeypatch) -> None:
    folder = tmp_path / GAME
    shutil.copytree(REPO / "games" / GAME, folder)
    text = (folder / "game.yaml").read_text()
    (folder / "game.yaml").write_text(text.replace("fields:\n", "fields:\n  at_Genesis: {address: 0xFF0000, type: '|u1'}\n", 1))
    monkeypatch.setenv("RETROKIT_GAMES", str(tmp_path))
    with pytest.raises(InvalidArgumentError, match=r"Field 'at_Genesis' \(0xff0000, \|u1\): Expected an address inside"):
        retrokit.make(GAME)


def test_a_data_json_of_thousands_of_foreign_fields_is_named_in_one_short_line(tmp_path, monkeypatch) -> None:
    folder = tmp_path / GAME
    shutil.copytree(REPO / "games" / GAME, folder, ignore=shutil.ignore_patterns("game.yaml"))
    game = find_game(REPO / "games" / GAME)
    info = {name: {"address": spec.address, "type": spec.type} for name, spec in game.fields.items()}
    info.update({f"far{i}": {"address": 0x100000 + i, "type": "|u1"} for i in range(3000)})
    (folder / "data.json").write_text(json.dumps({"info": info}))
    (folder / "rom.sha").write_text("\n".join(game.sha1s) + "\n")
    monkeypatch.setenv("RETROKIT_GAMES", str(tmp_path))
    with pytest.warns(SkippedDataWarning) as caught:
        env = retrokit.make(GAME)
    env.close()
    (warning,) = caught
    message = str(warning.message)
    assert "\n" not in message and len(message) < 1000 and "skipped 3000 field(s)" in message
    assert message.endswith("and 2990 more.")
