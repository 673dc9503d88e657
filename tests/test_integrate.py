"""Making and checking save states from recipes, on the test cartridge."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from retrokit.cli import main
from retrokit.data.games import find_game, load_game
from retrokit.data.integrate import integrate, make_state, recipes
from retrokit.data.statecheck import vet_state
from retrokit.data.states import read_state
from retrokit.errors import DataFileError, StateError, StateNotFoundError
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"


@pytest.fixture
def dasher_copy(tmp_path: Path) -> Path:
    """Dasher's folder without its states, as a game folder of its own."""
    folder = tmp_path / "Dasher-Genesis"
    folder.mkdir()
    for name in ("game.yaml", "rom.md", "scenario.yaml"):
        shutil.copy(DASHER / name, folder / name)
    return folder


def fields_after(game, state: bytes) -> dict[str, int]:
    with Emulator(game.system, game.require_rom()) as emu:
        emu.set_state(vet_state(state, game.system, game.require_rom()))
        return FieldReader(game.fields, emu.space).read()


@pytest.mark.parametrize("name,zone,act,players", [("Zone2.Act2", 1, 1, 1), ("Zone3.Act1.2P", 2, 0, 2)], ids=["1p", "2p"])
def test_a_recipe_reaches_its_level(name: str, zone: int, act: int, players: int) -> None:
    game = find_game("Dasher-Genesis")
    values = fields_after(game, make_state(game, recipes(game)[name]))
    assert values["game_mode"] == 1 and values["zone"] == zone and values["act"] == act
    assert (values["p2_state"] == 0) == (players == 2)


def test_integrate_makes_then_checks_then_keeps_what_differs(dasher_copy: Path) -> None:
    game = load_game(dasher_copy)
    first = integrate(game, ["Zone1.Act1", "Zone2.Act1"])
    assert [o.status for o in first] == ["made", "made"]
    again = integrate(load_game(dasher_copy), ["Zone1.Act1"])
    assert [o.status for o in again] == ["up to date"]
    # Swap in another level's state: it leads elsewhere, so it differs, and is kept.
    zone2 = (dasher_copy / "Zone2.Act1.state").read_bytes()
    (dasher_copy / "Zone1.Act1.state").write_bytes(zone2)
    assert [o.status for o in integrate(load_game(dasher_copy), ["Zone1.Act1"])] == ["differs"]
    assert (dasher_copy / "Zone1.Act1.state").read_bytes() == zone2
    assert [o.status for o in integrate(load_game(dasher_copy), ["Zone1.Act1"], force=True)] == ["replaced"]
    assert fields_after(game, read_state(dasher_copy / "Zone1.Act1.state"))["zone"] == 0


def test_the_committed_states_match_their_recipes() -> None:
    game = find_game("Dasher-Genesis")
    outcomes = integrate(game, out=game.folders[-1])  # the repository's folder: checked, and up to date
    assert {o.status for o in outcomes} == {"up to date"}
    assert len(outcomes) == 9


def test_cli_exits_1_when_a_state_differs(dasher_copy: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    monkeypatch.setenv("RETROKIT_GAMES", str(dasher_copy.parent))
    out = ["--out", str(dasher_copy)]
    assert main(["integrate", "Dasher-Genesis", "--state", "Zone1.Act1", "--state", "Zone1.Act2", *out]) == 0
    shutil.copy(dasher_copy / "Zone1.Act2.state", dasher_copy / "Zone1.Act1.state")
    assert main(["integrate", "Dasher-Genesis", "--state", "Zone1.Act1", *out]) == 1
    assert "--force" in capsys.readouterr().out


def test_a_missing_state_with_a_recipe_says_how_to_make_it(dasher_copy: Path) -> None:
    with pytest.raises(StateNotFoundError, match="retrokit integrate Dasher-Genesis"):
        load_game(dasher_copy).state_path("Zone1.Act1")


def write_recipe(folder: Path, recipe: str) -> None:
    text = (folder / "game.yaml").read_text()
    text = text[: text.index("integrate:")] + "integrate:\n" + recipe
    (folder / "game.yaml").write_text(text)


@pytest.mark.parametrize(
    "recipe,message",
    [
        ("  Zone1.Act1: {set: {zon: 0}, until: {game_mode: 1}}\n", "Did you mean 'zone'"),
        ("  Zone1.Act1: {set: {zone: 0}}\n", "expected 'until'.*or 'frames'.*found neither"),
        ("  Zone1.Act1: {press: [START], until: {game_mode: 1}, frames: 60}\n", "found both. Keep one"),
        ("  Zone1.Act1: {press: [START], frames: 0}\n", "expected frames to be a number of frames from 1"),
        ("  Zone1.Act1: {set: {zone: 0}, untill: {game_mode: 1}}\n", "Did you mean 'until'"),
        ("  Zone1.Act1: {script: '_*20 STRAT*2', frames: 60}\n", r"script at line 1, column 6: .*Did you mean 'START'\?\n_\*20 STRAT\*2\n     \^"),
        ("  Zone1.Act1: {script: '_*20 START*2', frames: 20}\n", "expected frames .20, counted from power-on. to cover"),
        ("  Zone1.Act1: {script: [START], frames: 60}\n", "Expected a script of at most"),
    ],
    ids=[
        "unknown-field", "no-until-nor-frames", "until-and-frames", "zero-frames", "unknown-key", "script-button",
        "frames-shorter-than-script", "script-not-text",
    ],
)
def test_bad_recipes_say_what_is_wrong(dasher_copy: Path, recipe: str, message: str) -> None:
    write_recipe(dasher_copy, recipe)
    with pytest.raises(DataFileError, match=message):
        recipes(load_game(dasher_copy))


def test_a_recipe_that_never_arrives_is_a_clear_error(dasher_copy: Path) -> None:
    write_recipe(dasher_copy, "  Zone1.Act1: {press: [START], until: {game_mode: 3}, max_frames: 120}\n")
    game = load_game(dasher_copy)
    with pytest.raises(StateError, match=r"reach \{'game_mode': 3\} within 120 frames; it ended at \{'game_mode': 1\}"):
        make_state(game, recipes(game)["Zone1.Act1"])


def test_a_press_and_frames_recipe_plays_that_many_frames(dasher_copy: Path) -> None:
    """A game with no fields yet can make its first state: START, then a number of frames."""
    write_recipe(dasher_copy, "  Zone1.Act1: {press: [START], frames: 100}\n  B: {press: [START], frames: 101}\n")
    game = load_game(dasher_copy)
    made = {name: fields_after(game, make_state(game, recipe)) for name, recipe in recipes(game).items()}
    assert made["Zone1.Act1"]["game_mode"] == made["B"]["game_mode"] == 1  # in play
    assert made["B"]["frame"] == made["Zone1.Act1"]["frame"] + 1  # exactly one frame more


def test_a_frames_recipe_passes_the_schema(dasher_copy: Path) -> None:
    from retrokit.data.schema import check_file

    write_recipe(dasher_copy, "  Zone1.Act1: {press: [START], frames: 100}\n")
    assert check_file(dasher_copy / "game.yaml", "game") == []
    write_recipe(dasher_copy, "  Zone1.Act1: {press: [START], frames: 100, until: {game_mode: 1}}\n")
    assert check_file(dasher_copy / "game.yaml", "game") != []
    write_recipe(dasher_copy, "  Zone1.Act1: {script: '_*20 START*2', until: {game_mode: 1}}\n")
    assert check_file(dasher_copy / "game.yaml", "game") == []
    write_recipe(dasher_copy, "  Zone1.Act1: {script: [START], until: {game_mode: 1}}\n")
    assert check_file(dasher_copy / "game.yaml", "game") != []



def test_a_state_name_inside_a_game_folder_is_that_games(dasher_copy: Path, tmp_path: Path, monkeypatch, capsys) -> None:
    """Level1 is a state of hundreds of games; run inside a game's folder, it is that game's."""
    write_recipe(dasher_copy, "  Zone1.Act1: {press: [START], frames: 100}\n  Level1: {press: [START], frames: 100}\n")
    monkeypatch.chdir(dasher_copy)
    assert main(["integrate", "Level1", "--out", str(tmp_path / "out")]) == 0
    assert capsys.readouterr().out.split()[:2] == ["Level1", "made"]
    assert (tmp_path / "out" / "Level1.state").is_file()


def test_a_script_presses_a_console_switch_once(tmp_path: Path) -> None:
    """The 2600's RESET starts Galaxian; tapped all along by press, as START is, it restarts the game every 4 frames."""
    import hashlib

    ale_py = pytest.importorskip("ale_py")
    rom = Path(ale_py.__file__).parent / "roms" / "galaxian.bin"
    folder = tmp_path / "Galaxian-Atari2600"
    folder.mkdir()
    shutil.copy(rom, folder / "rom.a26")
    (folder / "game.yaml").write_text(
        f"system: Atari2600\nroms:\n  - sha1: {hashlib.sha1(rom.read_bytes()).hexdigest()}\n"
        "fields:\n  lives: {address: 0x00B9, type: '|u1'}\n"  # the ships in reserve (docs/integrate.md)
        "integrate:\n  Wave1: {script: '_*20 RESET*2', frames: 120}\n  Tapped: {press: [RESET], frames: 120}\n"
    )
    game = load_game(folder)
    made = {name: make_state(game, recipe) for name, recipe in recipes(game).items()}
    assert fields_after(game, made["Wave1"]) == {"lives": 2}  # a ship in play, two in reserve
    assert fields_after(game, made["Tapped"]) == {"lives": 3}  # held at the game's start
    with Emulator(game.system, game.require_rom()) as emu:  # the same inputs by hand, as ramsearch run --script
        reset = emu.system.mask(["RESET"])
        for masks, frames in (([0, 0], 20), ([reset, 0], 2), ([0, 0], 98)):
            emu.run(masks, frames)
        by_hand = emu.ram.copy()
        emu.set_state(vet_state(made["Wave1"], game.system, game.require_rom()))
        assert (emu.ram == by_hand).all()
