"""Movies: .bk2 files made by stable-retro play in retrokit, and the other way round.

stable-retro is the reference here: it records a movie while we keep the
screens it showed, and it reads the movies retrokit writes.
"""

from __future__ import annotations

import io
import sys
import zipfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from retrokit.cli import main
from retrokit.data.statecheck import vet_state
from retrokit.errors import FileConflictError, InvalidArgumentError, MovieError
from retrokit.host.emulator import Emulator
from retrokit.host.systems import get_system
from retrokit.movie import Movie, MovieRecorder, encode_bk2, export, layout, play, read_bk2, write_bk2

stable_retro = pytest.importorskip("stable_retro")

GAME = "Airstriker-Genesis"
GENESIS = get_system("Genesis")
STEPS = 240


def scripted_buttons(step: int) -> list[str]:
    """Tap fire every 4th frame, and move up, down, left, right for 15 frames each: this scores twice by frame 200."""
    return [["UP"], ["DOWN"], ["LEFT"], ["RIGHT"]][step // 15 % 4] + (["B"] if step % 4 == 0 else [])


@dataclass
class Recording:
    path: Path
    screens: list[np.ndarray]
    scores: set[int]


@pytest.fixture(scope="module")
def stable_retro_recording(tmp_path_factory: pytest.TempPathFactory) -> Recording:
    """A movie recorded by stable-retro, with the screens it showed (after reset, then after each step)."""
    folder = tmp_path_factory.mktemp("stable_retro_movies")
    env = stable_retro.make(f"{GAME}-v0", render_mode=None, record=str(folder),
                            use_restricted_actions=stable_retro.Actions.ALL)
    try:
        env.reset(seed=0)
        reference = env.unwrapped
        screens, scores = [reference.em.get_screen().copy()], set()
        for step in range(STEPS):
            pressed = np.array([b in scripted_buttons(step) for b in reference.buttons], dtype=np.int8)
            _, _, _, _, info = env.step(pressed)
            screens.append(reference.em.get_screen().copy())
            scores.add(info["score"])
        reference.stop_record()  # writes the file
    finally:
        env.close()
    (path,) = folder.glob("*.bk2")
    return Recording(path, screens, scores)


def first_difference(ours: list[np.ndarray], theirs: list[np.ndarray]) -> int | None:
    for i, (a, b) in enumerate(zip(ours, theirs)):
        if a.shape != b.shape or not np.array_equal(a, b):
            return i
    return None


# --- 1. stable-retro's movies play in retrokit -------------------------------------------------------


def test_a_stable_retro_movie_plays_to_the_frames_stable_retro_showed(stable_retro_recording: Recording) -> None:
    rec = stable_retro_recording
    assert len(rec.scores) > 2, "the scripted input should shoot enemies, so the frames show a game in motion"
    movie = read_bk2(rec.path)
    assert (movie.game, movie.system, movie.players) == (GAME, "Genesis", 1)
    assert len(movie.frames) == len(rec.screens) == STEPS + 1  # stable-retro logs its reset frame too
    screens = list(play(movie))
    assert len(screens) == len(rec.screens)
    assert first_difference(screens, rec.screens) is None
    assert len({s.tobytes() for s in screens}) > STEPS // 2


def test_playback_follows_the_movie_input(stable_retro_recording: Recording) -> None:
    # The comparison above would catch a replay that ignored the buttons: without
    # the fire button, the replay leaves stable-retro's frames.
    movie = read_bk2(stable_retro_recording.path)
    fire = GENESIS.mask(["B"])
    unarmed = replace(movie, frames=[(f[0] & ~fire,) for f in movie.frames])
    assert first_difference(list(play(unarmed)), stable_retro_recording.screens) is not None


# --- 2. retrokit's movies play in stable-retro ------------------------------------------------------


def test_a_retrokit_movie_plays_in_stable_retro(tmp_path: Path, airstriker_rom: Path, airstriker_state: bytes) -> None:
    path = tmp_path / "ours.bk2"
    emu = Emulator("Genesis", airstriker_rom)
    emu.set_state(airstriker_state)
    ours, masks = [], []
    with MovieRecorder(path, GAME, "Genesis", 1, airstriker_state) as recorder:
        for step in range(STEPS):
            emu.run(GENESIS.mask(scripted_buttons(step)), 1)
            recorder.record(emu.held())
            masks.append(emu.held()[0])
            ours.append(emu.screen())
    emu.close()

    movie = stable_retro.Movie(str(path))
    assert (movie.players, movie.get_game()) == (1, f"{GAME}-v0")
    assert movie.get_state() == airstriker_state
    reference = stable_retro.RetroEmulator(str(airstriker_rom))
    try:
        reference.set_state(vet_state(movie.get_state(), "Genesis", airstriker_rom))
        theirs = []
        for step, mask in enumerate(masks):
            assert movie.step(), f"stable-retro's movie ended at frame {step} of {len(masks)}"
            keys = [movie.get_key(i, 0) for i in range(len(GENESIS.buttons))]
            assert keys == [bool(mask >> i & 1) for i in range(len(GENESIS.buttons))], f"frame {step}"
            reference.set_button_mask(np.array(keys, dtype=np.uint8), 0)
            reference.step()
            theirs.append(reference.get_screen().copy())
        assert not movie.step(), "stable-retro read more frames than were recorded"
    finally:
        del reference
    assert first_difference(ours, theirs) is None


SYSTEMS = ["Genesis", "Nes", "Snes", "Atari2600", "GameBoy", "GbAdvance", "PCEngine", "Sms", "N64"]


@pytest.mark.parametrize("players", [1, 2], ids=["1p", "2p"])
@pytest.mark.parametrize("system", SYSTEMS)
def test_stable_retro_reads_the_buttons_retrokit_writes(tmp_path: Path, system: str, players: int) -> None:
    lay = layout(system)
    rng = np.random.default_rng(0)
    frames = [tuple(int(m) & lay.allowed for m in rng.integers(0, 1 << 16, players)) for _ in range(50)]
    frames[0] = (lay.allowed,) * players  # every button once
    path = tmp_path / "keys.bk2"
    # stable-retro opens no movie without a Core.bin state; any bytes do for reading keys.
    write_bk2(path, Movie(f"Fake-{system}", system, players, b"state", frames))
    movie = stable_retro.Movie(str(path))
    assert movie.players == players
    width = len(get_system(system).buttons)
    for number, frame in enumerate(frames):
        assert movie.step()
        got = tuple(sum(movie.get_key(i, p) << i for i in range(width)) for p in range(players))
        assert got == tuple(read_by_letter(lay, mask) for mask in frame), f"frame {number}"
    assert not movie.step()


def read_by_letter(lay, mask: int) -> int:
    """What stable-retro reads of a frame's mask: each pressed column by its letter, to its own button of that letter
    (a column whose letter it has no button for, the PC Engine's I to VI, it skips)."""
    theirs = {letter: bit for bit, letter, _ in lay.columns if lay.stable_retro >> bit & 1}
    read = 0
    for bit, letter, _ in lay.columns:
        if mask >> bit & 1 and letter in theirs:
            read |= 1 << theirs[letter]
    return read


def test_pc_engine_movies_hold_i_ii_and_run_as_bizhawk_writes_them(tmp_path: Path) -> None:
    # BizHawk's PC Engine input log (TurboNyma): I to VI are the digits 1 to 6, RUN is R, Select s.
    system = get_system("PCEngine")
    names = ["I", "II", "RUN", "SELECT", "UP"]
    members = unzip(encode_bk2(Movie("Fake-PCEngine", "PCEngine", 1, b"state", [(system.mask(names),), (0,)])))
    key_line, pressed, idle = members["Input Log.txt"].decode().splitlines()[1:4]
    assert key_line == "P1 VI|P1 V|P1 IV|P1 I|P1 Right|P1 Left|P1 Down|P1 Up|P1 Run|P1 Select|P1 III|P1 II|"
    assert (pressed, idle) == ("|..|...1...URs.2|", "|..|............|")
    path = tmp_path / "pce.bk2"
    path.write_bytes(encode_bk2(Movie("Fake-PCEngine", "PCEngine", 1, b"state", [(system.mask(names),)])))
    assert read_bk2(path).frames == [(system.mask(names),)]
    # stable-retro opens it and reads the pad and SELECT; it skips the digits, and reads RUN's R as RIGHT.
    movie = stable_retro.Movie(str(path))
    assert movie.step()
    got = [name for i, name in enumerate(system.buttons) if movie.get_key(i, 0)]
    assert got == ["SELECT", "UP", "RIGHT"]


# Key lines recorded by stable-retro 1.0.1 (Movie.configure on an emulator of each system). Its PC Engine line,
# "P1 Right|P1 Left|P1 Down|P1 Up|P1 Select|", drops I to VI and RUN, which retrokit records (the test above).
STABLE_RETRO_KEY_LINES = {
    "Genesis": "P1 Z|P1 X|P1 Y|P1 C|P1 Right|P1 Left|P1 Down|P1 Up|P1 Start|P1 Mode|P1 A|P1 B|",
    "Nes": "P1 A|P1 Right|P1 Left|P1 Down|P1 Up|P1 Start|P1 Select|P1 B|",
    "Snes": "P1 R|P1 L|P1 X|P1 A|P1 Right|P1 Left|P1 Down|P1 Up|P1 Start|P1 Select|P1 Y|P1 B|",
    "Atari2600": "P1 Right|P1 Left|P1 Down|P1 Up|P1 Select|P1 Button|",
    "GameGear": "P1 A|P1 Right|P1 Left|P1 Down|P1 Up|P1 Start|P1 B|",
}


@pytest.mark.parametrize("system", STABLE_RETRO_KEY_LINES)
def test_the_key_line_is_the_one_stable_retro_writes(system: str) -> None:
    members = unzip(encode_bk2(Movie(f"Fake-{system}", system, 1, None, [])))
    assert members["Input Log.txt"].decode() == f"[Input]\n{STABLE_RETRO_KEY_LINES[system]}\n[/Input]"


# --- 3. The format: round trips, malformed files, no silent overwrite -------------------------------


def unzip(data: bytes) -> dict[str, bytes]:
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        return {name: archive.read(name) for name in archive.namelist()}


def zip_members(path: Path, members: dict[str, bytes | str]) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return path


def test_round_trip_writes_stable_retros_files_byte_for_byte(stable_retro_recording: Recording, tmp_path: Path) -> None:
    movie = read_bk2(stable_retro_recording.path)
    write_bk2(tmp_path / "again.bk2", movie)
    assert read_bk2(tmp_path / "again.bk2") == movie
    theirs = unzip(stable_retro_recording.path.read_bytes())
    ours = unzip((tmp_path / "again.bk2").read_bytes())
    assert list(ours) == list(theirs) == ["Input Log.txt", "Header.txt", "Core.bin"]
    for name in theirs:
        assert ours[name] == theirs[name], name


def test_round_trip_keeps_players_state_and_extra_header_lines(tmp_path: Path) -> None:
    movie = Movie(GAME, "Genesis", 2, b"\x01\x02", [(1, 2), (0, 0xFFF), (5, 0)])
    movie.header["Author"] = "somebody"
    movie.header["BoardName"] = "SEGA 315-5433"  # a BizHawk line stable-retro does not write
    write_bk2(tmp_path / "m.bk2", movie)
    assert read_bk2(tmp_path / "m.bk2") == movie
    header = unzip((tmp_path / "m.bk2").read_bytes())["Header.txt"].decode()
    assert header.splitlines()[:5] == [
        "MovieVersion Retro", "Author somebody", "emuVersion ?", "Platform GEN", f"GameName {GAME}-v0",
    ]
    assert header.endswith("BoardName SEGA 315-5433\n")


@pytest.fixture
def members() -> dict[str, bytes]:
    """The members of a small valid two-player Genesis movie."""
    return unzip(encode_bk2(Movie(GAME, "Genesis", 2, b"state", [(1, 0), (0, 2)])))


def edit_log(members: dict[str, bytes], old: str, new: str) -> dict[str, bytes]:
    log = members["Input Log.txt"].decode()
    assert old in log
    return {**members, "Input Log.txt": log.replace(old, new, 1).encode()}


def corrupt_deflate(data: bytes) -> bytes:
    blob = bytearray(data)
    at = blob.index(b"Core.bin") + len("Core.bin") + 2  # inside the first member's compressed data
    blob[at] ^= 0xFF
    return bytes(blob)


MALFORMED = {
    "not a zip": (lambda m: b"this is a text file", "not a complete zip"),
    "truncated zip": (lambda m: encode_bk2(Movie(GAME, "Genesis", 1, bytes(5000), [(1,)]))[:-300], "not a complete zip"),
    "corrupt data": (lambda m: corrupt_deflate(encode_bk2(Movie(GAME, "Genesis", 1, bytes(5000), [(1,)]))),
                     "not a complete zip"),
    "no Header.txt": (lambda m: {k: v for k, v in m.items() if k != "Header.txt"}, "holding 'Header.txt'"),
    "no Input Log.txt": (lambda m: {k: v for k, v in m.items() if k != "Input Log.txt"}, "holding 'Input Log.txt'"),
    "no Platform": (lambda m: {**m, "Header.txt": b"GameName x\n"}, "'Platform' line"),
    "unknown Platform": (lambda m: {**m, "Header.txt": b"Platform Dreamcast\n"}, "unknown platform"),
    "no [Input]": (lambda m: edit_log(m, "[Input]\n", ""), "expected '[Input]'"),
    "no key line": (lambda m: {**m, "Input Log.txt": b"[Input]\n|..|...........B|............|\n[/Input]"},
                    "key line"),
    "unknown button": (lambda m: edit_log(m, "P1 Mode|", "P1 Turbo|"), "'P1 Turbo'"),
    "players out of order": (lambda m: edit_log(m, "P1 B|P2 Z|", "P2 B|P1 Z|"), "out of order"),
    "wrong letter": (lambda m: edit_log(m, "|..|...........B|", "|..|...........Q|"), "found 'Q'"),
    "letter in the wrong column": (lambda m: edit_log(m, "|..|...........B|", "|..|B...........|"), "found 'B'"),
    "too few buttons": (lambda m: edit_log(m, "|..|...........B|", "|..|.........B|"), "expected 12 button"),
    "missing player": (lambda m: edit_log(m, "|..|...........B|............|", "|..|...........B|"), "2 player"),
}


@pytest.mark.parametrize("case", MALFORMED)
def test_a_malformed_movie_raises_a_clear_error(tmp_path: Path, members: dict[str, bytes], case: str) -> None:
    make, expected = MALFORMED[case]
    content = make(members)
    path = tmp_path / "bad.bk2"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        zip_members(path, content)
    with pytest.raises(MovieError) as info:
        read_bk2(path)
    message = str(info.value)
    assert str(path) in message and "expected" in message.lower()
    assert expected in message


def test_a_missing_movie_file_raises_movie_error(tmp_path: Path) -> None:
    with pytest.raises(MovieError, match="found no such file"):
        read_bk2(tmp_path / "nothing.bk2")


LENIENT = {
    "BizHawk LogKey prefix": lambda m: edit_log(m, "P1 Z|", "LogKey:#Reset|Power|#P1 Z|"),
    "CRLF lines": lambda m: {**m, "Input Log.txt": m["Input Log.txt"].replace(b"\n", b"\r\n")},
    "no [/Input]": lambda m: edit_log(m, "[/Input]", ""),
}


@pytest.mark.parametrize("case", LENIENT)
def test_variants_other_writers_produce_are_read(tmp_path: Path, members: dict[str, bytes], case: str) -> None:
    movie = read_bk2(zip_members(tmp_path / "m.bk2", LENIENT[case](members)))
    assert (movie.players, movie.frames, movie.state) == (2, [(1, 0), (0, 2)], b"state")


def test_a_movie_without_a_state_starts_from_power_on(tmp_path: Path, members: dict[str, bytes]) -> None:
    del members["Core.bin"]  # stable-retro writes none when it records without a start state
    movie = read_bk2(zip_members(tmp_path / "m.bk2", members))
    assert movie.state is None and len(movie.frames) == 2


def test_writing_never_replaces_a_different_file_unless_asked(tmp_path: Path) -> None:
    path = tmp_path / "m.bk2"
    first = Movie(GAME, "Genesis", 1, b"s", [(1,), (2,)])
    write_bk2(path, first)
    before = path.read_bytes()
    write_bk2(path, Movie(GAME, "Genesis", 1, b"s", [(1,), (2,)]))  # the same movie: nothing to do
    assert path.read_bytes() == before
    second = Movie(GAME, "Genesis", 1, b"s", [(1,), (4,)])
    with pytest.raises(FileConflictError, match="overwrite=True"):
        write_bk2(path, second)
    assert path.read_bytes() == before
    write_bk2(path, second, overwrite=True)
    assert read_bk2(path) == second
    assert [p.name for p in tmp_path.iterdir()] == ["m.bk2"]  # no temporary files left behind


def test_a_recorder_refuses_an_existing_file_before_recording(tmp_path: Path) -> None:
    (tmp_path / "m.bk2").write_bytes(b"mine")
    with pytest.raises(FileConflictError):
        MovieRecorder(tmp_path / "m.bk2", GAME, "Genesis")
    assert (tmp_path / "m.bk2").read_bytes() == b"mine"


BAD_RECORDS = {
    "a bit beyond the pad": ([1 << 12], "unknown bits"),
    "a button the format lacks": ([1 << 3], "PAUSE"),  # Sms below: stable-retro has no letter for it
    "too few masks": ([], "expected 1 mask"),
    "buttons on a port beyond the players": ([0, 1], "then only zeros"),
}


@pytest.mark.parametrize("case", BAD_RECORDS)
def test_a_recorder_rejects_frames_that_could_not_replay(tmp_path: Path, case: str) -> None:
    masks, expected = BAD_RECORDS[case]
    system = "Sms" if case == "a button the format lacks" else "Genesis"
    recorder = MovieRecorder(tmp_path / "m.bk2", GAME, system)
    recorder.record([0, 0])  # an idle second port is fine
    with pytest.raises(MovieError, match=expected):
        recorder.record(masks)
    assert len(recorder) == 1


def test_a_recorder_drops_the_ids_the_console_has_no_button_on(tmp_path: Path) -> None:
    # The NES under action_type="all": index 1 (stable-retro's unnamed button) reaches no game, and stable-retro
    # records the frame without it; so does retrokit (it raised MovieError on a random agent's first steps).
    recorder = MovieRecorder(tmp_path / "m.bk2", "Hopper-Nes", "Nes")
    recorder.record([0b11])  # B and id 1
    recorder.record([0b10])  # id 1 alone
    recorder.close()
    assert read_bk2(tmp_path / "m.bk2").frames == [(1,), (0,)]


def test_a_closed_recorder_refuses_more_frames(tmp_path: Path) -> None:
    recorder = MovieRecorder(tmp_path / "m.bk2", GAME, "Genesis")
    recorder.record([1])
    assert recorder.close() == tmp_path / "m.bk2" and recorder.closed
    with pytest.raises(MovieError, match="closed"):
        recorder.record([1])
    assert read_bk2(tmp_path / "m.bk2").frames == [(1,)]


# --- 4. Export -------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def short_movie(tmp_path_factory: pytest.TempPathFactory, airstriker_state: bytes) -> Path:
    frames = [(GENESIS.mask(scripted_buttons(step)),) for step in range(60)]
    path = tmp_path_factory.mktemp("short") / "short.bk2"
    write_bk2(path, Movie(GAME, "Genesis", 1, airstriker_state, frames))
    return path


def test_export_to_a_folder_writes_every_nth_frame_as_png(short_movie: Path, tmp_path: Path) -> None:
    from PIL import Image

    assert export(short_movie, tmp_path / "frames", every=10) == 6
    files = sorted((tmp_path / "frames").iterdir())
    assert [f.name for f in files] == [f"frame_{i:06d}.png" for i in range(0, 60, 10)]
    images = [np.asarray(Image.open(f).convert("RGB")) for f in files]
    assert {im.shape for im in images} == {(224, 320, 3)}
    assert len({im.tobytes() for im in images}) > 1
    expected = list(play(read_bk2(short_movie)))[::10]
    assert first_difference(images, expected) is None  # PNG is lossless


def test_export_to_a_gif_writes_an_animation(short_movie: Path, tmp_path: Path) -> None:
    from PIL import Image, ImageSequence

    assert export(short_movie, tmp_path / "clip.gif", every=5) == 12
    with Image.open(tmp_path / "clip.gif") as gif:
        frames = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(gif)]
        assert gif.size == (320, 224)
    assert len(frames) == 12
    assert len({f.tobytes() for f in frames}) > 1


def test_export_never_replaces_output_unless_asked(short_movie: Path, tmp_path: Path) -> None:
    (tmp_path / "clip.gif").write_bytes(b"mine")
    with pytest.raises(FileConflictError):
        export(short_movie, tmp_path / "clip.gif", every=30)
    assert (tmp_path / "clip.gif").read_bytes() == b"mine"
    export(short_movie, tmp_path / "frames", every=30)
    with pytest.raises(FileConflictError, match="earlier export"):
        export(short_movie, tmp_path / "frames", every=30)
    assert export(short_movie, tmp_path / "clip.gif", every=30, overwrite=True) == 2


BAD_EXPORTS = {
    "mp4 without imageio": ("clip.mp4", 1, "Export to a .gif or to a folder"),
    "every 0": ("frames", 0, "1 or more"),
}


@pytest.mark.parametrize("case", BAD_EXPORTS)
def test_export_rejects_what_it_cannot_write(short_movie: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             case: str) -> None:
    name, every, expected = BAD_EXPORTS[case]
    monkeypatch.setitem(sys.modules, "imageio", None)  # as if not installed
    with pytest.raises(InvalidArgumentError, match=expected):
        export(short_movie, tmp_path / name, every=every)
    assert list(tmp_path.iterdir()) == []


def test_the_playback_command(short_movie: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["playback", str(short_movie), str(tmp_path / "out"), "--every", "20"]) == 0
    assert "Wrote 3 frames" in capsys.readouterr().out
    assert len(list((tmp_path / "out").glob("*.png"))) == 3
    # Only .gif and .mp4 name files: a name with a dot (a state's) is a folder.
    assert main(["playback", str(short_movie), str(tmp_path / "out" / "Zone1.Act1"), "--every", "20"]) == 0
    assert len(list((tmp_path / "out" / "Zone1.Act1").glob("*.png"))) == 3
    (tmp_path / "bad.bk2").write_bytes(b"nope")
    assert main(["playback", str(tmp_path / "bad.bk2"), str(tmp_path / "out2")]) == 2
    assert "not a complete zip" in capsys.readouterr().err
