"""Finding games and reading their data files (retrokit's game.yaml and Gym Retro folders)."""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import pytest

from retrokit import paths
from retrokit.data import games
from retrokit.errors import (
    DataFileError,
    FieldTypeError,
    GameNotFoundError,
    RomMismatchError,
    RomNotFoundError,
    StateNotFoundError,
    UnknownNameError,
)
from retrokit.host.fields import FieldSpec

WHEEL = paths.wheel_dir()
AIRSTRIKER_DIR = WHEEL / "data" / "stable" / "Airstriker-Genesis-v0"
AIRSTRIKER_SHA1 = "a8be7b0ca850119b167f9644e6a4a22e983d61a4"
SHA_NOBODY_HAS = "0123456789abcdef0123456789abcdef01234567"

TESTBED_YAML = f"""\
system: Genesis
title: Testbed
roms:
  - sha1: {SHA_NOBODY_HAS}
    label: Testbed v1 (homebrew)
fields:
  x:      {{address: 0xFF0010, type: ">i2"}}
  lives:  {{address: 0xFF0012, type: "|u1"}}
  jumped: {{address: 0xFF0013, type: "|u1", mask: 0x80}}
states:
  default: Zone1.Act1
players: 2
notes: free-form, kept for other tools
"""


@pytest.fixture(autouse=True)
def isolated(tmp_path, monkeypatch):
    """Point the data folder at an empty temp folder and clear RETROKIT_GAMES."""
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)


@pytest.fixture
def user_games(tmp_path, monkeypatch) -> Path:
    """An empty RETROKIT_GAMES folder."""
    root = tmp_path / "games"
    root.mkdir()
    monkeypatch.setenv("RETROKIT_GAMES", str(root))
    return root


def make_yaml_game(root: Path, name: str = "Testbed-Genesis", text: str = TESTBED_YAML, states=("Zone1.Act1",)) -> Path:
    folder = root / name
    folder.mkdir()
    (folder / "game.yaml").write_text(text)
    for state in states:
        (folder / f"{state}.state").write_bytes(b"")
    return folder


# --- The wheel's integrations ---------------------------------------------------------------------


@pytest.mark.parametrize("name", ["Airstriker-Genesis", "Airstriker-Genesis-v0"])
def test_airstriker_is_reachable_with_fields_state_and_bundled_rom(name):
    game = games.find_game(name)
    assert game.name == "Airstriker-Genesis"
    assert game.system.name == "Genesis"
    assert game.folders == (AIRSTRIKER_DIR,)
    assert game.sha1s == (AIRSTRIKER_SHA1,)
    assert dict(game.fields) == {
        "gameover": FieldSpec("gameover", 0xFF0266, ">u2"),
        "lives": FieldSpec("lives", 0xFF025A, ">u2"),
        "score": FieldSpec("score", 0xFF024E, ">u4"),
    }
    assert game.default_state == "Level1"
    assert game.states == ["Level1"]
    assert game.state_path() == game.state_path("Level1.state") == AIRSTRIKER_DIR / "Level1.state"
    assert game.rom_path() == game.require_rom() == AIRSTRIKER_DIR / "rom.md"
    assert game.default_scenario == "scenario"
    assert game.scenario_path() == AIRSTRIKER_DIR / "scenario.json"
    assert game.players == 1


def _wheel_folders() -> list[Path]:
    return sorted(p for d in paths.wheel_data_dirs() for p in d.iterdir() if p.is_dir() and p.name[0] not in "._")


def test_every_wheel_integration_is_reachable_by_name():
    folders = _wheel_folders()
    start = time.perf_counter()
    failures = {}
    for folder in folders:
        name = games.normalize_name(folder.name)
        try:
            game = games.find_game(name)
            assert game.name == name and folder in game.folders
            game.fields, game.states, game.scenarios  # noqa: B018 - read them all
        except Exception as exc:  # noqa: BLE001 - collect every failure
            failures[folder.name] = repr(exc)
    elapsed = time.perf_counter() - start
    assert failures == {}
    assert len(folders) > 1000
    assert {g.name for g in games.list_games()} >= {games.normalize_name(f.name) for f in folders}
    print(f"\n{len(folders)} wheel folders loaded in {elapsed:.2f} s")
    assert elapsed < 60


def test_list_games_is_fast_and_lazy():
    games._index_cache.clear()
    start = time.perf_counter()
    listed = games.list_games()
    elapsed = time.perf_counter() - start
    print(f"\nlist_games: {len(listed)} games in {elapsed * 1000:.0f} ms (cold index)")
    assert len(listed) > 1000
    assert all("info" not in g.__dict__ for g in listed)  # no data file read yet
    assert elapsed < 5
    assert [g.name for g in listed] == sorted(g.name for g in listed)


@pytest.mark.parametrize(
    ("name", "count", "default"),
    [
        ("SonicTheHedgehog-Genesis", 17, "GreenHillZone.Act1"),
        ("SonicTheHedgehog2-Genesis", 18, "EmeraldHillZone.Act1"),
        ("SonicAndKnuckles3-Genesis", 23, "AngelIslandZone.Act1"),
    ],
    ids=["Sonic1", "Sonic2", "Sonic3K"],
)
def test_sonic_states(name, count, default):
    game = games.find_game(name)
    assert len(game.states) == count
    assert game.default_state == default
    assert all(game.state_path(s).is_file() for s in game.states)
    assert {"scenario", "contest", "xpos"} <= set(game.scenarios)


def test_sonic_games_have_58_states_in_all():
    names = ["SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis"]
    assert sum(len(games.find_game(n).states) for n in names) == 58


def test_list_games_pattern():
    names = [g.name for g in games.list_games("sonicthehedgehog2*genesis")]
    assert "SonicTheHedgehog2-Genesis" in names
    assert all(n.lower().startswith("sonicthehedgehog2") for n in names)
    assert [g.name for g in games.list_games("Airstriker")] == ["Airstriker-Genesis"]


def test_multiplayer_metadata():
    game = games.find_game("Pong-Atari2600")
    assert game.players == 2
    assert game.default_player_states == ("Start", "Start.2P")


def _repo_folders() -> list[Path]:
    root = paths.repo_games_dir()
    return sorted(p for p in root.iterdir() if games._is_game_folder(p)) if root else []


@pytest.mark.parametrize("folder", _repo_folders(), ids=lambda p: p.name)
def test_every_repo_game_folder_loads(folder):
    game = games.find_game(folder.name)
    assert game.folders[0] == folder
    for state in game.states:
        assert game.state_path(state).is_file()


# --- Names that do not exist --------------------------------------------------------------------------


def test_misspelled_game_suggests_the_right_one():
    with pytest.raises(GameNotFoundError, match="Did you mean 'SonicTheHedgehog-Genesis'") as info:
        games.find_game("SonicTheHedgehg-Genesis")
    assert "retrokit games" in str(info.value)
    assert isinstance(info.value, KeyError)  # UnknownNameError is a KeyError too


def test_missing_games_folder_is_named(tmp_path, monkeypatch):
    monkeypatch.setenv("RETROKIT_GAMES", str(tmp_path / "nowhere"))
    with pytest.raises(GameNotFoundError, match="RETROKIT_GAMES names folders that do not exist"):
        games.find_game("Testbed-Genesis")


def test_misspelled_state_suggests_the_right_one():
    game = games.find_game("SonicTheHedgehog-Genesis")
    with pytest.raises(StateNotFoundError, match="Did you mean 'GreenHillZone.Act1'"):
        game.state_path("GreenHilZone.Act1")


def test_unknown_scenario():
    with pytest.raises(UnknownNameError, match="Did you mean 'scenario'"):
        games.find_game("Airstriker-Genesis").scenario_path("scenari")


# --- retrokit game folders ------------------------------------------------------------------------------


def test_yaml_game(user_games):
    folder = make_yaml_game(user_games)
    (folder / "scenario.yaml").write_text("reward: x\n")
    game = games.find_game("Testbed-Genesis")
    assert game.folders == (folder,)
    assert game.system.name == "Genesis"
    assert game.sha1s == (SHA_NOBODY_HAS,)
    assert game.fields["jumped"] == FieldSpec("jumped", 0xFF0013, "|u1", 0x80)
    assert game.fields["x"] == FieldSpec("x", 0xFF0010, ">i2")
    assert game.players == 2
    assert game.default_state == "Zone1.Act1"
    assert game.scenarios == {"scenario": folder / "scenario.yaml"}
    assert game.info.title == "Testbed"
    assert game.info.extra == {"notes": "free-form, kept for other tools"}


def test_user_folder_comes_first_and_uses_the_wheels_states(user_games):
    text = f"roms: [{AIRSTRIKER_SHA1}]\nfields:\n  score: {{address: 0xFF024E, type: '>u4'}}\nstates: {{default: Level1}}\n"
    folder = make_yaml_game(user_games, "Airstriker-Genesis", text, states=())
    game = games.find_game("Airstriker-Genesis")
    assert game.folders == (folder, AIRSTRIKER_DIR)
    assert list(game.fields) == ["score"]
    assert game.state_path("Level1") == AIRSTRIKER_DIR / "Level1.state"
    assert game.rom_path() == AIRSTRIKER_DIR / "rom.md"


def test_declared_state_list(user_games):
    text = TESTBED_YAML.replace("  default: Zone1.Act1", "  default: Zone1.Act1\n  list: [Zone1.Act1]")
    make_yaml_game(user_games, text=text, states=("Zone1.Act1", "Scratch"))
    assert games.find_game("Testbed-Genesis").states == ["Zone1.Act1"]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("fields: {x: {address: 1, type: '>u2'}\n", "expected valid YAML; found a syntax error at line"),
        ("- just\n- a list\n", "expected the file to be a mapping"),
        ("feilds: {}\n", "Did you mean 'fields'"),
        ("fields: {x: {adress: 1, type: '|u1'}}\n", "Did you mean 'address'"),
        ("fields: {x: {address: 1}}\n", "expected field 'x' to have 'type'"),
        ("fields: {x: {address: twelve, type: '|u1'}}\n", "the address of field 'x' to be an integer"),
        ("fields: {x: {address: -4, type: '|u1'}}\n", "non-negative address"),
        ("roms: [{sha1: 1234}]\n", "SHA-1 of 40 hex digits"),
        ("players: 0\n", "'players' to be at least 1"),
        ("states: {default: Zone1.Act2}\n", "Did you mean 'Zone1.Act1'"),
        ("states: {default: Zone1.Act1, list: [Zone9]}\n", "state files for the listed states"),
        ("system: Genesys\n", "Did you mean 'Genesis'"),
    ],
    ids=["syntax", "not-a-mapping", "key-typo", "field-key-typo", "no-type", "bad-address",
         "negative-address", "bad-sha1", "no-players", "unknown-default-state", "missing-listed-state",
         "unknown-system"],
)
def test_malformed_yaml(user_games, text, message):
    folder = make_yaml_game(user_games, text=text)
    with pytest.raises((DataFileError, UnknownNameError)) as info:
        games.find_game("Testbed-Genesis")
    assert message in str(info.value)
    if isinstance(info.value, DataFileError):
        assert str(folder / "game.yaml") in str(info.value)


def test_bad_type_code(user_games):
    folder = make_yaml_game(user_games, text="fields:\n  lives: {address: 0xFF0012, type: '>x2'}\n")
    with pytest.raises(FieldTypeError) as info:
        games.find_game("Testbed-Genesis")
    assert str(folder / "game.yaml") in str(info.value) and "field 'lives'" in str(info.value)


def make_gym_game(root: Path, name: str, data: str, sha1s: str = SHA_NOBODY_HAS + "\n", **extra: str) -> Path:
    folder = root / name
    folder.mkdir()
    (folder / "data.json").write_text(data)
    (folder / "rom.sha").write_text(sha1s)
    for filename, text in extra.items():
        (folder / filename.replace("_", ".")).write_text(text)
    return folder


def test_gym_retro_folder(user_games):
    data = json.dumps({"info": {"lives": {"address": 0x75A, "type": "|u1", "mask": 15}}})
    make_gym_game(user_games, "Runner-Nes-v0", data, metadata_json='{"default_state": "Start"}')
    (user_games / "Runner-Nes-v0" / "Start.state").write_bytes(b"")
    game = games.find_game("Runner-Nes")
    assert game.system.name == "Nes"
    assert game.fields == {"lives": FieldSpec("lives", 0x75A, "|u1", 15)}
    assert game.states == ["Start"] and game.default_state == "Start"


@pytest.mark.parametrize(
    ("data", "sha1s", "message"),
    [
        ('{"info": {"lives": ', SHA_NOBODY_HAS, "data.json: expected valid JSON; found a syntax error at line 1"),
        ('{"info": {"lives": {"address": 1, "type": 5}}}', SHA_NOBODY_HAS, "the type of field 'lives' to be a type code"),
        ('{"info": [1, 2]}', SHA_NOBODY_HAS, "expected 'info' to be a mapping"),
        ('{"inf": {}}', SHA_NOBODY_HAS, "Did you mean 'info'"),
        ('{"info": {}}', "not-a-sha", "rom.sha: expected line 1 to be a SHA-1"),
    ],
    ids=["syntax", "type-not-string", "info-not-mapping", "key-typo", "bad-rom-sha"],
)
def test_malformed_data_json(user_games, data, sha1s, message):
    make_gym_game(user_games, "Broken-Nes", data, sha1s)
    with pytest.raises(DataFileError) as info:
        games.find_game("Broken-Nes")
    assert message in str(info.value)


def test_list_games_survives_a_broken_folder(user_games):
    make_gym_game(user_games, "Broken-Nes", "{")
    listed = {g.name: g for g in games.list_games()}
    assert "Broken-Nes" in listed and "Airstriker-Genesis" in listed
    with pytest.raises(DataFileError):
        listed["Broken-Nes"].fields  # noqa: B018


# --- ROMs ---------------------------------------------------------------------------------------------


def test_missing_rom_says_how_to_import(tmp_path):
    game = games.find_game("SonicTheHedgehog-Genesis")
    assert game.rom_path() is None
    with pytest.raises(RomNotFoundError) as info:
        game.require_rom()
    message = str(info.value)
    assert "retrokit import /path/to/your/roms" in message
    for sha1 in game.sha1s:
        assert sha1 in message
    assert str(tmp_path / "data" / "roms" / "SonicTheHedgehog-Genesis" / "rom.md") in message


def test_wrong_rom_in_place_is_a_mismatch(user_games, tmp_path):
    make_yaml_game(user_games)
    game = games.find_game("Testbed-Genesis")
    wrong = tmp_path / "data" / "roms" / "Testbed-Genesis" / "rom.md"
    wrong.parent.mkdir(parents=True)
    wrong.write_bytes(b"not the game")
    with pytest.raises(RomMismatchError, match=hashlib.sha1(b"not the game").hexdigest()):
        game.require_rom()


def test_imported_rom_is_found(user_games, tmp_path):
    body = b"testbed rom" * 100
    make_yaml_game(user_games, text=f"roms: [{hashlib.sha1(body).hexdigest()}]\n", states=())
    game = games.find_game("Testbed-Genesis")
    dest = game.imported_rom_path()
    assert dest == tmp_path / "data" / "roms" / "Testbed-Genesis" / "rom.md"
    dest.parent.mkdir(parents=True)
    dest.write_bytes(body)
    assert game.require_rom() == dest


def test_game_without_rom_hashes_says_so():
    with pytest.raises(RomNotFoundError, match="found none, so no ROM can be imported"):
        games.find_game("VirtuaFighter2-Genesis").require_rom()  # its rom.sha is empty in the wheel
