"""A movie in memory, and how each system's buttons are laid out in a ``.bk2`` file.

See :mod:`retrokit.movie.bk2` for the file format.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, field

from retrokit.data.games import normalize_name
from retrokit.errors import MovieError
from retrokit.host.systems import get_system

#: retrokit button name -> (the frame letter, the key-line name), as stable-retro writes them.
LETTERS: dict[str, tuple[str, str]] = {
    "A": ("A", "A"), "B": ("B", "B"), "C": ("C", "C"),
    "X": ("X", "X"), "Y": ("Y", "Y"), "Z": ("Z", "Z"),
    "START": ("S", "Start"), "SELECT": ("s", "Select"), "MODE": ("M", "Mode"),
    "UP": ("U", "Up"), "DOWN": ("D", "Down"), "LEFT": ("L", "Left"), "RIGHT": ("R", "Right"),
    "L": ("l", "L"), "R": ("r", "R"), "BUTTON": ("B", "Button"),
}

#: retrokit system name -> the Platform header value, where the two differ.
PLATFORMS = {"Genesis": "GEN", "Snes": "SNES", "Nes": "NES", "Atari2600": "A26"}

#: The header lines stable-retro writes besides Platform and GameName, in its order.
DEFAULT_HEADER = {
    "MovieVersion": "Retro", "Author": "?", "emuVersion": "?", "SHA1": "?", "Core": "?", "rerecordCount": "1",
}


#: The header key under which retrokit records its start state's SHA-256 (beside the ROM's, under SHA1).
STATE_DIGEST = "StateSHA256"


def _default_header() -> dict[str, str]:
    return dict(DEFAULT_HEADER)


@dataclass
class Movie:
    """One recorded episode: a game, its start state and the buttons of every frame.

    Attributes:
        game: The game's name, ``<Name>-<System>`` (a ``-v0`` suffix is dropped).
        system: The system's name, e.g. ``"Genesis"``.
        players: How many players' buttons each frame holds.
        state: The uncompressed start state, or ``None`` to start from power-on.
        frames: Per emulated frame, one RetroPad bit mask per player (bit ``i``
            is ``System.buttons[i]``).
        header: The other ``Header.txt`` lines (all but Platform and GameName), in order.
    """

    game: str
    system: str
    players: int = 1
    state: bytes | None = None
    frames: list[tuple[int, ...]] = field(default_factory=list)
    header: dict[str, str] = field(default_factory=_default_header)

    def __post_init__(self) -> None:
        self.game = normalize_name(self.game)
        self.system = get_system(self.system).name
        if not isinstance(self.players, int) or self.players < 1:
            raise MovieError(f"Expected a movie of at least 1 player; found players={self.players!r}.")


@dataclass(frozen=True)
class Layout:
    """How one system's buttons appear in a movie.

    Attributes:
        system: The system's name.
        columns: ``(RetroPad id, letter, key-line name)`` per recorded button, in file order.
        allowed: The mask of the buttons a movie can hold.
        stable_retro: The mask of those stable-retro reads (its letters; not a descriptor's ``movie_buttons``).
    """

    system: str
    columns: tuple[tuple[int, str, str], ...]
    allowed: int
    stable_retro: int = 0

    def describe(self) -> str:
        """Return the buttons a movie of this system can hold, e.g. ``"Z, X, ..., B"``."""
        return ", ".join(name for _, _, name in self.columns)

    def check_frame(self, frame: Sequence[int], players: int, where: str) -> tuple[int, ...]:
        """Return ``frame`` as a tuple of masks, checked for the player count and the recordable buttons.

        Raises:
            MovieError: The frame has the wrong number of masks, or presses a button
                the format cannot hold.
        """
        masks = tuple(int(m) for m in frame)
        if len(masks) != players:
            raise MovieError(f"{where}: expected {players} button mask(s), one per player; found {masks!r}.")
        for player, mask in enumerate(masks, 1):
            if mask < 0 or mask & ~self.allowed:
                extra = get_system(self.system).buttons_of(mask & ~self.allowed) if mask >= 0 else [str(mask)]
                raise MovieError(
                    f"{where}: expected player {player} to press only buttons that .bk2 movies of {self.system} record "
                    f"({self.describe()}); found mask {mask:#x}, which also presses {extra or 'unknown bits'}. "
                    "stable-retro's format has no letter for them, so the movie could not replay; leave them out."
                )
        return masks


@functools.cache
def layout(system: str) -> Layout:
    """Return the movie layout of a system (by name, case-insensitive)."""
    desc = get_system(system)
    letters = {**LETTERS, **desc.movie_buttons}
    columns = [(bit, *letters[name]) for bit, name in enumerate(desc.buttons) if name in letters]
    columns.sort(reverse=True)  # stable-retro lists buttons from the highest id down
    allowed = sum(1 << bit for bit, _, _ in columns)
    theirs = sum(1 << bit for bit, name in enumerate(desc.buttons) if name in LETTERS)
    return Layout(desc.name, tuple(columns), allowed, theirs)


def platform_of(system: str) -> str:
    """Return the ``Platform`` header value of a system."""
    name = get_system(system).name
    return PLATFORMS.get(name, name)


def system_of_platform(platform: str) -> str:
    """Return the system a ``Platform`` header value names.

    Raises:
        UnsupportedSystemError: It names no system.
    """
    for system, value in PLATFORMS.items():
        if value == platform:
            return system
    return get_system(platform).name
