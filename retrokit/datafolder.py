"""The per-user data folder, and the one way to a path inside it.

The data folder holds what retrokit makes for the user: imported ROMs
(``<data>/roms/<Game>/rom.<ext>``), the user's game folders (``<data>/games/<Game>/``:
made states, game.yaml copies with the user's fields), the studio's drafts, the
cores' saves, and retrokit's own records (verdicts, owners, caches), some of which
vouch for files. It is ``RETROKIT_DATA`` if set, else ``$XDG_DATA_HOME/retrokit``,
else ``~/.local/share/retrokit``.

Every path in it that retrokit writes, or reads back as its own, comes from
:func:`data_path`, which refuses a symlink at any level below the data folder:
a link planted there (``<data>/games/Dasher-Genesis`` pointing at someone else's
folder) would send retrokit's writes elsewhere, and let files nobody wrote here
pass for its own. :mod:`retrokit.paths` re-exports these names.
"""

from __future__ import annotations

import os
from pathlib import Path

from retrokit.errors import InvalidArgumentError, PlantedLinkError, printable, shown

DATA_ENV = "RETROKIT_DATA"


def data_dir() -> Path:
    """Return the per-user data folder (it may not exist yet)."""
    override = os.environ.get(DATA_ENV)
    if override:
        return Path(override).expanduser()
    xdg = os.environ.get("XDG_DATA_HOME")
    if xdg and Path(xdg).is_absolute():  # the XDG spec says to ignore relative paths
        return Path(xdg) / "retrokit"
    return Path.home() / ".local" / "share" / "retrokit"


def data_path(*parts: str, data: Path | str | None = None) -> Path:
    """``<data>/<parts...>``, once no folder or file on the way below the data folder is a symlink.

    Each level that exists is checked (``lstat``), the last one too: a writer
    that makes the rest makes real folders. The data folder itself is trusted
    even as a link: the user names it (``RETROKIT_DATA``, ``--data-dir``, the
    home folder), and a link there is the user's own choice (a data folder on
    another disk); whoever could plant it could set the variable as well.

    Args:
        parts: The path below the data folder, one or more names (``"games", "Dasher-Genesis"``).
        data: The data folder; by default :func:`data_dir`.

    Raises:
        PlantedLinkError: One level is a symlink (the message names it, where it points, and the fix).
        InvalidArgumentError: ``parts`` would lead out of the data folder (an absolute path, ``..``).
    """
    path = Path(data) if data is not None else data_dir()
    names = Path(*parts).parts if parts else ()
    if names and (Path(names[0]).is_absolute() or ".." in names):  # a name made of user input, checked or not
        raise InvalidArgumentError(
            f"Expected a path inside retrokit's data folder; got {shown(os.path.join(*parts))}, which leads out of it. "
            "Use a plain name."
        )
    for name in names:
        path = path / name
        if os.path.islink(path):
            raise _planted(path, games=names[0] == "games")
    return path


def inside_data(path: Path | str) -> Path:
    """Return ``path``, checked as :func:`data_path` checks its parts if it lies in the data folder (as written)."""
    path = Path(path)
    root = os.path.abspath(data_dir())
    full = os.path.abspath(path)
    if os.path.commonpath([root, full]) != root or full == root:
        return path
    data_path(os.path.relpath(full, root))
    return path


def _planted(link: Path, *, games: bool) -> PlantedLinkError:
    try:
        target = os.readlink(link)
    except OSError:  # gone meanwhile: still not retrokit's own
        target = "?"
    return PlantedLinkError(
        f"Expected '{printable(str(link))}' in retrokit's data folder to be a real folder or file; found a symlink to "
        f"'{printable(target)}', which would send retrokit's files elsewhere. Remove the link (retrokit makes the "
        "folder again)" + ("; to keep game folders elsewhere, name their parent folder in RETROKIT_GAMES." if games else ".")
    )


def records_dir(kind: str) -> Path:
    """``<data>/<kind>``: a folder of retrokit's own records (``state-probes``, ``state-owners``, ``core-probes``).

    Records vouch for files (a verdict lets a state load unprobed), so the folder
    is never a link (:func:`data_path`); read its files with ``follow=False``
    (:func:`retrokit.paths.read_regular_file`), and write them with the atomic
    writer, whose rename replaces a link at the file rather than writing through it.

    Raises:
        PlantedLinkError: It is a symlink.
    """
    return data_path(kind)


def user_games_dir(data: Path | str | None = None) -> Path:
    """Return the folder of the user's game folders, ``<data>/games``, as searched (it may not exist yet).

    Game folders are read as any other (untrusted input); writers take their
    paths from :func:`data_path` (``data_path("games", name)``).
    """
    return (Path(data) if data is not None else data_dir()) / "games"


def roms_dir(data: Path | str | None = None) -> Path:
    """Return the folder of imported ROMs: ``<data>/roms`` (never a link: :func:`data_path`)."""
    return data_path("roms", data=data)


def imported_rom_path(game: str, ext: str, data: Path | str | None = None) -> Path:
    """Return where the imported ROM of ``game`` lives: ``<data>/roms/<game>/rom.<ext>`` (no link on the way)."""
    return data_path("roms", game, f"rom.{ext.lstrip('.')}", data=data)
