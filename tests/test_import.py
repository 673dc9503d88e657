"""ROM import from folders and zip files, by stable-retro's hashing rules, without silent overwrites."""

from __future__ import annotations

import hashlib
import io
import zipfile
from pathlib import Path

import pytest
from smd import interleave_smd

from retrokit import paths
from retrokit.data import games
from retrokit.data.importer import import_roms
from retrokit.errors import RomNotFoundError

AIRSTRIKER_ROM = paths.wheel_dir() / "data" / "stable" / "Airstriker-Genesis-v0" / "rom.md"
NES_BODY = bytes(range(256)) * 128
NES_ROM = b"NES\x1a" + bytes([2, 0, 0x10]) + bytes(9) + NES_BODY  # a 16-byte iNES header (mapper 1), then the body


@pytest.fixture(autouse=True)
def data_dir(tmp_path, monkeypatch) -> Path:
    """An empty RETROKIT_DATA; RETROKIT_GAMES holds one fake NES game whose rom.sha is of NES_BODY."""
    root = tmp_path / "games"
    for name in ("FakeQuest-Nes", "FakeQuestTurbo-Nes"):
        (root / name).mkdir(parents=True)
        (root / name / "data.json").write_text('{"info": {}}')
        (root / name / "rom.sha").write_text(hashlib.sha1(NES_BODY).hexdigest() + "\n")
    monkeypatch.setenv("RETROKIT_GAMES", str(root))
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))
    return tmp_path / "data"


@pytest.fixture
def src(tmp_path) -> Path:
    folder = tmp_path / "my roms"
    folder.mkdir()
    (folder / "notes.txt").write_text("not a rom")
    return folder


def imported(data_dir: Path, game: str, ext: str) -> Path:
    return data_dir / "roms" / game / f"rom.{ext}"


def test_import_from_a_folder(src, data_dir):
    (src / "sub").mkdir()
    (src / "sub" / "Airstriker (homebrew).bin").write_bytes(AIRSTRIKER_ROM.read_bytes())
    report = import_roms([src])
    dest = imported(data_dir, "Airstriker-Genesis", "md")
    assert [(r.game, r.path) for r in report.imported] == [("Airstriker-Genesis", dest)]
    assert dest.read_bytes() == AIRSTRIKER_ROM.read_bytes()
    assert report.unmatched == [] and report.not_roms == [str(src / "notes.txt")]  # a .txt is listed as no ROM
    assert report.conflicts == [] and report.already_present == [] and report.broken_games == []
    assert sorted(p.name for p in dest.parent.iterdir()) == ["rom.md"]  # no temp file left


def _zip(members: dict[str, bytes]) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return buffer.getvalue()


@pytest.mark.parametrize("nested", [False, True], ids=["zip", "zip-in-zip"])
def test_import_from_a_zip(src, data_dir, nested):
    archive = _zip({"readme.txt": b"hello", "Airstriker/Airstriker.md": AIRSTRIKER_ROM.read_bytes()})
    if nested:
        archive = _zip({"inner.zip": archive})
    (src / "collection.zip").write_bytes(archive)
    report = import_roms([src / "collection.zip"])
    assert [r.game for r in report.imported] == ["Airstriker-Genesis"]
    assert report.imported[0].source.endswith("!Airstriker/Airstriker.md")
    assert imported(data_dir, "Airstriker-Genesis", "md").read_bytes() == AIRSTRIKER_ROM.read_bytes()
    assert report.unmatched == [] and [u.rsplit("!", 1)[-1] for u in report.not_roms] == ["readme.txt"]
    assert not list(src.glob("**/*.md"))  # zip members are never extracted to disk


def test_import_of_an_smd_stores_the_md_form(src, data_dir):
    (src / "Airstriker.smd").write_bytes(interleave_smd(AIRSTRIKER_ROM.read_bytes()))
    report = import_roms([src])
    assert [r.game for r in report.imported] == ["Airstriker-Genesis"]
    assert imported(data_dir, "Airstriker-Genesis", "md").read_bytes() == AIRSTRIKER_ROM.read_bytes()


def test_nes_header_is_left_out_of_the_hash(src, data_dir):
    (src / "FakeQuest.nes").write_bytes(NES_ROM)
    (src / "FakeQuest-headered.bin").write_bytes(NES_ROM)  # not .nes: hashed whole, so no match
    game = games.find_game("FakeQuest-Nes")
    with pytest.raises(RomNotFoundError):
        game.require_rom()
    report = import_roms([src])
    # Two games accept the same ROM: each gets its copy, stored with its header.
    assert sorted(r.game for r in report.imported) == ["FakeQuest-Nes", "FakeQuestTurbo-Nes"]
    assert imported(data_dir, "FakeQuest-Nes", "nes").read_bytes() == NES_ROM
    assert str(src / "FakeQuest-headered.bin") in [u.source for u in report.unmatched]
    assert game.require_rom() == imported(data_dir, "FakeQuest-Nes", "nes")


def test_importing_again_reports_already_imported(src, data_dir):
    (src / "FakeQuest.nes").write_bytes(NES_ROM)
    import_roms([src])
    report = import_roms([src])
    assert report.imported == []
    assert sorted(r.game for r in report.already_present) == ["FakeQuest-Nes", "FakeQuestTurbo-Nes"]


def test_no_silent_overwrite(src, data_dir):
    dest = imported(data_dir, "FakeQuest-Nes", "nes")
    dest.parent.mkdir(parents=True)
    dest.write_bytes(b"NES\x1a" + bytes(12) + b"the user's own hack")
    (src / "FakeQuest.nes").write_bytes(NES_ROM)
    report = import_roms([src], games=[games.find_game("FakeQuest-Nes")])
    assert report.imported == []
    [conflict] = report.conflicts
    assert conflict.path == dest
    assert conflict.sha1 == hashlib.sha1(NES_BODY).hexdigest()
    assert conflict.existing_sha1 == hashlib.sha1(b"the user's own hack").hexdigest()
    assert dest.read_bytes().endswith(b"the user's own hack")
    report = import_roms([src], overwrite=True, games=[games.find_game("FakeQuest-Nes")])
    assert [r.path for r in report.imported] == [dest]
    assert dest.read_bytes() == NES_ROM


def test_unreadable_inputs_are_reported(src, data_dir):
    (src / "broken.zip").write_bytes(b"PK\x03\x04 not really a zip")
    report = import_roms([src, src / "missing-folder"])
    reasons = dict(report.skipped)
    assert "not a readable zip file" in reasons[str(src / "broken.zip")]
    assert reasons[str(src / "missing-folder")] == "no such file or folder"
    assert report.imported == []


def test_written_files_get_the_usual_permissions(tmp_path):
    import os

    from retrokit.paths import atomic_write

    umask = os.umask(0o022)
    try:
        atomic_write(tmp_path / "f.bin", b"data")
    finally:
        os.umask(umask)
    assert (tmp_path / "f.bin").stat().st_mode & 0o777 == 0o644


def test_an_unmatched_file_has_its_sha1_and_likely_system(src, data_dir):
    from runner_rom import write_runner_rom

    runner = write_runner_rom(src / "runner.bin")
    (src / "FakeQuest-headered.bin").write_bytes(NES_ROM)
    report = import_roms([src])
    by_source = {Path(u.source).name: u for u in report.unmatched}
    assert by_source["runner.bin"].sha1 == hashlib.sha1(runner.read_bytes()).hexdigest()
    assert by_source["runner.bin"].system == "Genesis"  # told by its header: .bin says nothing
    assert by_source["FakeQuest-headered.bin"].system == "Nes"
    assert "notes.txt" not in by_source and str(src / "notes.txt") in report.not_roms
    (src / "mystery.bin").write_bytes(b"\x01" * 1000)  # a .bin of no system's size or header: listed, system unknown
    assert {Path(u.source).name: u for u in import_roms([src]).unmatched}["mystery.bin"].system is None


@pytest.mark.parametrize("nested", [False, True], ids=["zip", "zip-in-zip"])
def test_a_zip_holding_no_rom_is_listed_once(src, data_dir, nested):
    archive = _zip({"readme.txt": b"hello"})
    if nested:
        archive = _zip({"inner.zip": archive})
    (src / "docs.zip").write_bytes(archive)
    (src / "empty.zip").write_bytes(_zip({}))
    report = import_roms([src / "docs.zip", src / "empty.zip"])
    inner = "!inner.zip" if nested else ""
    assert [u.source for u in report.unmatched] == [str(src / "empty.zip")]
    assert report.not_roms == [f"{src / 'docs.zip'}{inner}!readme.txt"]


def _with_header(rom: bytes, **at: int) -> bytes:
    """``rom`` with header bytes changed: ``b4=prg``, ``b6=flags6``, ``b7=flags7``."""
    data = bytearray(rom)
    for key, value in at.items():
        data[int(key[1:])] = value
    return bytes(data)


def test_a_known_rom_whose_header_its_core_cannot_run_is_refused(src, data_dir):
    """Issue 42: the SHA-1 leaves the iNES header out, so a known body under a header `new` refuses was imported,
    and played with every pixel wrong. Import checks what `new` checks."""
    (src / "mapper255.nes").write_bytes(_with_header(NES_ROM, b6=0xF0, b7=0xF0))
    (src / "prg-too-big.nes").write_bytes(_with_header(NES_ROM, b4=4))
    report = import_roms([src], games=[games.find_game("FakeQuest-Nes")])
    assert report.imported == [] and not imported(data_dir, "FakeQuest-Nes", "nes").exists()
    refused = {Path(label).name: (game, why) for label, game, why in report.refused}
    mapper = "its iNES mapper 255 is one the fceumm core cannot run (it has no such board)"
    assert refused["mapper255.nes"] == ("FakeQuest-Nes", mapper)
    assert refused["prg-too-big.nes"][1].startswith("it is truncated: its iNES header gives 4 x 16 KiB of program ROM")


def test_a_second_copy_names_both_files_and_how_their_headers_differ(src, data_dir, capsys):
    from retrokit.cli import main

    (src / "FakeQuest.nes").write_bytes(NES_ROM)
    import_roms([src], games=[games.find_game("FakeQuest-Nes")])
    other = src.parent / "other"
    other.mkdir()
    (other / "FakeQuest (mapper 2).nes").write_bytes(_with_header(NES_ROM, b6=0x20))  # a board the core has
    capsys.readouterr()
    assert main(["import", str(other)]) == 1
    out = capsys.readouterr().out
    dest = imported(data_dir, "FakeQuest-Nes", "nes")
    line = next(line for line in out.splitlines() if line.startswith("  FakeQuest-Nes:"))
    assert line == f"  FakeQuest-Nes: {dest} and {other / 'FakeQuest (mapper 2).nes'} differ (their iNES headers " \
        "differ: mapper 1 against 2)", out
    assert dest.read_bytes() == NES_ROM  # left as it was


def test_a_hint_prints_a_hostile_file_name_escaped_and_quoted_for_the_shell(src, data_dir, capsys):
    """Issue 42: a file name's escape sequence reached the terminal raw, and unquoted, through a hint's command."""
    import shutil
    import subprocess

    from retrokit.cli import main

    name = "\x1b[2J\x1b[31mevil\nname $(reboot).nes"
    (src / name).write_bytes(_with_header(NES_ROM, b4=2)[:16] + bytes(range(255, -1, -1)) * 128)  # no game's
    capsys.readouterr()
    assert main(["import", str(src)]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\nname" not in out, out  # escaped everywhere it is printed
    (hint,) = [line for line in out.splitlines() if line.startswith("A game nobody has integrated yet?")]
    word = hint.split("retrokit new ", 1)[1].split(" --name NAME-Nes", 1)[0]
    if shutil.which("bash"):  # the word is the file's name again, and runs nothing
        done = subprocess.run(["bash", "-c", f"printf %s {word}"], capture_output=True, check=True)
        assert done.stdout == str(src / name).encode()
