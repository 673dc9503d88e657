"""The ``.bk2`` movie format, as stable-retro reads and writes it.

A ``.bk2`` file is a zip archive (members deflated) of three files:

``Input Log.txt``
    ``[Input]``, a key line naming the columns (``P1 Z|P1 X|...|P2 B|``), one
    line per emulated frame (``|..|.......U...B|``), and ``[/Input]`` with no
    newline after it. A frame line starts with a command group (``..``: BizHawk's
    Reset and Power, always blank and ignored by stable-retro), then one group
    per player. In a group each button is its letter when pressed, else ``.``.
``Header.txt``
    ``Key Value`` lines: ``MovieVersion Retro``, ``Author ?``, ``emuVersion ?``,
    ``Platform GEN``, ``GameName Airstriker-Genesis-v0`` (the game's folder name in
    stable-retro's data: ``-v0`` for its stable games, none for its experimental
    and contrib ones), ``SHA1 ?``, ``Core ?``, ``rerecordCount 1``.
``Core.bin``
    The start state, uncompressed core serialization (only deflated by the zip).

Details stable-retro depends on, found by recording and reading real movies:
its key line has no ``LogKey:`` prefix (a BizHawk-style ``LogKey:#Reset|Power|#``
prefix makes its reader fail); buttons are listed in descending RetroPad id
order; only buttons with a letter in :data:`LETTERS` are recorded (it drops the
others, e.g. PC Engine's I to VI and RUN, silently; retrokit records those as
BizHawk's own input log of the console does, its descriptor's ``movie_buttons``,
and stable-retro's reader, which goes by letter, skips letters it does not
know); it cannot open a movie without
``Core.bin``, nor decode keys without ``Platform``. It maps frame characters to
buttons by letter; retrokit maps them by column and checks the letter, so any
movie retrokit accepts plays the same in both.
"""

from __future__ import annotations

import datetime
import errno
import io
import os
import re
import zipfile
import zlib
from pathlib import Path

from retrokit.data.games import stable_retro_name
from retrokit.errors import MovieError, UnsupportedSystemError
from retrokit.host.systems import get_system
from retrokit.movie.model import Layout, Movie, layout, platform_of, system_of_platform
from retrokit.paths import atomic_write, require_regular_file

MAX_TEXT_SIZE = 32 * 2**20
"""The largest header or input log read: about a million frames (over four hours at 60 fps)."""
INPUT_LOG = "Input Log.txt"
HEADER = "Header.txt"
STATE = "Core.bin"

#: The header keys in the order stable-retro writes them; others follow in the movie's order.
HEADER_ORDER = ("MovieVersion", "Author", "emuVersion", "Platform", "GameName", "SHA1", "Core", "rerecordCount")
_PLAYER_COLUMN = re.compile(r"P(\d+) (.+)")

# --- Reading ---------------------------------------------------------------------------------


def read_bk2(path: str | os.PathLike[str]) -> Movie:
    """Read a ``.bk2`` movie written by retrokit, stable-retro or Gym Retro.

    Raises:
        MovieError: The file is missing, not a zip, truncated, lacks a member, or
            its header or input log does not follow the format. The message names
            the file, what was expected and what was found.
    """
    path = Path(path)
    if path.is_dir():
        raise MovieError(f"Expected a .bk2 movie at {path}; found a folder.")
    if path.exists():
        require_regular_file(path, "a .bk2 movie")  # a FIFO would block, a device never end
    try:
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
            for member in (HEADER, INPUT_LOG):
                if member not in names:
                    raise MovieError(
                        f"{path}: expected a .bk2 movie holding {member!r}; found only "
                        f"{', '.join(map(repr, names)) or 'no files'}. Was it made by another program?"
                    )
            header_text = _text(path, archive, HEADER)
            system, game, header = _parse_header(path, header_text)
            log_text = _text(path, archive, INPUT_LOG)
            # no larger than the movie's core writes a state (systems.yaml's state_max)
            state = _member(path, archive, STATE, get_system(system).state_max) if STATE in names else None
    except FileNotFoundError:
        raise MovieError(f"Expected a .bk2 movie at {path}; found no such file.") from None
    except IsADirectoryError:
        raise MovieError(f"Expected a .bk2 movie at {path}; found a folder.") from None
    except OSError as exc:  # a symlink loop, no permission, a failing disk
        found = "a symlink loop" if exc.errno == errno.ELOOP else f"it cannot be read: {exc.strerror or exc}"
        raise MovieError(f"Expected a .bk2 movie at {path}; found {found}.") from None
    except (zipfile.BadZipFile, zlib.error, EOFError) as exc:
        raise MovieError(
            f"{path}: expected a .bk2 movie, which is a zip file; found a file that is not a complete zip "
            f"({exc}). It may be truncated: record it again."
        ) from None
    if state == b"":  # read as power-on, it would replay another game than the one recorded
        raise MovieError(
            f"{path}: expected {STATE!r} to hold the movie's start state; found 0 bytes. A movie that starts at "
            f"power-on has no {STATE!r}: record it again, or copy the movie again if it was cut short."
        )
    players, frames = _parse_log(path, log_text, layout(system))
    return Movie(game, system, players, state, frames, header)


def _member(path: Path, archive: zipfile.ZipFile, member: str, limit: int) -> bytes:
    """A member's bytes, refused once more than ``limit`` of them inflate (a zip bomb is never inflated whole)."""
    with archive.open(member) as stream:
        data = stream.read(limit + 1)
    if len(data) > limit:
        raise MovieError(
            f"{path}: expected {member!r} to hold at most {limit} bytes; found more. It is not a movie retrokit "
            "or stable-retro wrote."
        )
    return data


def _text(path: Path, archive: zipfile.ZipFile, member: str) -> str:
    try:
        return _member(path, archive, member, MAX_TEXT_SIZE).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MovieError(f"{path}: expected {member!r} to be UTF-8 text; found bytes that are not ({exc}).") from None


def _parse_header(path: Path, text: str) -> tuple[str, str, dict[str, str]]:
    values: dict[str, str] = {}
    for line in text.splitlines():
        if line.strip():
            key, _, value = line.strip().partition(" ")
            values[key] = value
    if "Platform" not in values:
        raise MovieError(f"{path}: expected {HEADER!r} to have a 'Platform' line (e.g. 'Platform GEN'); found none.")
    try:
        system = system_of_platform(values.pop("Platform"))
    except UnsupportedSystemError as exc:
        raise MovieError(f"{path}: {HEADER!r} names an unknown platform. {exc}") from None
    game = values.pop("GameName", "?")
    return system, game, values


def _parse_log(path: Path, text: str, lay: Layout) -> tuple[int, list[tuple[int, ...]]]:
    lines = text.splitlines()
    numbered = [(i + 1, line.strip()) for i, line in enumerate(lines) if line.strip()]
    where = f"{path}: {INPUT_LOG!r}"
    if not numbered or numbered[0][1] != "[Input]":
        found = repr(numbered[0][1][:60]) if numbered else "an empty file"
        raise MovieError(f"{where}: expected '[Input]' on the first line; found {found}.")
    if len(numbered) < 2 or numbered[1][1].startswith("|") or numbered[1][1] == "[/Input]":
        raise MovieError(f"{where}: expected a key line naming the buttons after '[Input]' (e.g. 'P1 B|'); found none.")
    groups = _parse_key_line(where, numbered[1], lay)
    decode: dict[str, int] = {}
    frames = []
    for number, line in numbered[2:]:
        if line == "[/Input]":
            break
        parts = line.split("|")
        if len(parts) != len(groups) + 3 or parts[0] or parts[-1]:
            example = "|..|" + "|".join("." * len(g) for g in groups) + "|"
            raise MovieError(
                f"{where} line {number}: expected a frame of {len(groups)} player(s) like {example!r}; found {line!r}."
            )
        masks = []
        for player, (group, columns) in enumerate(zip(parts[2:-1], groups), 1):
            mask = decode.get(group)
            if mask is None:
                mask = decode[group] = _decode_group(f"{where} line {number}, player {player}", group, columns)
            masks.append(mask)
        frames.append(tuple(masks))
    return len(groups), frames


def _parse_key_line(where: str, numbered: tuple[int, str], lay: Layout) -> list[list[tuple[int, str, str]]]:
    """Return each player's columns, in file order, from the key line."""
    number, line = numbered
    by_name = {column[2]: column for column in lay.columns}
    line = line.removeprefix("LogKey:")  # BizHawk's form; stable-retro writes the line bare
    groups: dict[int, list[tuple[int, str, str]]] = {}
    for entry in filter(None, (part.strip().lstrip("#") for part in line.split("|"))):
        match = _PLAYER_COLUMN.fullmatch(entry)
        if match is None:
            if groups:  # commands (Reset, Power) come before the players' buttons
                raise MovieError(f"{where} line {number}: expected 'P<n> <button>' columns; found {entry!r}.")
            continue
        player, name = int(match[1]), match[2]
        if name not in by_name:
            raise MovieError(
                f"{where} line {number}: expected {lay.system} buttons ({lay.describe()}); found {entry!r}."
            )
        if player != (len(groups) if player in groups else len(groups) + 1):
            raise MovieError(
                f"{where} line {number}: expected each player's columns together, P1 first, then P2, ...; "
                f"found {entry!r} out of order."
            )
        if by_name[name] in groups.get(player, ()):
            raise MovieError(f"{where} line {number}: expected each button once per player; found {entry!r} twice.")
        groups.setdefault(player, []).append(by_name[name])
    if not groups:
        raise MovieError(f"{where} line {number}: expected a key line naming the buttons (e.g. 'P1 B|'); found {line!r}.")
    return list(groups.values())


def _decode_group(where: str, group: str, columns: list[tuple[int, str, str]]) -> int:
    expected = "".join(letter for _, letter, _ in columns)
    if len(group) != len(columns):
        raise MovieError(f"{where}: expected {len(columns)} button characters ({expected!r} or '.'); found {group!r}.")
    mask = 0
    for char, (bit, letter, name) in zip(group, columns):
        if char == letter:
            mask |= 1 << bit
        elif char != ".":
            raise MovieError(
                f"{where}: expected {letter!r} (pressed) or '.' in the column of {name!r} ({expected!r}); "
                f"found {char!r} in {group!r}."
            )
    return mask


# --- Writing ---------------------------------------------------------------------------------


def encode_bk2(movie: Movie) -> bytes:
    """Return the bytes of a ``.bk2`` file holding ``movie``, laid out as stable-retro writes it.

    Raises:
        MovieError: A frame does not fit the movie's players or presses a button
            the format cannot hold.
    """
    lay = layout(movie.system)
    key_line = "".join(f"P{p} {name}|" for p in range(1, movie.players + 1) for _, _, name in lay.columns)
    encode: dict[tuple[int, ...], str] = {}
    lines = ["[Input]", key_line]
    for index, frame in enumerate(movie.frames):
        frame = frame if type(frame) is tuple else tuple(frame)  # lists and arrays become keys
        text = encode.get(frame)
        if text is None:
            masks = lay.check_frame(frame, movie.players, f"{movie.game} frame {index}")
            groups = ("".join(letter if m >> bit & 1 else "." for bit, letter, _ in lay.columns) for m in masks)
            text = encode[masks] = "|..|" + "|".join(groups) + "|"
        lines.append(text)
    log = "\n".join(lines) + "\n[/Input]"
    values = {**movie.header, "Platform": platform_of(movie.system), "GameName": _file_game_name(movie.game)}
    order = [*HEADER_ORDER, *(k for k in values if k not in HEADER_ORDER)]
    header = "".join(f"{key} {values[key]}\n" for key in order if key in values)
    members = [(INPUT_LOG, log.encode()), (HEADER, header.encode())]
    if movie.state:
        members.append((STATE, bytes(movie.state)))
    buffer = io.BytesIO()
    stamp = datetime.datetime.now().timetuple()[:6]
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, data in members:
            info = zipfile.ZipInfo(name, date_time=stamp)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, data)
    return buffer.getvalue()


def _file_game_name(game: str) -> str:
    """The name stable-retro's player looks the movie's game up by (:func:`retrokit.data.games.stable_retro_name`)."""
    return game if game == "?" else stable_retro_name(game)


def write_bk2(path: str | os.PathLike[str], movie: Movie, *, overwrite: bool = False) -> None:
    """Write ``movie`` to ``path`` through a temporary file renamed into place.

    Writing the same movie again is a no-op.

    Args:
        path: The ``.bk2`` file to write; its folder is created.
        movie: The movie.
        overwrite: Replace a different file already at ``path``.

    Raises:
        FileConflictError: A different file is at ``path`` and ``overwrite`` is false.
        MovieError: A frame does not fit the movie (see :func:`encode_bk2`).
    """
    path = Path(path)
    data = encode_bk2(movie)
    if not overwrite and path.exists() and _holds(path, movie):
        return
    atomic_write(path, data, overwrite=overwrite)


def _holds(path: Path, movie: Movie) -> bool:
    try:
        return read_bk2(path) == movie
    except MovieError:
        return False
