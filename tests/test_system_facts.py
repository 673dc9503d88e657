"""System facts in the descriptors (systems.yaml), each shown on a real core or ROM and against stable-retro.

- A 32X cartridge carries a Genesis header, and many say ``SEGA GENESIS`` or ``SEGA MEGA DRIVE`` there
  (stable-retro's own 32X test ROM does): the ``.32x`` extension tells it, as stable-retro goes by the extension.
- Its screen is 240 rows, as stable-retro shows it: picodrive announces 320x240, and stable-retro keeps that size.
  Dasher, our Genesis cartridge, runs on picodrive as a ``.32x`` (the 32X plays Genesis cartridges): a real game
  on the real core, beside stable-retro.
- A Game Boy cartridge whose header says it also runs on the Color is a Game Boy game when its file is a ``.gb``.
- Each core's state has its own cap: parallel_n64's state is 16,789,312 bytes, past the 16 MiB all shared before.
- A 2-byte field across two of FCEUmm's 1 KiB memory descriptors (one array in the core) reads the bytes that
  follow, as stable-retro reads it.
"""

from __future__ import annotations

import gzip
import hashlib
import json
from pathlib import Path

import numpy as np
import pytest
from stable_retro_game import found_by_both, write_integration

import retrokit
from retrokit.cli import main
from retrokit.data import roms
from retrokit.data.games import find_game
from retrokit.data.states import read_state, read_state_file
from retrokit.errors import StateError
from retrokit.host.systems import DEFAULT_STATE_MAX, get_system
from retrokit.paths import wheel_dir

stable_retro = pytest.importorskip("stable_retro")

REPO = Path(__file__).resolve().parent.parent
DASHER = REPO / "games" / "Dasher-Genesis" / "rom.md"
COLOR = REPO / "games" / "Trekker-GbColor" / "rom.gbc"  # our Color cartridge: CGB flag 0x80, runs on both
N64_STATE = "stable/MortalKombatTrilogy-N64-v0/LiuKangVsScorpion.Novice.state"


def test_a_32x_rom_with_a_genesis_header_is_a_32x_rom() -> None:
    data = DASHER.read_bytes()
    assert data[0x100:0x110] == b"SEGA MEGA DRIVE "  # the header a Genesis cartridge has, no "SEGA 32X"
    assert roms.guess_system(data, "game.32x") == (get_system("32x"), "extension")
    assert roms.guess_system(data, "game.md") == (get_system("Genesis"), "header")
    assert roms.guess_system(data, "game.bin") == (get_system("Genesis"), "header")  # a .bin: its header tells


def test_a_game_boy_rom_that_also_runs_on_the_color_is_a_game_boy_rom_as_a_gb(tmp_path, monkeypatch, capsys) -> None:
    data = bytearray(COLOR.read_bytes())
    assert data[0x143] == 0x80
    assert roms.guess_system(bytes(data), "game.gb") == (get_system("GameBoy"), "extension")
    assert roms.guess_system(bytes(data), "game.gbc") == (get_system("GbColor"), "header")
    plain = (REPO / "games" / "Trekker-GameBoy" / "rom.gb").read_bytes()  # CGB flag 0: a Game Boy header
    assert roms.guess_system(plain, "game.gbc") == (get_system("GbColor"), "extension")  # stable-retro's Color game
    assert roms.guess_system(plain, "game.gb") == (get_system("GameBoy"), "header")
    # `retrokit new` under a -GameBoy name, as stable-retro takes the .gb: one byte past the code changed, so no
    # game knows the ROM yet.
    data[-1] ^= 0xFF
    rom = tmp_path / "dual.gb"
    rom.write_bytes(bytes(data))
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)
    assert main(["new", str(rom), "--name", "Dual-GameBoy"]) == 0, capsys.readouterr().err
    assert "Made Dual-GameBoy (GameBoy, told by its extension" in capsys.readouterr().out
    assert find_game("Dual-GameBoy").system.name == "GameBoy"


@pytest.fixture(scope="module")
def dasher_32x(tmp_path_factory: pytest.TempPathFactory):
    """Dasher as a 32X game, in a stable-retro integration folder that both search."""
    root = tmp_path_factory.mktemp("games-32x")
    folder = root / "Dasher-32x"
    folder.mkdir()
    (folder / "rom.32x").write_bytes(DASHER.read_bytes())
    (folder / "rom.sha").write_text(hashlib.sha1(DASHER.read_bytes()).hexdigest() + "\n")
    (folder / "data.json").write_text(json.dumps({"info": {}}))  # its RAM is the 32X's: at 0, no Genesis fields
    (folder / "scenario.json").write_text(json.dumps({"reward": {"variables": {}}, "done": {"variables": {}}}))
    (folder / "metadata.json").write_text("{}")
    with found_by_both(root):
        yield "Dasher-32x"


def test_a_32x_screen_is_240_rows_as_stable_retro_shows_it(dasher_32x: str) -> None:
    theirs = stable_retro.make(dasher_32x, state=stable_retro.State.NONE, render_mode=None,
                               inttype=stable_retro.data.Integrations.CUSTOM_ONLY)  # fmt: skip
    try:
        their_obs, _ = theirs.reset(seed=0)
        for _ in range(60):
            their_obs = theirs.step(theirs.action_space.sample() * 0)[0]
    finally:
        theirs.close()
    with retrokit.make(dasher_32x, state=retrokit.State.NONE) as ours:
        obs, _ = ours.reset(seed=0)
        assert ours.observation_space.shape == their_obs.shape == (240, 320, 3)
        for _ in range(60):
            obs = ours.step(ours.action_space.sample() * 0)[0]
        assert obs.shape == (240, 320, 3)
        assert ours.unwrapped.emulator.screen_shape() == (224, 320)  # the core's frames: padded to the 240 rows
        assert obs[:224].any() and not obs[224:].any()


def test_parallel_n64s_state_is_read_whole_and_each_core_has_its_cap() -> None:
    path = wheel_dir() / "data" / N64_STATE
    assert len(read_state(path)) == len(read_state_file(path, "N64").data) == 16_789_312 > DEFAULT_STATE_MAX
    with pytest.raises(StateError, match="at most 16,777,216 bytes once inflated .no state of the genesis_plus_gx"):
        read_state(path, "Genesis")  # no Genesis state is that large: refused before it is inflated whole


@pytest.mark.parametrize("system", ["N64", "Saturn", "Genesis"])
def test_a_state_one_byte_past_its_cores_cap_is_refused(tmp_path: Path, system: str) -> None:
    cap = get_system(system).state_max
    path = tmp_path / "big.state"
    path.write_bytes(gzip.compress(bytes(cap + 1), 1))
    with pytest.raises(StateError, match=f"at most {cap:,} bytes once inflated"):
        read_state(path, system)
    path.write_bytes(gzip.compress(bytes(cap), 1))
    assert len(read_state(path, system)) == cap


ACROSS = {"across_ram": 0x3FF, "across_wram": 0x67FF}  # each the last byte of a 1 KiB descriptor, and the next's first


@pytest.fixture(scope="module")
def nes_across(tmp_path_factory: pytest.TempPathFactory):
    """Hopper-Nes's stable-retro integration with 2-byte fields across FCEUmm's 1 KiB descriptors, found by both."""
    root = tmp_path_factory.mktemp("nes-across")
    integration = write_integration(find_game("Hopper-Nes"), root)
    data = json.loads((integration.folder / "data.json").read_text())
    data["info"].update({name: {"address": address, "type": "<u2"} for name, address in ACROSS.items()})
    (integration.folder / "data.json").write_text(json.dumps(data))
    with found_by_both(root):
        yield integration


def test_a_field_across_two_fceumm_descriptors_reads_as_stable_retro_reads_it(nes_across) -> None:
    theirs = stable_retro.make(nes_across.name, inttype=stable_retro.data.Integrations.CUSTOM_ONLY, render_mode=None)
    try:
        with retrokit.make("Hopper-Nes", state=nes_across.after_reset) as ours:
            ours.reset(seed=0)
            emulator = ours.unwrapped.emulator
            assert emulator.system.name == "Nes" and set(ACROSS) <= set(ours.unwrapped.game.fields)
            rng = np.random.default_rng(0)
            for _ in range(4):
                for address in ACROSS.values():
                    emulator.poke(address, int(rng.integers(256)))
                    emulator.poke(address + 1, int(rng.integers(256)))
                ours_now = ours.unwrapped.reader.read()
                theirs.unwrapped.em.set_state(bytes(emulator.get_state()))
                theirs.unwrapped.data.update_ram()
                for name, address in ACROSS.items():
                    expected = emulator.peek(address) | emulator.peek(address + 1) << 8
                    assert ours_now[name] == theirs.unwrapped.data.lookup_value(name) == expected, name
    finally:
        theirs.close()
