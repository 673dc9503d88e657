"""Every core that a state can crash has its layout checked (issue 42 item 1): PC Engine, Game Boy, NES, SNES.

Each core's states (our cartridges') are fuzzed where its loader reads
structure and small values (tests/statefuzz.py), and every fuzzed state runs on
the raw core, one fork each, in one child: the fuzz must kill or hang each
core, and :mod:`retrokit.host.statelayout` must refuse every state that did,
before any probe. Then one of those states per core goes through every entry
point (tests/entrypoints.py), all in one child: each refuses it with the
layout's reason, and the child lives. And no legal state is refused: every
state retrokit and the stable-retro wheel ship for these systems passes.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from childproc import REPO
from entrypoints import ENTRY_POINTS, entry_cases, refusal, run_cases
from statefuzz import FUZZES, run_raw

from retrokit import paths
from retrokit.data.states import read_state
from retrokit.host.gblayout import gambatte_entries
from retrokit.host.pcelayout import mednafen_sections
from retrokit.host.sneslayout import SPC_RAM, snes9x_blocks
from retrokit.host.statelayout import state_layout_problem

SYSTEMS = list(FUZZES)
#: What each core's check says of the state each entry point is given (the first the raw core died on).
REASONS = {"PCEngine": "outside", "GameBoy": "entries do not", "Nes": "chunks do not", "Snes": "what the core itself"}


@pytest.fixture(scope="module")
def fuzzed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[tuple[bytes, str | None]]]:
    """Each core's fuzzed states, each with how the raw core ended on it (``None``: it lived), from one child."""
    root = tmp_path_factory.mktemp("layout-fuzz")
    states: dict[str, list[tuple[Path, bytes]]] = {}
    for system, fuzz in FUZZES.items():
        states[system] = []
        for i, state in enumerate(fuzz.states()):
            path = root / f"{system}-{i:03d}.bin"
            path.write_bytes(state)
            states[system].append((path, state))
    jobs = [(f.system, REPO / "games" / f.game / f.rom, [p for p, _ in states[s]]) for s, f in FUZZES.items()]
    died = run_raw(jobs, root)
    return {system: [(state, died.get(str(path))) for path, state in found] for system, found in states.items()}


@pytest.mark.parametrize("system", SYSTEMS)
def test_every_state_that_kills_the_raw_core_is_refused_by_its_layout(fuzzed, system: str) -> None:
    deaths = [(state, how) for state, how in fuzzed[system] if how]
    assert deaths, f"the fuzz of {system} no longer kills its raw core: it proves nothing"
    missed = [how for state, how in deaths if not state_layout_problem(system, state)]
    assert not missed, f"{len(missed)} of {len(deaths)} states that killed the raw {system} core passed: {missed}"
    print(f"{system}: {len(deaths)} of {len(fuzzed[system])} fuzzed states killed the raw core ({sorted({h for _, h in deaths})})")


@pytest.fixture(scope="module")
def entries(fuzzed, tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[dict, Path]]:
    """Each core's first killing state through every entry point, all in one child: ``{case: (answer, folder)}``."""
    root = tmp_path_factory.mktemp("layout-entries")
    cases, folders = [], {}
    for system, fuzz in FUZZES.items():
        state = next(state for state, how in fuzzed[system] if how)
        folder = root / system
        cases += entry_cases(system, fuzz.game, system, state, folder)
        folders.update({f"{system}-{entry}": folder for entry in ENTRY_POINTS})
    answers, child = run_cases(cases)
    assert child.signal is None, child.describe()
    return {name: (answer, folders[name]) for name, answer in answers.items()}


@pytest.mark.parametrize("entry", ENTRY_POINTS)
@pytest.mark.parametrize("system", SYSTEMS)
def test_each_entry_point_refuses_a_state_that_kills_the_core(entries, system: str, entry: str) -> None:
    answer, folder = entries[f"{system}-{entry}"]
    said = refusal(entry, answer, folder)
    assert REASONS[system] in said, said


def _shipped(system: str) -> list[Path]:
    ours = sorted((REPO / "games").glob(f"*-{system}/*.state"))
    return ours + sorted(p for kind in paths.wheel_data_dirs() for p in kind.glob(f"*-{system}-v0/*.state"))


@pytest.mark.parametrize("system", [*SYSTEMS, "GbColor"])
def test_every_shipped_state_passes(system: str) -> None:
    files = _shipped(system)
    assert files, f"no shipped {system} state to check"
    problems = {f"{f.parent.name}/{f.name}": state_layout_problem(system, read_state(f)) for f in files}
    assert not {name: problem for name, problem in problems.items() if problem}


def test_a_pce_dot_clock_past_its_three_widths_is_refused() -> None:
    """It indexes the table of the frame's 3 widths: 3 reads past it (the core itself writes 0, 1 or 2)."""
    good = read_state(REPO / "games" / "Skipper-PCEngine" / "Level1.state")
    (at,) = [at for name, at, _ in (mednafen_sections(good) or {})[b"VCE"] if name == b"dot clock"]

    def with_clock(clock: int) -> bytes:
        return good[:at] + bytes([clock]) + good[at + 1 :]

    assert state_layout_problem("PCEngine", with_clock(2)) == ""
    assert "VCE dot clock is 3, outside 0 to 2" in state_layout_problem("PCEngine", with_clock(3))


def test_a_gambatte_label_without_its_end_is_refused() -> None:
    """Its loader copies a label up to its NUL into 8 bytes, never counting: one unended label overruns the heap."""
    good = read_state(REPO / "games" / "Trekker-GameBoy" / "Level1.state")
    at, _ = (gambatte_entries(good) or {})[b"c2mastr"]
    state = bytearray(good)
    state[at - 4] = ord("b")  # the NUL after "c2mastr": the label now runs on into its size
    assert "label unended" in state_layout_problem("GameBoy", bytes(state))


def test_a_snes_voice_past_its_brr_buffer_is_refused() -> None:
    """A voice's position indexes its 24-entry BRR buffer: the core keeps it a multiple of 4 below 12."""
    good = read_state(REPO / "games" / "Skipper-Snes" / "Level1.state")
    block = snes9x_blocks(good)[b"SND"]
    at = good.index(block) + SPC_RAM + 4 * 41 + 128 + 24 + 8  # voice 0's BRR position
    assert state_layout_problem("Snes", good) == ""
    wild = good[:at] + bytes([128]) + good[at + 1 :]
    assert "SND voice 0 BRR position 128" in state_layout_problem("Snes", wild)


@pytest.mark.parametrize("system", [*SYSTEMS, "GbColor"])
def test_every_state_the_core_writes_in_play_passes(system: str) -> None:
    """The core's own states, taken every 15 frames of 900 of random play from our cartridge's first state (a legal
    state is never refused, wherever in a frame's work the core stands when it is saved)."""
    import random

    from retrokit.data.games import find_game
    from retrokit.data.statecheck import load_state
    from retrokit.host.emulator import Emulator

    game = find_game(FUZZES[system].game if system in FUZZES else "Trekker-GbColor")
    emulator = Emulator(system, game.require_rom())
    try:
        emulator.set_state(load_state(game, game.state_path()))
        rng = random.Random(7)
        refused = []
        for step in range(60):
            emulator.run([rng.getrandbits(12) for _ in range(emulator.ports)], 15)
            if problem := state_layout_problem(system, bytes(emulator.get_state())):
                refused.append((step, problem))
    finally:
        emulator.close()
    assert not refused, refused


def test_a_memory_map_that_sends_the_pce_program_astray_is_left_to_the_probe(tmp_path: Path, monkeypatch) -> None:
    """Each MPR byte is legal, the map as a whole is not (the raw core dies at the same frame every run): no layout
    can tell, so the probe, playing it in a child first, refuses it."""
    from retrokit.data.statecheck import vet_state
    from retrokit.errors import StateError

    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))  # no verdict of an earlier run
    game = REPO / "games" / "Skipper-PCEngine"
    good = read_state(game / "Level1.state")
    (at,) = [at for name, at, _ in (mednafen_sections(good) or {})[b"CPU"] if name == b"MPR"]
    astray = good[:at] + bytes([0x40, 0, 0, 0, 0, 0, 0, 0]) + good[at + 8 :]
    assert state_layout_problem("PCEngine", astray) == ""
    with pytest.raises(StateError, match="the PCEngine core can run; found one that it cannot"):
        vet_state(astray, "PCEngine", game / "rom.pce")


def test_a_super_fx_plot_mode_or_pointer_past_its_memory_is_refused() -> None:
    """Yoshi's Island's wheel state (the one Super FX state shipped): its plot mode picks the function the core
    calls from a table, its pointers are offsets the core adds to its own bases; no ROM here runs one, so the rule
    is shown on the layout alone."""
    from retrokit.host.sneslayout import SFX_MODE, SFX_REGISTER_POINTERS

    files = [p for kind in paths.wheel_data_dirs() for p in kind.glob("SuperMarioWorld2-Snes-v0/Start.state")]
    if not files:
        pytest.skip("the wheel's Yoshi's Island state is not installed")
    good = read_state(files[0])
    sfx = good.index(snes9x_blocks(good)[b"SFX"])

    def with_word(offset: int, value: int) -> bytes:
        return good[: sfx + offset] + value.to_bytes(4, "big") + good[sfx + offset + 4 :]

    assert state_layout_problem("Snes", good) == ""
    assert "SFX plot mode 7" in state_layout_problem("Snes", with_word(SFX_MODE, 7))
    assert "SFX register pointers" in state_layout_problem("Snes", with_word(SFX_REGISTER_POINTERS[0], 0x7FFF0000))
