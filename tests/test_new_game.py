"""``retrokit new ROM --name NAME-SYSTEM``: a game nobody integrated, from a bare ROM, seen by every command."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from runner_rom import DASHER_ROM, write_runner_rom

import retrokit
from retrokit.cli import main
from retrokit.data import roms
from retrokit.data.games import find_game
from retrokit.data.yamlfile import load_yaml
from retrokit.host.emulator import Emulator


@pytest.fixture
def data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty per-user data folder, and no RETROKIT_GAMES."""
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    monkeypatch.delenv("RETROKIT_GAMES", raising=False)
    return tmp_path / "data"


@pytest.fixture
def runner(tmp_path: Path) -> Path:
    return write_runner_rom(tmp_path / "runner.bin")


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_new_makes_the_game_in_the_users_games_folder_and_imports_its_rom(data, runner, capsys):
    status, out, err = cli(capsys, "new", str(runner), "--name", "Runner-Genesis")
    assert status == 0, err
    folder = data / "games" / "Runner-Genesis"
    sha1 = roms.rom_sha1(runner, "Genesis")
    assert f"Made Runner-Genesis (Genesis, told by its header; ROM SHA-1 {sha1})" in out
    assert "retrokit ramsearch new Runner-Genesis" in out and "retrokit validate Runner-Genesis" in out
    doc = load_yaml((folder / "game.yaml").read_text())
    assert doc["system"] == "Genesis" and [r["sha1"] for r in doc["roms"]] == [sha1]
    assert "fields" not in doc and "states" not in doc
    assert sorted(p.name for p in folder.iterdir()) == ["game.yaml"]  # no temporary file left
    assert (data / "roms" / "Runner-Genesis" / "rom.md").read_bytes() == runner.read_bytes()
    game = find_game("Runner-Genesis")
    assert game.folders == (folder,) and dict(game.fields) == {} and game.require_rom() == data / "roms" / "Runner-Genesis" / "rom.md"


def test_the_header_tells_the_system_whatever_the_extension(tmp_path):
    dasher = DASHER_ROM.read_bytes()
    nes = b"NES\x1a" + bytes(12) + bytes(16384)
    assert roms.guess_system(dasher, "x.bin")[0].name == "Genesis"  # .bin is also an N64 extension
    assert roms.guess_system(dasher, "x.nes") == (roms.get_system("Genesis"), "header")
    assert roms.guess_system(nes, "x.rom") == (roms.get_system("Nes"), "header")
    sms = bytearray(0x8000)
    sms[0x7FF0:0x7FF8], sms[0x7FFF] = b"TMR SEGA", 0x4C
    assert roms.header_system(bytes(sms)) == "Sms"
    sms[0x7FFF] = 0x6C
    assert roms.header_system(bytes(sms)) == "GameGear"
    assert roms.guess_system(bytes(100), "x.sfc") == (roms.get_system("Snes"), "extension")
    assert roms.guess_system(bytes(100), "x.bin") == (None, "")
    assert roms.guess_system(b"just some notes\n", "notes.txt") == (None, "")


def test_the_descriptors_detect_rules_tell_the_rest():
    gb = bytearray(0x8000)
    gb[0x104:0x11C] = bytes.fromhex("CEED6666CC0D000B03730083000C000D0008111F8889000E")
    assert roms.header_system(bytes(gb)) == "GameBoy"
    gb[0x143] = 0xC0  # the CGB flag
    assert roms.header_system(bytes(gb)) == "GbColor"
    x32 = bytearray(0x200)
    x32[0x100:0x108] = b"SEGA 32X"
    assert roms.header_system(bytes(x32)) == "32x"  # the longer mark wins over the Genesis's SEGA
    sms = bytearray(0x4000)
    sms[0x3FF0:0x3FF8], sms[0x3FFF] = b"TMR SEGA", 0x9C  # a region no console has: the extension tells
    assert roms.header_system(bytes(sms)) is None and roms.guess_system(bytes(sms), "x.gg")[0].name == "GameGear"
    for size in (2048, 4096, 8192, 16384, 32768):
        assert roms.guess_system(bytes(size), "x.bin") == (roms.get_system("Atari2600"), "size")
    assert roms.guess_system(bytes(4096), "x.gb") == (roms.get_system("GameBoy"), "extension")  # size needs .bin/.a26
    assert roms.guess_system(bytes(3000), "x.bin") == (None, "")
    snes = bytearray(0x10000)
    snes[0xFFD5], snes[0xFFDC:0xFFE0] = 0x21, bytes.fromhex("34125BED")  # HiROM, a wrong complement
    assert roms.header_system(bytes(snes)) is None  # a complement that does not complement the checksum
    snes[0xFFDC:0xFFE0] = (0x1234 ^ 0xFFFF).to_bytes(2, "little") + (0x1234).to_bytes(2, "little")
    assert roms.guess_system(bytes(snes), "x.bin") == (roms.get_system("Snes"), "header")
    snes[0xFFD5] = 0x00  # no map mode there: not a header
    assert roms.header_system(bytes(snes)) is None


def test_system_told_by_the_name_or_passed_when_the_rom_tells_nothing(data, tmp_path, capsys):
    blob = tmp_path / "mystery.rom"
    blob.write_bytes(bytes(range(256)) * 64)
    status, out, err = cli(capsys, "new", str(blob), "--name", "Mystery-Snes")
    assert status == 0, err
    assert "told by its name" in out and find_game("Mystery-Snes").system.name == "Snes"
    other = tmp_path / "other.rom"
    other.write_bytes(bytes(range(255, -1, -1)) * 64)
    status, out, err = cli(capsys, "new", str(other), "--name", "Other-Snes", "--system", "Snes")
    assert status == 0, err
    assert "told by its --system" in out and find_game("Other-Snes").system.name == "Snes"


def test_the_next_hint_presses_the_systems_start_button(data, tmp_path, capsys):
    """A 2600 has no START: a game begins with the console's RESET switch (`start:` in systems.yaml)."""
    blob = tmp_path / "game.a26"
    blob.write_bytes(bytes(range(256)) * 16)  # 4 KiB, no header: the extension tells the system
    status, out, err = cli(capsys, "new", str(blob), "--name", "Blob-Atari2600")
    assert status == 0, err
    assert "retrokit ramsearch run --script '_*20 RESET*2 _*98'" in out and "START" not in out
    status, out, err = cli(capsys, "new", str(write_runner_rom(tmp_path / "runner.bin")), "--name", "Runner-Genesis")
    assert status == 0 and "--script '_*20 START*2 _*98'" in out, err


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("Runner", "Expected the game's name as <Name>-<System>"),
        ("Runner-Genesis-v0", "Expected the game's name as <Name>-<System>"),
        ("../Runner-Genesis", "Expected the game's name as <Name>-<System>"),
        ("Runner-Gensis", "Did you mean 'Genesis'?"),
        ("Runner-Nes", "Expected the name to end with the ROM's system, -Genesis; found -Nes"),
        ("Dasher-Genesis", "found 'Dasher-Genesis', a known game"),
        ("dasher-Genesis", "found 'Dasher-Genesis', a known game"),
    ],
    ids=["no-system", "version-suffix", "a-path", "misspelt-system", "another-system", "taken", "taken-in-another-case"],
)
def test_a_bad_or_taken_name_is_refused(data, runner, capsys, name, message):
    status, _, err = cli(capsys, "new", str(runner), "--name", name)
    assert status == 2 and message in err, err
    assert err.count("\n") == 1  # one line, no traceback
    assert not (data / "games").exists() and not (data / "roms").exists()


def test_a_known_rom_or_a_file_that_is_no_rom_is_refused(data, tmp_path, capsys):
    status, _, err = cli(capsys, "new", str(DASHER_ROM), "--name", "Dasher2-Genesis")
    assert status == 2 and "is the ROM of Dasher-Genesis. Import it with: retrokit import" in err
    notes = tmp_path / "notes.txt"
    notes.write_text("not a rom\n")
    empty = tmp_path / "empty.md"
    empty.write_bytes(b"")
    fifo = tmp_path / "pipe.md"
    os.mkfifo(fifo)
    zero = tmp_path / "zero.md"
    zero.symlink_to("/dev/zero")
    huge = tmp_path / "huge.md"
    with open(huge, "wb") as f:  # sparse: 40 MiB on paper, nothing on disk
        f.truncate(40 * 2**20)
    for path, message in [(notes, "found none in"), (empty, "found an empty file"), (fifo, "found a FIFO"),
                          (zero, "found a device"), (huge, "at most 32 MiB"),
                          (tmp_path / "missing.md", "No such file"), (tmp_path, "found a folder")]:
        status, _, err = cli(capsys, "new", str(path), "--name", "Junk-Genesis")
        assert status == 2 and message in err, err
    assert not (data / "games").exists()


def test_an_existing_folder_is_never_overwritten(data, runner, capsys):
    folder = data / "games" / "Runner-Genesis"
    folder.mkdir(parents=True)  # the user's states of a game not made yet: a known (broken) game
    (folder / "Level1.state").write_bytes(b"mine")
    status, _, err = cli(capsys, "new", str(runner), "--name", "Runner-Genesis")
    assert status == 2 and "a known game" in err
    assert sorted(p.name for p in folder.iterdir()) == ["Level1.state"]


@pytest.mark.parametrize("where", ["data folder", "RETROKIT_GAMES"])
def test_the_new_game_is_seen_by_every_command(data, runner, tmp_path, monkeypatch, capsys, where):
    assert cli(capsys, "new", str(runner), "--name", "Runner-Genesis")[0] == 0
    folder = data / "games" / "Runner-Genesis"
    if where == "RETROKIT_GAMES":  # a game folder kept elsewhere, e.g. in the user's own repository
        mine = tmp_path / "my games"
        mine.mkdir()
        folder = Path(shutil.move(folder, mine / "Runner-Genesis"))
        monkeypatch.setenv("RETROKIT_GAMES", str(mine))
    with open(folder / "game.yaml", "a", encoding="utf-8") as f:
        f.write("integrate:\n  Level1: {press: [START], frames: 30}\n")

    status, out, _ = cli(capsys, "games", "Runner-Genesis")  # an exact name: that game only
    assert status == 0 and out.splitlines()[0].split() == ["Runner-Genesis", "ROM", "imported", "scenarios", "none",
                                                           "states:", "(none)"]
    assert out.splitlines()[1].startswith("1 game shown")

    status, out, err = cli(capsys, "integrate", "Runner-Genesis")
    assert status == 0, err
    state = data / "games" / "Runner-Genesis" / "Level1.state"
    assert out.split() == ["Level1", "made", str(state)]

    env = retrokit.make("Runner-Genesis", state="Level1", obs_type="ram")
    try:
        env.reset(seed=0)
        with Emulator("Genesis", DASHER_ROM) as emu:  # the state is in play: Dasher's game_mode byte is 1
            emu.set_state(env.emulator.get_state())
            assert emu.peek(0xFF0002, "|u1") == 1
    finally:
        env.close()

    status, out, err = cli(capsys, "validate", "Runner-Genesis")
    assert status == 0, out + err
    assert "Level1  PASS    loaded" in out

    session = tmp_path / "s.session"
    status, out, err = cli(capsys, "ramsearch", "new", "Runner-Genesis", "--state", "Level1", "--session", str(session))
    assert status == 0 and "New search of Runner-Genesis" in out, err


def test_games_with_an_exact_name_shows_that_game_only(capsys):
    status, out, _ = cli(capsys, "games", "Airstriker-Genesis")
    assert status == 0 and len(out.splitlines()) == 2 and out.startswith("Airstriker-Genesis ")
    status, out, _ = cli(capsys, "games", "Airstriker-Genesis-v0")
    assert status == 0 and len(out.splitlines()) == 2
    status, out, _ = cli(capsys, "games", "SonicTheHedgehog")  # a part of names: every game containing it
    assert status == 0 and len(out.splitlines()) > 2


def test_new_help_shows_examples(capsys):
    status, out, _ = cli(capsys, "new", "--help")
    assert status == 0 and "retrokit new ~/roms/runner.bin --name Runner-Genesis" in out


def _ines(mapper: int, prg: int = 2, chr_: int = 1, cut: int = 0) -> bytes:
    header = bytes([0x4E, 0x45, 0x53, 0x1A, prg, chr_, (mapper & 0xF) << 4, mapper & 0xF0]) + bytes(8)
    body = bytes(prg * 16384 + chr_ * 8192)
    return header + body[: len(body) - cut]


@pytest.mark.parametrize(
    "rom,message",
    [
        pytest.param(_ines(0, cut=1), "it is truncated: its iNES header gives 2 x 16 KiB", id="truncated"),
        pytest.param(_ines(0)[:10], "shorter than the 16-byte iNES header", id="header-only"),
        pytest.param(_ines(0, prg=0), "no program ROM", id="no-program"),
        pytest.param(_ines(20), "iNES mapper 20 is one the fceumm core cannot run", id="mapper-20-famicom-disk"),
    ],
)
def test_an_ines_rom_the_core_cannot_run_is_refused_in_one_line(data, tmp_path, capsys, rom: bytes, message: str):
    path = tmp_path / "broken.nes"
    path.write_bytes(rom)
    status, _, err = cli(capsys, "new", str(path), "--name", "Broken-Nes")
    assert status == 2 and message in err and err.count("\n") == 1, err


def test_missing_mappers_are_the_ones_the_core_says_it_lacks(tmp_path, caplog) -> None:
    # The descriptor's list is a measurement of this fceumm build: a ROM of a listed mapper makes the core say
    # "not supported at all", one of a mapper off the list does not.
    import logging

    from retrokit.host.emulator import Emulator

    nes = roms.get_system("Nes")
    for mapper in (4, min(nes.missing_mappers), max(nes.missing_mappers)):
        path = tmp_path / f"m{mapper}.nes"
        path.write_bytes(_ines(mapper))
        caplog.clear()
        with caplog.at_level(logging.INFO, logger="retrokit.core"), Emulator("Nes", path):
            pass
        said = any("not supported at all" in r.getMessage() for r in caplog.records)
        assert said == (mapper in nes.missing_mappers), mapper
