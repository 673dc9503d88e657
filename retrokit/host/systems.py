"""System descriptors: each console's buttons, RAM layout, types and core.

The descriptors live in ``systems.yaml`` beside this module.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import yaml

from retrokit.errors import DataFileError, InvalidArgumentError, UnknownNameError, UnsupportedSystemError, did_you_mean

_FILE = Path(__file__).with_name("systems.yaml")
#: The state cap of a core whose descriptor names none: far above every such core's (Genesis Plus GX's is 1 MiB).
DEFAULT_STATE_MAX = 16 * 2**20
_T = TypeVar("_T")


@dataclass(frozen=True)
class DetectRule:
    """One way a ROM's bytes tell its system (``detect:`` in systems.yaml; read by :mod:`retrokit.data.roms`).

    Attributes:
        at: Offsets where the mark may be (the first where it is counts).
        mark: The bytes there; empty for a rule by size or checksum.
        complement: The mark is a checksum's complement: two little-endian words whose XOR is 0xFFFF.
        byte_at: An offset, after the mark's start, of one more byte to check (``None``: none).
        byte_shift: Bits to drop from that byte (4: its high nibble).
        byte_in: The values it may have, once shifted.
        sizes: For a system whose ROMs have no header: the file sizes its ROMs have.
        extensions: The file extensions a rule by size needs.
    """

    at: tuple[int, ...] = ()
    mark: bytes = b""
    complement: bool = False
    byte_at: int | None = None
    byte_shift: int = 0
    byte_in: frozenset[int] = frozenset()
    sizes: frozenset[int] = frozenset()
    extensions: tuple[str, ...] = ()


@dataclass(frozen=True)
class System:
    """What retrokit knows about one console.

    Attributes:
        name: Gym Retro's name for the system, e.g. ``"Genesis"``.
        core: The libretro core's library name, e.g. ``"genesis_plus_gx"``.
        extensions: ROM file extensions, without the dot.
        aliases: Other extensions its ROM dumps come in.
        ram_base: The console address of the first byte of system RAM.
        ram_swap: The word size of the RAM buffer's byte swap (1: none).
        buttons: The console's name for each RetroPad id, ``None`` where unused.
        types: The type codes integrations of this system usually use.
        options: Core option defaults for this system; ``""`` (``null`` in the descriptor) leaves
            the option unanswered, so the core keeps the value it falls back to.
        actions: Gym Retro's default groups of button combinations.
        screen: ``(height, width)`` of observations, or ``None`` for the first frame's.
        frame_rates: The console's frames per second, by video standard (``"ntsc"``,
            ``"pal"``, or ``"lcd"`` for a handheld's one rate); empty where it
            depends on the game (arcade boards) or is not listed.
        state_length: ``"exact"``: the core reads its ``retro_serialize_size``
            bytes of a state whatever length it is given, so a state of another
            length is refused before it; ``"parsed"``: the core reads a state
            within the length it is given, so any length goes to it as it is.
        detect: How its ROMs' bytes tell the system, for ROMs no game knows.
        rom_format: The layout a ROM's header describes (``"ines"``), checked by
            :func:`retrokit.data.roms.rom_problem`; ``""``: none.
        missing_mappers: Mapper numbers of that format the core cannot run.
        reset_before_state: The core restores some state only partly (so a
            load's outcome would depend on what ran before it): the console is
            reset before each state is loaded, so every load starts alike.
        reload_before_state: The core keeps part of the console outside its
            states, where a reset does not reach it either: the game is unloaded
            and loaded again before each state is loaded (then reset, if
            ``reset_before_state``), as a fresh core would take it, and before
            each hard reset.
        reload_md5: With ``reload_before_state``, the ROMs (by MD5) whose state
            loads need the reload; with ``reload_cartridges`` also empty, every
            ROM's do. The others' state loads are a load, and their hard resets
            restore what the first one (a reload) left: see :meth:`reloads_states`.
        reload_cartridges: The cartridge classes (named in stella's states) whose
            state loads need the reload too.
        start: The button that starts a game from its title screen.
        jump: The button JERK jumps with, unless a scenario names another.
        switches: Console switches (not pad buttons), which default action sets, the random
            agent, JERK and validate's smoke run leave alone.
        extension_wins_over: Systems whose header this system's ROMs carry: a file with this system's
            extension whose header names one of them is this system's (stable-retro goes by the extension).
        state_max: The largest state the core writes, in bytes: a state inflating past it is refused.
        movie_buttons: Buttons stable-retro's ``.bk2`` letters lack, recorded all the same: the button's
            ``(frame letter, key-line name)``, as BizHawk's own input log of the console writes them.
        proven_by: What proves retrokit runs the system right, by kind (``"cartridge"``,
            ``"stable-retro"``, ``"ale-py"``): a game's name, or ``""``; empty if nothing does.
        build_speedup: How many times faster this system's env steps on the core ``retrokit
            build-core`` makes than on the wheel's, as measured (``None``: not measured).
        build_measured: On what, when and how loaded a machine ``build_speedup`` was measured.
    """

    name: str
    core: str
    extensions: tuple[str, ...]
    ram_base: int
    ram_swap: int
    buttons: tuple[str | None, ...]
    types: tuple[str, ...] = ()
    options: dict[str, str] = field(default_factory=dict)
    actions: tuple[tuple[tuple[str, ...], ...], ...] = ()
    screen: tuple[int, int] | None = None
    aliases: tuple[str, ...] = ()
    frame_rates: dict[str, float] = field(default_factory=dict)
    state_length: str = "exact"
    reset_before_state: bool = False
    reload_before_state: bool = False
    reload_md5: frozenset[str] = frozenset()
    reload_cartridges: frozenset[str] = frozenset()
    detect: tuple[DetectRule, ...] = ()
    rom_format: str = ""
    missing_mappers: frozenset[int] = frozenset()
    start: str = "START"
    jump: str | None = None
    switches: tuple[str, ...] = ()
    movie_buttons: dict[str, tuple[str, str]] = field(default_factory=dict)
    extension_wins_over: tuple[str, ...] = ()
    state_max: int = DEFAULT_STATE_MAX
    proven_by: dict[str, str] = field(default_factory=dict)
    build_speedup: float | None = None
    build_measured: str = ""

    def __post_init__(self) -> None:
        named = (("start", [self.start]), ("jump", [self.jump] if self.jump else []), ("switches", self.switches),
                 ("movie_buttons", list(self.movie_buttons)))  # fmt: skip
        for what, names in named:
            for name in names:
                if name not in self.button_names:
                    raise DataFileError(
                        f"{_FILE}: system {self.name!r}: expected its {what} to be one of its buttons "
                        f"({', '.join(self.button_names)}), got {name!r}." + did_you_mean(str(name), self.button_names)
                    )

    def __str__(self) -> str:
        return self.name

    @property
    def button_names(self) -> tuple[str, ...]:
        """The names of the buttons that exist, in RetroPad id order."""
        return tuple(b for b in self.buttons if b is not None)

    def button_bit(self, name: str) -> int:
        """Return the RetroPad id of a button.

        Raises:
            UnknownNameError: The system has no such button.
        """
        try:
            return self.buttons.index(name)
        except ValueError:
            raise UnknownNameError(
                f"Expected one of {self.name}'s buttons ({', '.join(self.button_names)}), got {name!r}."
                + did_you_mean(name, self.button_names)
            ) from None

    def frame_rate(self, reported: float | None = None) -> float:
        """The console's real frame rate, in frames per second.

        Args:
            reported: The rate the core reports for the game it runs; it tells
                which of the console's video standards the game runs in
                (NTSC or PAL), and is the answer where the descriptor lists no rate.
        """
        if not self.frame_rates:
            return float(reported) if reported else 60.0
        if reported is None:
            return next(iter(self.frame_rates.values()))
        return min(self.frame_rates.values(), key=lambda rate: abs(rate - reported))

    @property
    def proven(self) -> bool:
        """Whether anything proves retrokit runs this system right (``proven_by``)."""
        return bool(self.proven_by)

    @property
    def present_mask(self) -> int:
        """The RetroPad bits of the buttons the console has (``buttons`` entries that are not ``None``)."""
        return self.mask(self.button_names)

    @property
    def switch_mask(self) -> int:
        """The RetroPad bits of the console switches."""
        return self.mask(self.switches)

    @property
    def pad_buttons(self) -> tuple[str, ...]:
        """The buttons that exist, console switches left out, in RetroPad id order."""
        return tuple(b for b in self.button_names if b not in self.switches)

    def mask(self, buttons: Iterable[str]) -> int:
        """Return the RetroPad bit mask that presses the named buttons."""
        if isinstance(buttons, str):
            raise InvalidArgumentError(f"Expected a list of button names, got the string {buttons!r}; write [{buttons!r}].")
        value = 0
        for name in buttons:
            value |= 1 << self.button_bit(name)
        return value

    def reloads_states(self, rom_md5: str, cartridge: str) -> bool:
        """Whether loading a state into a console of this ROM must load the game again first.

        Args:
            rom_md5: The ROM's MD5, hex.
            cartridge: The cartridge class the core's states name (``""`` when they name none).
        """
        if not self.reload_before_state:
            return False
        if not (self.reload_md5 or self.reload_cartridges):
            return True
        return rom_md5 in self.reload_md5 or cartridge in self.reload_cartridges

    def buttons_of(self, mask: int) -> list[str]:
        """Return the names of the buttons a bit mask presses."""
        return [b for i, b in enumerate(self.buttons) if b is not None and mask >> i & 1]


def _parse(name: str, entry: object) -> System:
    if not isinstance(entry, dict):
        raise DataFileError(f"{_FILE}: expected a mapping for system {name!r}, got {type(entry).__name__}.")
    try:
        ram = entry.get("ram", {})
        return System(
            name=name,
            core=str(entry["core"]),
            extensions=tuple(entry["extensions"]),
            ram_base=int(ram.get("base", 0)),
            ram_swap=int(ram.get("swap", 1)),
            buttons=tuple(entry["buttons"]),
            types=tuple(entry.get("types", ())),
            options={str(k): "" if v is None else str(v) for k, v in (entry.get("options") or {}).items()},
            actions=tuple(tuple(tuple(combo) for combo in group) for group in entry.get("actions", ())),
            screen=tuple(entry["screen"]) if "screen" in entry else None,
            aliases=tuple(entry.get("aliases", ())),
            frame_rates={str(k): float(v) for k, v in (entry.get("frame_rate") or {}).items()},
            state_length=_one_of(entry.get("state_length", "exact"), ("exact", "parsed"), "state_length"),
            reset_before_state=_one_of(entry.get("reset_before_state", False), (False, True), "reset_before_state"),
            reload_before_state=_one_of(entry.get("reload_before_state", False), (False, True), "reload_before_state"),
            reload_md5=frozenset(str(m).lower() for m in (entry.get("reload_only_for") or {}).get("md5", ())),
            reload_cartridges=frozenset(str(c) for c in (entry.get("reload_only_for") or {}).get("cartridges", ())),
            detect=tuple(_detect_rule(rule) for rule in entry.get("detect") or ()),
            rom_format=_one_of(str((entry.get("rom") or {}).get("format", "")), ("", "ines"), "rom.format"),
            missing_mappers=frozenset(int(m) for m in (entry.get("rom") or {}).get("missing_mappers", ())),
            start=str(entry.get("start", "START")),
            jump=str(entry["jump"]) if entry.get("jump") else None,
            switches=tuple(str(b) for b in entry.get("switches", ())),
            extension_wins_over=tuple(str(n) for n in entry.get("extension_wins_over", ())),
            state_max=_positive(entry.get("state_max", DEFAULT_STATE_MAX), "state_max"),
            movie_buttons={str(k): _letter_and_name(v) for k, v in (entry.get("movie_buttons") or {}).items()},
            proven_by={str(k): str(v or "") for k, v in (entry.get("proven_by") or {}).items()},
            build_speedup=float(entry["build_core"]["speedup"]) if "build_core" in entry else None,
            build_measured=str((entry.get("build_core") or {}).get("measured", "")),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise DataFileError(f"{_FILE}: system {name!r} is malformed: {exc!r}.") from exc


def _positive(value: object, key: str) -> int:
    if type(value) is not int or value <= 0:
        raise ValueError(f"{key} must be a positive number of bytes, not {value!r}")
    return value


def _letter_and_name(value: object) -> tuple[str, str]:
    if not (isinstance(value, list) and len(value) == 2 and len(str(value[0])) == 1 and str(value[1])):
        raise ValueError(f"a movie button is [one-character letter, key-line name], not {value!r}")
    return str(value[0]), str(value[1])


def _detect_rule(rule: dict) -> DetectRule:
    at = rule.get("at", ())
    mark = bytes.fromhex(rule["hex"]) if "hex" in rule else str(rule.get("text", "")).encode("ascii")
    byte = rule.get("byte") or {}
    made = DetectRule(
        at=tuple(at) if isinstance(at, list) else (int(at),) if at != () else (),
        mark=mark,
        complement=_one_of(rule.get("complement", False), (False, True), "complement"),
        byte_at=int(byte["at"]) if byte else None,
        byte_shift=int(byte.get("shift", 0)),
        byte_in=frozenset(int(v) for v in byte.get("in", ())),
        sizes=frozenset(int(v) for v in rule.get("sizes", ())),
        extensions=tuple(str(e) for e in rule.get("extensions", ())),
    )
    marked = bool(made.mark) or made.complement
    if marked == bool(made.sizes) or marked != bool(made.at):
        raise ValueError(f"a detect rule holds a mark (at + text, hex or complement) or sizes, not both: {rule!r}")
    return made


def _one_of(value: _T, allowed: tuple[_T, ...], key: str) -> _T:
    if value not in allowed or type(value) is not type(allowed[0]):
        raise ValueError(f"{key} must be one of {', '.join(map(str, allowed))}, not {value!r}")
    return value


@functools.cache
def all_systems() -> dict[str, System]:
    """Return every known system by name."""
    with open(_FILE, encoding="utf-8") as f:
        # libyaml's loader where PyYAML has it: every process that makes an env reads this file, and the
        # pure-Python one takes a fifth of a second over it.
        data = yaml.load(f, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    systems = {name: _parse(name, entry) for name, entry in data.items()}
    for system in systems.values():
        for other in system.extension_wins_over:
            if other not in systems:
                raise DataFileError(
                    f"{_FILE}: system {system.name!r}: expected extension_wins_over to name systems; found {other!r}."
                    + did_you_mean(other, systems)
                )
    return systems


def largest_state() -> int:
    """The largest state any core writes (the largest ``state_max``): what a state read for no known system may be."""
    return max(system.state_max for system in all_systems().values())


def get_system(name: str | System) -> System:
    """Return the descriptor of a system by name (case-insensitive).

    Raises:
        UnsupportedSystemError: No system has that name.
    """
    if isinstance(name, System):
        return name
    systems = all_systems()
    if name in systems:
        return systems[name]
    for key, system in systems.items():
        if key.lower() == str(name).lower():
            return system
    raise UnsupportedSystemError(
        f"Expected a system name ({', '.join(systems)}), got {name!r}." + did_you_mean(str(name), systems)
    )


def systems_by_extension() -> dict[str, System]:
    """Return the system of each ROM extension (without dot) the descriptors list.

    Where two systems list the same extension, the first in ``systems.yaml`` has
    it; aliases come after every system's own extensions.
    """
    known: dict[str, System] = {}
    for system in all_systems().values():
        for ext in system.extensions:
            known.setdefault(ext, system)
    for system in all_systems().values():
        for ext in system.aliases:
            known.setdefault(ext, system)
    return known


def extension_of(filename: str | os.PathLike[str]) -> str:
    """Return a file name's extension, lowercase and without the dot (``""`` if none)."""
    return Path(filename).suffix.lower().lstrip(".")


def system_for_extension(ext: str) -> System:
    """Return the system whose ROMs have a file extension (``"md"`` or ``".md"``).

    Raises:
        UnsupportedSystemError: No system uses that extension.
    """
    ext = ext.lower().lstrip(".")
    known = systems_by_extension()
    if ext in known:
        return known[ext]
    raise UnsupportedSystemError(
        f"Expected a ROM file extension retrokit knows ({', '.join('.' + e for e in sorted(known))}), got "
        f"{'.' + ext!r}. Rename the file, or pass the system explicitly."
        + did_you_mean(f".{ext}", [f".{k}" for k in known])
    )
