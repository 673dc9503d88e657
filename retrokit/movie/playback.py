"""Replaying movies on retrokit's emulator, and exporting them as images or video."""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from tqdm import tqdm

from retrokit.data.states import StateRecord
from retrokit.errors import (
    DataFileError,
    FileConflictError,
    FileSystemError,
    GameNotFoundError,
    InvalidArgumentError,
    MovieError,
    RomError,
    install_extra,
    shell_word,
)
from retrokit.host.emulator import Emulator, VettedState
from retrokit.movie.bk2 import read_bk2
from retrokit.movie.gif import GifWriter, gif_step
from retrokit.movie.model import STATE_DIGEST, Movie
from retrokit.paths import REPLACE_HINT, atomic_output, atomic_write, ensure_folder

if TYPE_CHECKING:
    from retrokit.data.games import Game

FRAME_PATTERN = "frame_{:06d}.png"
_SHA1 = re.compile(r"[0-9a-f]{40}")
VIDEO_SUFFIXES = (".gif", ".mp4")


def open_emulator(movie: Movie) -> Emulator:
    """Return an emulator running the movie's game, with a port for every player.

    Raises:
        GameNotFoundError: No game folder has the movie's game.
        RomNotFoundError: The game's ROM has not been imported.
    """
    from retrokit.data.games import find_game

    rom = find_game(movie.game).require_rom()
    return Emulator(movie.system, rom, ports=max(2, movie.players))


def check_movie_state(movie: Movie, emu: Emulator, source: str) -> VettedState:
    """Refuse a movie's start state that is for another ROM, or that crashes or hangs the core; return it checked.

    A movie retrokit recorded names its ROM's SHA-1 in its header: one for a
    ROM the game does not accept is refused. Whether the state may crash the
    core is decided as for any state (see :mod:`retrokit.data.statecheck`),
    never from the header.

    Raises:
        StateError: The state is for another ROM, or the core cannot run it.
    """
    from retrokit.data.games import find_game
    from retrokit.data.statecheck import check_state, vet_state

    if movie.state is None:
        raise MovieError(f"{source}: expected a start state; found a movie that starts at power-on.")
    sha1 = movie.header.get("SHA1", "?").strip().lower()
    record = StateRecord(movie.game, sha1, movie.header.get(STATE_DIGEST, "")) if _SHA1.fullmatch(sha1) else None
    try:
        game = find_game(movie.game)
    except (GameNotFoundError, DataFileError):  # a movie of a game retrokit does not know: probe it all the same
        return vet_state(movie.state, emu.system, emu.rom, source=source)
    return check_state(game, movie.state, record, source=source, rom=emu.rom)


def replay(movie: Movie, emu: Emulator, *, source: str, stop: int | None = None) -> Iterator[int]:
    """Replay a movie on ``emu``: the one loop every replay uses, and the one place its start state is checked.

    The emulator's sticky-action probability is set to 0 and it is put at the
    movie's start state (checked first: :func:`check_movie_state`), or reset
    to power-on if the movie has none; then it runs one frame per movie frame.

    Args:
        movie: The movie.
        emu: An emulator of the movie's system with a port for every player.
        source: What to call the movie's start state in errors.
        stop: Replay only this many frames (all by default).

    Yields:
        0 once the console is at the movie's start, then the number of each
        movie frame (1-based) once it has run.

    Raises:
        MovieError: ``emu`` runs another system or has too few ports.
        StateError: The start state is for another ROM, or the core cannot run it.
    """
    if emu.system.name != movie.system or emu.ports < movie.players:
        raise MovieError(
            f"Expected an emulator of {movie.system} with at least {movie.players} port(s) to play "
            f"{movie.game}; found one of {emu.system.name} with {emu.ports}."
        )
    emu.set_sticky(0.0, 0)
    emu.forget_action()
    if movie.state is not None:
        emu.set_state(check_movie_state(movie, emu, source))
    else:
        emu.reset()
    yield 0
    for number, frame in enumerate(movie.frames[:stop] if stop is not None else movie.frames, start=1):
        emu.run(frame, 1)
        yield number


def play(
    movie: Movie | str | os.PathLike[str], *, emulator: Emulator | None = None, source: str | None = None
) -> Iterator[np.ndarray]:
    """Replay a movie, yielding the screen after each of its frames (see :func:`replay`).

    Args:
        movie: A movie, or the path of a ``.bk2`` file.
        emulator: An emulator of the movie's game to replay on; its sticky-action
            probability is set to 0. By default one is opened (and closed after).
        source: What to call the movie's start state in errors (by default its path, or its game).

    Yields:
        RGB ``uint8`` arrays of shape (H, W, 3), one per movie frame.

    Raises:
        MovieError: The movie is malformed, or ``emulator`` runs another system or has too few ports.
        StateError: The movie's start state is for another ROM, or the core cannot run it.
    """
    if source is None:
        source = f"the start state (Core.bin) of the {movie.game} movie" if isinstance(movie, Movie) else f"{movie}: Core.bin"
    if not isinstance(movie, Movie):
        movie = read_bk2(movie)
    own = emulator is None
    emu = open_emulator(movie) if emulator is None else emulator
    try:
        for number in replay(movie, emu, source=source):
            if number:
                yield emu.screen()
    finally:
        if own:
            emu.close()


def export(
    movie_path: str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    every: int = 1,
    overwrite: bool = False,
    progress: bool = False,
) -> int:
    """Replay a movie into PNG frames, an animated GIF or an MP4 video.

    Args:
        movie_path: The ``.bk2`` file.
        out: A folder for ``frame_000000.png``, ... (named by movie frame), or a
            file ending in ``.gif`` (Pillow) or ``.mp4`` (needs ``imageio`` with ffmpeg).
        every: Keep one frame in ``every`` (the video's frame rate shrinks to match).
        overwrite: Replace the output file, or frames already in the folder.
        progress: Show a progress bar (on standard error) while the movie plays.

    Returns:
        How many images were written.

    Raises:
        InvalidArgumentError: ``every`` is below 1, ``out`` names an unknown format,
            or ``.mp4`` was asked for without imageio's ffmpeg.
        FileConflictError: The output exists and ``overwrite`` is false.
        MovieError: The movie is malformed.
    """
    if not isinstance(every, int) or every < 1:
        raise InvalidArgumentError(f"Expected every to be a whole number of frames, 1 or more; found {every!r}.")
    out = Path(out)
    kind = _output_kind(out)
    if kind == ".mp4":
        imageio = _require_imageio(out)
    if not overwrite and (out.exists() if kind else any(out.glob("frame_*.png"))):
        where, found = (f"no file at {out}", "one") if kind else (f"no frames in {out}", "frames of an earlier export")
        raise FileConflictError(f"Expected {where}; found {found}, left as it is. {REPLACE_HINT}")
    movie = read_bk2(movie_path)
    try:
        emu = open_emulator(movie)
    except (GameNotFoundError, RomError) as exc:
        raise type(exc)(f"{movie_path} plays {movie.game}. {exc}") from None
    bar = tqdm(total=len(movie.frames), unit="frame", disable=not progress, desc=Path(movie_path).name)
    try:  # the bar is closed on any error, so the error prints on a line of its own
        ensure_folder(out if kind is None else out.parent, "for the frames" if kind is None else f"to write {out.name} into")
        fps = float(emu.av_info()["fps"]) / every
        frames = ((i, f) for i, f in enumerate(_counted(play(movie, emulator=emu, source=f"{movie_path}: Core.bin"), bar)) if i % every == 0)
        if kind is None:
            return _write_pngs(frames, out)
        if kind == ".gif":
            return _write_gif(frames, out, fps, overwrite)
        return _write_mp4(imageio, frames, out, fps, overwrite)
    finally:
        bar.close()
        emu.close()


def _counted(screens: Iterator[np.ndarray], bar: tqdm) -> Iterator[np.ndarray]:
    for screen in screens:
        bar.update(1)
        yield screen


def _output_kind(out: Path) -> str | None:
    """Return ``".gif"`` or ``".mp4"`` for a video file, ``None`` for a folder of PNGs.

    Only ``.gif`` and ``.mp4`` name files: anything else is a folder, dots
    and all (``out/Zone1.Act1`` is a folder named after a state).
    """
    if out.is_dir():
        return None
    suffix = out.suffix.lower()
    if suffix in VIDEO_SUFFIXES:
        return suffix
    if out.exists():
        raise InvalidArgumentError(
            f"Expected the output to be a folder (for PNG frames), a .gif or an .mp4 file; found {str(out)!r}, "
            "a file that is none of them. Name a folder, or a file ending in .gif or .mp4."
        )
    return None


def _require_imageio(out: Path):  # the imageio.v2 module
    try:
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401 - the plugin that writes .mp4
    except ImportError:
        raise InvalidArgumentError(
            f"Expected imageio with its ffmpeg plugin to write {out}; found them not installed. "
            f"Export to a .gif or to a folder of PNG frames instead, or: {install_extra('video')}"
        ) from None
    return imageio


def _write_pngs(frames: Iterator[tuple[int, np.ndarray]], folder: Path) -> int:
    from PIL import Image

    ensure_folder(folder, "for PNG frames")
    count = 0
    for index, frame in frames:
        path = folder / FRAME_PATTERN.format(index)
        try:
            Image.fromarray(frame).save(path)
        except OSError as exc:
            raise FileSystemError(f"Expected to write {path}; found it cannot be written: {exc}.") from None
        count += 1
    return count


def _write_gif(frames: Iterator[tuple[int, np.ndarray]], out: Path, fps: float, overwrite: bool) -> int:
    """Stream the frames into a GIF at 30 fps at most, one frame encoded at a time (see :mod:`retrokit.movie.gif`)."""
    step = gif_step(fps)
    with atomic_output(out, overwrite=overwrite) as stream:
        writer = GifWriter(stream, fps / step)
        for k, (_, frame) in enumerate(frames):
            if k % step == 0:
                writer.add(frame)
        if writer.count == 0:
            raise MovieError(f"Expected a movie with frames to write {out}; found none.")
        writer.close()
    return writer.count


def _write_mp4(imageio, frames: Iterator[tuple[int, np.ndarray]], out: Path, fps: float, overwrite: bool) -> int:
    ensure_folder(out.parent, f"to write {out.name} into")
    fd, tmp_name = tempfile.mkstemp(prefix=f".{out.stem}.", suffix=".mp4", dir=out.parent)
    os.close(fd)
    count = 0
    try:
        with imageio.get_writer(tmp_name, fps=fps, codec="libx264", macro_block_size=1) as writer:
            for _, frame in frames:
                writer.append_data(frame)
                count += 1
        atomic_write(out, Path(tmp_name).read_bytes(), overwrite=overwrite)
    finally:
        Path(tmp_name).unlink(missing_ok=True)
    return count


def state_from_movie(game: Game, movie_path: str | os.PathLike[str], frame: int | None = None) -> VettedState:
    """Replay a movie of ``game`` for ``frame`` frames (all by default) and return the state it reaches.

    Raises:
        MovieError: The movie is malformed, of another game, or shorter than ``frame``.
    """
    movie = read_bk2(movie_path)
    if movie.game != game.name:
        raise MovieError(
            f"Expected a movie of {game.name}; found one of {movie.game} in {str(movie_path)!r}. "
            f"Give its game instead: retrokit integrate {movie.game} NAME --movie {shell_word(movie_path)}"
        )
    length = len(movie.frames)
    frame = length if frame is None else frame
    if not 0 <= frame <= length:
        raise MovieError(f"Expected a frame from 0 to {length} (the movie's length) for --frame; found {frame}.")
    with Emulator(game.system, game.require_rom(), ports=max(2, movie.players)) as emu:
        for _ in replay(movie, emu, source=f"{movie_path}: Core.bin", stop=frame):
            pass
        return emu.get_state()
