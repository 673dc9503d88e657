"""Hopper, our Master System / Game Gear cartridge, on the real Genesis Plus GX core through retrokit's host.

The game is documented in tools/smscart/README.md; its RAM map is games/Hopper-Sms/game.yaml and
games/Hopper-GameGear/game.yaml (checked here against tools/smscart/src/ram.h). One source builds both ROMs; the
byte-for-byte rebuild is tests/test_cartridges.py's, every generic tool is tests/test_systems.py's.
"""

from __future__ import annotations

import re
import struct
from pathlib import Path

import pytest
import yaml

from retrokit.host.emulator import Emulator

REPO = Path(__file__).resolve().parent.parent
CART_DIR = REPO / "tools" / "smscart"
GAMES = {"Sms": REPO / "games" / "Hopper-Sms", "GameGear": REPO / "games" / "Hopper-GameGear"}
ROMS = {"Sms": "rom.sms", "GameGear": "rom.gg"}
START = {"Sms": "PAUSE", "GameGear": "START"}  # the Master System's PAUSE is its NMI; the Game Gear's START a port bit
GROUND = 0xC100  # one byte per 8-pixel column: the ground's height in tiles, 0 = pit
MODE_TITLE, MODE_PLAY, MODE_CLEAR, MODE_GAMEOVER = 0, 1, 2, 3
ALIVE, DYING, OUT, ABSENT = 0, 1, 2, 3


def _fields(system: str) -> dict[str, tuple[int, str]]:
    doc = yaml.safe_load((GAMES[system] / "game.yaml").read_text())
    return {name: (int(f["address"]), f["type"]) for name, f in doc["fields"].items()}


class Hopper:
    """An emulator running one of Hopper's ROMs, with the game's fields by name."""

    def __init__(self, system: str) -> None:
        self.system = system
        self.fields = _fields(system)
        self.emu = Emulator.for_rom(GAMES[system] / ROMS[system])
        self.mask = self.emu.system.mask

    def __getitem__(self, name: str) -> int:
        address, code = self.fields[name]
        return self.emu.peek(address, code)

    def __setitem__(self, name: str, value: int) -> None:
        address, code = self.fields[name]
        self.emu.poke(address, value, code)

    def run(self, p1=(), p2=(), frames: int = 1) -> None:
        self.emu.run([self.mask(list(p1)), self.mask(list(p2))], frames)

    def run_until(self, condition, p1=(), p2=(), limit: int = 600) -> int:
        """Run frames holding the buttons until ``condition()``; return the frames run."""
        for n in range(limit):
            if condition():
                return n
            self.run(p1, p2)
        raise AssertionError(f"condition not met within {limit} frames")

    def boot(self) -> None:
        self.run_until(lambda: self["frame"] >= 2, limit=120)
        assert self["game_mode"] == MODE_TITLE

    def start(self, p1=None, p2=()) -> None:
        """Press the start button (or ``p1``/``p2``) for one frame at the title; wait for play."""
        self.run([START[self.system]] if p1 is None else p1, p2)
        self.run_until(lambda: self["game_mode"] == MODE_PLAY, limit=120)

    def ground(self, column: int) -> int:
        return self.emu.peek(GROUND + column)


@pytest.fixture(params=["Sms", "GameGear"])
def hopper(request) -> Hopper:
    game = Hopper(request.param)
    yield game
    game.emu.close()


@pytest.mark.parametrize("system", ["Sms", "GameGear"])
def test_game_yaml_addresses_match_the_sources_ram_map(system: str) -> None:
    header = (CART_DIR / "src" / "ram.h").read_text()
    defines = {m[1].lower(): int(m[2], 16) for m in re.finditer(r"#define ADDR_(\w+) (0x[0-9A-F]+)", header)}
    # The Player struct's members, each commented with its offset ("uint8_t lives;  /* +0x0B */").
    player = {m[1]: int(m[2], 16) for m in re.finditer(r"(\w+)(?:\[\d+\])?;\s*/\* \+(0x[0-9A-F]{2}) ", header)}
    assert {"x", "y", "vx", "vy", "state", "lives", "score", "on_ground", "deaths", "coins"} <= set(player)
    fields = _fields(system)
    for name, (address, _) in fields.items():
        if name in defines:
            assert address == defines[name], name
        elif name[:3] in ("p1_", "p2_"):
            assert address == defines[name[:2]] + player[name[3:]], name
    # crt0.s hard-codes the two bytes its interrupt handlers write.
    crt0 = (CART_DIR / "src" / "crt0.s").read_text()
    assert f"VBLANKS = {defines['vblanks']:#06X}".replace("0X", "0x") in crt0
    assert f"PAUSE   = {defines['pause']:#06X}".replace("0X", "0x") in crt0


@pytest.mark.parametrize(("system", "region"), [("Sms", 0x4), ("GameGear", 0x6)])
def test_rom_has_a_valid_tmr_sega_header(system: str, region: int) -> None:
    rom = (GAMES[system] / ROMS[system]).read_bytes()
    assert len(rom) == 0x8000
    assert rom[0x7FF0:0x7FF8] == b"TMR SEGA"
    (checksum,) = struct.unpack_from("<H", rom, 0x7FFA)
    assert checksum == sum(rom[:0x7FF0]) & 0xFFFF
    assert rom[0x7FFF] == region << 4 | 0xC  # region (4 SMS export, 6 GG export), size code 0xC = 32 KiB


def test_boots_to_the_title_with_its_build_and_screen(hopper: Hopper) -> None:
    hopper.boot()
    gg = hopper.system == "GameGear"
    assert hopper["console"] == int(gg)
    assert hopper.emu.screen().shape[:2] == ((144, 160) if gg else (192, 256))


def test_starts_moves_and_scrolls(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    assert hopper["p1_state"] == ALIVE and hopper["p1_lives"] == 3
    x0, screen0 = hopper["p1_x"], hopper.emu.screen().copy()
    hopper.run(["RIGHT"], frames=60)
    assert hopper["p1_x"] > x0 + 60
    assert hopper["camera_x"] > 0
    assert (hopper.emu.screen() != screen0).any()
    hopper.run(["B"])
    hopper.run_until(lambda: hopper["p1_on_ground"] == 0, limit=5)
    assert hopper["p1_vy"] < 0  # button 1 jumps


def test_left_and_right_together_cancel_out(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    x = hopper["p1_x"]
    hopper.run(["LEFT", "RIGHT"], frames=30)
    assert hopper["p1_x"] == x and hopper["p1_vx"] == 0


def test_button_2_jumps_too(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    hopper.run(["A"], frames=3)
    assert hopper["p1_on_ground"] == 0 and hopper["p1_vy"] < 0


def test_walking_into_a_pit_costs_a_life(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    hopper.run_until(lambda: hopper["p1_state"] == DYING, p1=["RIGHT"], limit=300)
    assert hopper["p1_lives"] == 2 and hopper["p1_deaths"] == 1
    assert hopper.ground(hopper["p1_x"] // 8) == 0
    hopper.run_until(lambda: hopper["p1_state"] == ALIVE, limit=200)  # respawned on solid ground
    assert hopper.ground(hopper["p1_x"] // 8) > 0


def test_coins_score_in_bcd(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    coins = hopper["coin_count"]
    column, row = hopper.emu.peek(0xC0A0, "|u1"), hopper.emu.peek(0xC0A1, "|u1")
    # Put the player's feet just under the first coin (it hangs over a pit).
    hopper["p1_x"] = column * 8 + 4
    hopper["p1_y"] = row * 8 + 16
    hopper["p1_vy"], hopper["p1_on_ground"] = 0, 0
    hopper.run(frames=2)
    assert hopper["p1_coins"] == 1 and hopper["p1_score"] == 10
    assert hopper.emu.peek(0xC0A1, "|u1") == row | 0x80 and hopper["coin_count"] == coins
    assert hopper.emu.peek(hopper.fields["p1_score"][0], "|u1") == 0x10  # BCD, lowest pair first


def test_landing_on_a_crawler_defeats_it(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    crawler_x = hopper.emu.peek(0xC060, "<u2")
    top = hopper.emu.peek(GROUND + crawler_x // 8)
    floor = (168 if hopper.system == "GameGear" else 192) - 8 * top
    hopper["p1_x"], hopper["p1_y"], hopper["p1_vy"], hopper["p1_on_ground"] = crawler_x, floor - 10, 0x100, 0
    hopper["camera_x"] = max(0, crawler_x - 60)
    hopper.run(frames=2)
    assert hopper.emu.peek(0xC066, "|u1") == 0  # gone
    assert hopper["p1_score"] == 100 and hopper["p1_lives"] == 3


def test_reaching_the_goal_clears_the_level_and_starts_the_next(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    end_x = hopper["end_x"]
    hopper["camera_x"] = end_x - 100
    hopper["p1_x"] = end_x - 4
    hopper["p1_y"] = (168 if hopper.system == "GameGear" else 192) - 8 * hopper.ground((end_x - 4) // 8)
    hopper.run_until(lambda: hopper["level_done"] == 1, p1=["RIGHT"], limit=30)
    assert hopper["p1_score"] == 1000
    hopper.run_until(lambda: hopper["game_mode"] == MODE_CLEAR, limit=3)
    hopper.run_until(lambda: hopper["game_mode"] == MODE_PLAY, limit=200)
    assert hopper["level"] == 1 and hopper["level_done"] == 0 and hopper["end_x"] != end_x


def test_level_select_by_poke_before_the_first_frame(hopper: Hopper) -> None:
    widths = []
    for level in range(4):
        game = Hopper(hopper.system)
        game["level"] = level  # the boot's RAM clear keeps this byte
        game.boot()
        game.start()
        assert game["level"] == level
        widths.append(game["level_width"])
        game.emu.close()
    assert widths == sorted(widths) and len(set(widths)) == 4  # each level its own, longer than the last


def test_out_of_range_level_starts_level_1(hopper: Hopper) -> None:
    hopper.boot()
    hopper["level"] = 9
    hopper.start()
    assert hopper["level"] == 0


def test_game_over_returns_to_the_title(hopper: Hopper) -> None:
    hopper.boot()
    hopper.start()
    hopper["p1_lives"] = 1
    hopper.run_until(lambda: hopper["game_mode"] == MODE_GAMEOVER, p1=["RIGHT"], limit=600)
    assert hopper["p1_state"] == OUT
    hopper.run_until(lambda: hopper["game_mode"] == MODE_TITLE, limit=300)


def test_two_players_on_the_master_system() -> None:
    game = Hopper("Sms")
    game.boot()
    game.start(p1=[], p2=["B"])  # button 1 on pad 2 starts a two-player game
    assert game["p1_state"] == ALIVE and game["p2_state"] == ALIVE
    x1, x2 = game["p1_x"], game["p2_x"]
    game.run(p1=[], p2=["RIGHT"], frames=60)
    assert game["p1_x"] == x1 and game["p2_x"] > x2 + 60  # pad 2 drives player 2 only
    game.run(p1=["LEFT"], p2=[], frames=10)
    assert game["p1_facing"] == 1 and game["p2_facing"] == 0
    game.emu.close()


def test_player_2_joins_mid_game_on_the_master_system() -> None:
    game = Hopper("Sms")
    game.boot()
    game.start()
    assert game["p2_state"] == ABSENT
    game.run(p2=["A"])
    assert game["p2_state"] == ALIVE and game["p2_lives"] == 3


def test_the_game_gear_has_one_player() -> None:
    game = Hopper("GameGear")
    game.boot()
    game.start(p1=[START["GameGear"]], p2=["B"])
    assert "p2_state" not in game.fields
    assert game.emu.peek(0xC04A, "|u1") == ABSENT  # pad 2's input brought in no one
    game.emu.close()
