"""Shared fixtures: the free ROMs that every test machine has.

Airstriker-Genesis ships in the stable-retro wheel with its ROM and a Level1
state; Dasher-Genesis is our own test cartridge (games/Dasher-Genesis).
"""

from __future__ import annotations

import gzip
import json
import os
import signal
import sys
from pathlib import Path

import pytest
import suiteorder

from retrokit.paths import wheel_dir

REPO = Path(__file__).resolve().parent.parent

# Compiled bytecode, kept: where PYTHONDONTWRITEBYTECODE is set (it is on the developers' VMs), every test
# process and every child a test starts (a level worker, the state probe, a CLI) compiled retrokit's modules from
# source again, and pytest rewrote every test module's asserts again (about 0.15 CPU-s a child, 10 a worker). The
# files go into the checkout's pytest cache folder (ignored by git), not beside the sources, so the tree is as
# clean as before; the children find the folder through the environment they inherit.
_PYCACHE = REPO / ".pytest_cache" / "pycache"
sys.dont_write_bytecode = False
sys.pycache_prefix = str(_PYCACHE)
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
os.environ["PYTHONPYCACHEPREFIX"] = str(_PYCACHE)

# Ctrl-C as a user presses it: a shell without job control (a script's `cmd &`, some CI runners) starts background
# jobs with SIGINT ignored, and an ignored signal stays ignored across exec, so every child a test starts (an
# evaluation, a studio) would shrug off the SIGINT the Ctrl-C tests send. Python leaves an ignored SIGINT alone at
# startup, so it is put back here; children then start with the default, as under a terminal.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """`-n auto`: one worker more than the cores this process may use.

    Many tests wait: on a child process's start, a browser's page, Ray's start-up, a stall timeout. With one worker
    per core those waits leave a core idle; a third worker on 2 cores fills them (a quiet full run on 2 cores: 615 s
    with 3 workers against 665 s with 2). Every wait is on a condition with a generous limit, so a busier core only
    makes a test slower, never wrong.
    """
    from retrokit.envs.vector import available_cpus

    return available_cpus() + 1


def pytest_configure(config: pytest.Config) -> None:
    suiteorder.configure(config)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The longest files first (tests/suiteorder.py says why)."""
    items[:] = suiteorder.longest_first(items)

@pytest.fixture(scope="session")
def airstriker_dir() -> Path:
    """The wheel's Airstriker integration folder."""
    root = wheel_dir()
    assert root is not None, "the stable-retro wheel is a dependency of retrokit and must be installed"
    return root / "data" / "stable" / "Airstriker-Genesis-v0"


@pytest.fixture(scope="session")
def airstriker_rom(airstriker_dir: Path) -> Path:
    return airstriker_dir / "rom.md"


@pytest.fixture(scope="session")
def airstriker_state(airstriker_dir: Path) -> bytes:
    """Airstriker's Level1 state, uncompressed, checked (the wheel ships it: no probe) so an emulator loads it."""
    from retrokit.data.statecheck import vet_state

    path = airstriker_dir / "Level1.state"
    return vet_state(gzip.decompress(path.read_bytes()), "Genesis", airstriker_dir / "rom.md", shipped=path)


@pytest.fixture(scope="session")
def airstriker_fields(airstriker_dir: Path) -> dict[str, dict]:
    """Airstriker's RAM fields as stable-retro's data.json gives them."""
    return json.loads((airstriker_dir / "data.json").read_text())["info"]


@pytest.fixture
def airstriker(airstriker_rom: Path, airstriker_state: bytes):
    """A Genesis emulator at the start of Airstriker's Level1."""
    from retrokit.host.emulator import Emulator

    emu = Emulator("Genesis", airstriker_rom)
    emu.set_state(airstriker_state)
    yield emu
    emu.close()


@pytest.fixture(scope="session")
def dasher_rom() -> Path:
    """Dasher, our own test cartridge (built from tools/testcart, committed as a free ROM)."""
    return REPO / "games" / "Dasher-Genesis" / "rom.md"


@pytest.fixture(scope="session")
def good_state(dasher_rom: Path) -> bytes:
    """Dasher's Zone1.Act1 state, uncompressed."""
    from retrokit.data.states import read_state

    return read_state(dasher_rom.parent / "Zone1.Act1.state")


@pytest.fixture(scope="session")
def corrupt_state(good_state: bytes) -> bytes:
    """The right size and a valid header (GENPLUS-GX 1.7.5), then random bytes: it crashes the core.

    The real state's pointer bytes are kept (tests/corrupt.py), so only the probe can tell.
    """
    import random

    from corrupt import random_body

    # Seed 6: with the bytes statelayout reads kept real (bank map, Z80 bank, VDP FIFO index), the body of
    # seeds 1 to 5 happens to run; this one crashes the core in the probe's run.
    return random_body(good_state, random.Random(6), keep_pointers=True)


@pytest.fixture(scope="module")
def studio_game(tmp_path_factory) -> Path:
    """A copy of Dasher's folder for one test module's studio to write its states and movies into."""
    import shutil

    folder = tmp_path_factory.mktemp("studio") / "Dasher-Genesis"
    shutil.copytree(REPO / "games" / "Dasher-Genesis", folder)
    return folder


@pytest.fixture(scope="module")
def studio_session(studio_game: Path):
    """A studio session on that copy at Zone1.Act1, its emulator thread stopping 0.5 s after the last page."""
    from retrokit.studio.session import Session

    session = Session(str(studio_game), "Zone1.Act1", grace=0.5)
    yield session
    session.close()


@pytest.fixture(scope="session")
def wheel() -> Path:
    """The stable-retro wheel's own Genesis Plus GX, which the patched build is compared against."""
    from retrokit.host.cores import wheel_core

    path = wheel_core("genesis_plus_gx")
    assert path is not None, "the stable-retro wheel ships genesis_plus_gx"
    return path


@pytest.fixture(scope="session")
def chromium_session():
    """One headless Chromium for all the browser tests this process runs (skipped where Chromium is missing)."""
    from chromium import chrome  # importing it skips the test where Chromium is not installed

    with chrome() as driver:
        yield driver


@pytest.fixture
def browser(chromium_session):
    """That Chromium, as fresh for this test as a new one: a blank page, no cookies, no alert, no console log."""
    from chromium import fresh

    return fresh(chromium_session)
