"""The native host refuses bad input in one clear error: unchecked states, bad actions and buffers, no core."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from retrokit.data.statecheck import vet_state
from retrokit.errors import (
    CoreError,
    CoreNotFoundError,
    InvalidArgumentError,
    RetrokitError,
    StateError,
)
from retrokit.host.emulator import Emulator
from retrokit.native import _host


def test_truncated_state_is_a_clear_error(airstriker_rom: Path, airstriker_state: bytes) -> None:
    with pytest.raises(StateError, match=rf"expected a state of {len(airstriker_state)} bytes.*got 1000 bytes.*truncated"):
        vet_state(airstriker_state[:1000], "Genesis", airstriker_rom)  # the probe's child says what the core refused


def test_corrupt_state_of_the_right_size_is_refused(airstriker_rom: Path, airstriker_state: bytes) -> None:
    with pytest.raises(StateError, match="refused the state"):
        vet_state(b"\xff" * len(airstriker_state), "Genesis", airstriker_rom)


@pytest.mark.parametrize(
    "state", [None, b"", "a string", bytearray(8)], ids=["none", "empty-bytes", "string", "bytearray"]
)
def test_set_state_takes_only_a_checked_state(airstriker: Emulator, state: object) -> None:
    with pytest.raises(StateError, match="Expected a checked state .* found (None|bytes|str|bytearray)"):
        airstriker.set_state(state)  # type: ignore[arg-type]


def test_a_checked_state_cannot_be_made_directly(airstriker_state: bytes) -> None:
    from retrokit.host.emulator import VettedState, claim_mint

    with pytest.raises(StateError, match="made directly as VettedState"):
        VettedState(bytes(airstriker_state), "Genesis")
    with pytest.raises(RetrokitError, match="claimed already"):
        claim_mint()  # retrokit.data.probe holds it


def test_a_slice_or_a_pickle_of_a_checked_state_is_unchecked(airstriker: Emulator, airstriker_state: bytes) -> None:
    import pickle

    for copy in (airstriker_state[:], pickle.loads(pickle.dumps(airstriker_state)), bytes(airstriker_state)):
        assert copy == airstriker_state
        with pytest.raises(StateError, match="Expected a checked state"):
            airstriker.set_state(copy)


def test_wrong_screen_buffer_says_what_shape_it_needs(airstriker: Emulator) -> None:
    airstriker.run(0, 1)
    with pytest.raises(InvalidArgumentError, match=r"shape \(224, 320, 3\)"):
        airstriker.screen(np.zeros((224, 320, 4), dtype=np.uint8))
    with pytest.raises(InvalidArgumentError, match="uint8"):
        airstriker.screen(np.zeros((224, 320, 3), dtype=np.float32))


@pytest.mark.parametrize(
    "actions,message",
    [([0, 0, 0], "at most 2 button masks"), ([-1], "from 0 to 0xFFFF"), ([0x10000], "from 0 to 0xFFFF")],
    ids=["too-many-ports", "negative", "too-large"],
)
def test_bad_actions_are_refused(airstriker: Emulator, actions: list[int], message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        airstriker.run(actions, 1)


def test_bad_sticky_probability_is_refused(airstriker: Emulator) -> None:
    with pytest.raises(InvalidArgumentError, match=r"in \[0, 1\], got 1.5"):
        airstriker.set_sticky(1.5, 0)


def test_native_run_checks_its_arguments_before_the_core(airstriker: Emulator) -> None:
    raw = airstriker.handle
    with pytest.raises(InvalidArgumentError, match="uint16"):
        raw.run(np.zeros(2, dtype=np.int32), 1)
    with pytest.raises(InvalidArgumentError, match="frames must be 0 or more"):
        raw.run(np.zeros(2, dtype=np.uint16), -1)


def test_closed_emulator_raises_and_live_views_stay_valid(airstriker_rom: Path) -> None:
    emu = Emulator("Genesis", airstriker_rom)
    emu.run(0, 10)
    ram = emu.ram
    before = ram.copy()
    emu.close()
    assert (ram == before).all()  # the view kept the core loaded
    with pytest.raises(CoreError, match="closed"):
        emu.run(0, 1)


def test_a_library_that_is_not_a_core_is_refused(airstriker_rom: Path) -> None:
    with pytest.raises(CoreError, match="not a libretro core: it has no retro_init"):
        Emulator("Genesis", airstriker_rom, core_path=_host.__file__)


def test_missing_core_says_where_it_looked(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from retrokit.host import cores

    monkeypatch.setattr(cores, "wheel_cores_dir", lambda: None)
    monkeypatch.setattr(cores, "_DEBIAN_DIRS", ())
    monkeypatch.setenv("RETROKIT_CORES", str(tmp_path))
    monkeypatch.setenv("RETROKIT_DATA", str(tmp_path / "data"))  # no core built by retrokit build-core either
    with pytest.raises(CoreNotFoundError, match=rf"genesis_plus_gx_libretro.so in one of: {tmp_path}, {tmp_path}/data/cores.*RETROKIT_CORES"):
        cores.find_core("genesis_plus_gx")


def test_missing_rom_file_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(InvalidArgumentError, match="Expected a ROM file, found nothing"):
        Emulator("Genesis", tmp_path / "nothing.md")


def test_a_packed_state_unpacks_checked_and_cannot_be_made_directly(airstriker: Emulator) -> None:
    from retrokit.host.emulator import PackedState

    state = airstriker.get_state()
    packed = state.pack()
    assert len(packed) < len(state) and packed.unpack() == state
    airstriker.set_state(packed.unpack())
    with pytest.raises(StateError, match="made directly as PackedState"):
        PackedState(b"x", "Genesis")


def test_memory_span_refuses_descriptors_the_core_lacks_and_joins_only_what_follows() -> None:
    from retrokit.data.games import find_game

    game = find_game("Hopper-Nes")
    with Emulator(game.system, game.require_rom()) as emu:
        native = emu.handle
        count = len(native.memory_maps())  # FCEUmm's: 0x0, 0x400, then 0x6000 to 0x7C00, 1 KiB each
        for first, many in [(-1, 1), (0, 0), (0, count + 1), (count, 1), (0, 2**31 - 1), (2**31 - 1, 2)]:
            with pytest.raises(InvalidArgumentError, match="expected descriptors within the core's"):
                native.memory_span(first, many)
        with pytest.raises(TypeError):
            native.memory_span("0", 1)
        assert len(native.memory_span(0, 2)) == 2048  # the NES's RAM: one array
        assert native.memory_span(1, 2) is None  # 0x400 then 0x6000: not adjacent addresses
        view = native.memory_span(0, 1)
        assert len(view) == 1024
        view.release()
