"""ROM identity: systems by extension, and SHA-1s by stable-retro's rules."""

from __future__ import annotations

import hashlib

import pytest
from smd import interleave_smd

from retrokit import paths
from retrokit.data import roms
from retrokit.errors import InvalidArgumentError, RomError, UnsupportedSystemError
from retrokit.host.systems import get_system, system_for_extension

AIRSTRIKER_ROM = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"
AIRSTRIKER_SHA1 = "a8be7b0ca850119b167f9644e6a4a22e983d61a4"


@pytest.mark.parametrize(
    ("filename", "system"),
    [
        ("Sonic.md", "Genesis"),
        ("Sonic.smd", "Genesis"),
        ("Mario.NES", "Nes"),
        ("Zelda.sfc", "Snes"),
        ("Tetris.gb", "GameBoy"),
        ("Pokemon.gbc", "GbColor"),
        ("Alex.sms", "Sms"),
        ("Sonic.gg", "GameGear"),
        ("Pong.a26", "Atari2600"),
        ("Bonk.pce", "PCEngine"),
        ("mk2.zip", "FBNeo"),
        ("VirtuaFighter.32x", "32x"),
    ],
)
def test_detect_system(filename, system):
    assert system_for_extension(filename.rsplit('.', 1)[1]).name == system


@pytest.mark.parametrize(("filename", "suggestion"), [("Mario.nez", "'.nes'"), ("Zelda.sfx", "'.sfc'")])
def test_unknown_extension_suggests_one(filename, suggestion):
    with pytest.raises(UnsupportedSystemError) as info:
        system_for_extension(filename.rsplit(".", 1)[1])
    assert f"Did you mean {suggestion}" in str(info.value)


@pytest.mark.parametrize(("system", "ext"), [("Genesis", "md"), ("Nes", "nes"), ("Snes", "sfc"), ("FBNeo", "zip")])
def test_system_extension(system, ext):
    assert get_system(system).extensions[0] == ext


def test_unknown_system_suggests_one():
    with pytest.raises(UnsupportedSystemError, match="Did you mean 'Genesis'"):
        get_system("Genesys")


def test_airstriker_rom_matches_its_rom_sha():
    assert AIRSTRIKER_ROM.with_name("rom.sha").read_text().strip() == AIRSTRIKER_SHA1
    assert roms.rom_sha1(AIRSTRIKER_ROM) == AIRSTRIKER_SHA1
    assert roms.rom_sha1(AIRSTRIKER_ROM.read_bytes(), "Genesis") == AIRSTRIKER_SHA1


def test_nes_header_is_left_out_of_the_hash():
    body = bytes(range(256)) * 64
    header = b"NES\x1a" + bytes([2, 1]) + bytes(10)
    expected = hashlib.sha1(body).hexdigest()
    for rule in ("Nes", "nes", ".NES"):
        assert roms.rom_sha1(header + body, rule) == expected
    assert roms.rom_sha1(header + body, "Genesis") == hashlib.sha1(header + body).hexdigest()
    assert roms.groom_rom(header + body, "nes") == (header + body, expected)  # stored whole


def _plain_block() -> bytes:
    """16 KiB of plain .md ROM with the "SEGA" signature at 0x100, as real Genesis ROMs have."""
    block = bytearray(hashlib.sha256(str(i).encode()).digest()[0] for i in range(roms.SMD_BLOCK_SIZE))
    block[0x100:0x104] = b"SEGA"
    return bytes(block)


def test_smd_is_deinterleaved_by_the_documented_layout():
    plain = _plain_block() * 2
    # By hand: a 512-byte header, then per 16 KiB block the odd bytes, then the even bytes.
    smd = bytes(512) + b"".join(plain[i : i + 16384][1::2] + plain[i : i + 16384][0::2] for i in (0, 16384))
    assert roms.is_smd(smd)
    assert roms.deinterleave_smd(smd) == plain
    assert interleave_smd(plain)[512:] == smd[512:]
    assert roms.rom_sha1(smd, "smd") == hashlib.sha1(plain).hexdigest()


def test_airstriker_as_smd_hashes_like_the_md():
    smd = interleave_smd(AIRSTRIKER_ROM.read_bytes())
    assert roms.is_smd(smd) and len(smd) == 512 + AIRSTRIKER_ROM.stat().st_size
    assert roms.rom_sha1(smd, ".smd") == AIRSTRIKER_SHA1
    assert roms.groom_rom(smd, "smd")[0] == AIRSTRIKER_ROM.read_bytes()


def test_smd_without_the_signature_is_hashed_whole():
    data = bytes(4096)
    assert not roms.is_smd(data)
    assert roms.rom_sha1(data, "smd") == hashlib.sha1(data).hexdigest()


def test_too_big_rom(tmp_path):
    with pytest.raises(RomError, match="at most 32 MiB"):
        roms.rom_sha1(bytes(roms.MAX_ROM_SIZE + 1), "Genesis")
    big = tmp_path / "big.md"
    with big.open("wb") as f:
        f.truncate(roms.MAX_ROM_SIZE + 4096)
    with pytest.raises(RomError, match="big.md"):
        roms.rom_sha1(big)


def test_bytes_need_a_system():
    with pytest.raises(InvalidArgumentError, match="a system or a ROM extension"):
        roms.rom_sha1(b"abc")
    with pytest.raises(UnsupportedSystemError, match="Did you mean 'Nes'"):
        roms.rom_sha1(b"abc", "Nez")
