"""A store of state-probe verdicts shared by the tests of one module.

Tests that point ``RETROKIT_DATA`` at a fresh folder would re-probe the same states (one
``python -m retrokit.data.probe`` child, ~1 CPU-s, each) in every test. Verdicts are keyed by the
SHA-256 of the state, system and ROM, so a verdict one test earned holds for the next one, exactly
as on a user's machine that probed the state before. Tests that are ABOUT probing keep a bare folder.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

DASHER = Path(__file__).resolve().parent.parent / "games" / "Dasher-Genesis"


@contextmanager
def shared_verdicts(store: Path, data: Path) -> Iterator[Path]:
    """Seed ``data``'s verdicts from ``store`` for the test's run, then keep the ones it earned.

    Args:
        store: The module's verdict folder (stays outside every test's data folder).
        data: The test's data folder (``RETROKIT_DATA``).

    Yields:
        ``data``.
    """
    probes = data / "state-probes"
    shutil.copytree(store, probes, dirs_exist_ok=True)
    yield data
    for verdict in probes.glob("*") if probes.is_dir() else ():
        # finished verdicts only, never a writer's leftover temp file (".<name>.*.tmp")
        if verdict.is_file() and not verdict.name.startswith(".") and not (store / verdict.name).exists():
            shutil.copy(verdict, store / verdict.name)


def seed_shipped(store: Path, game: Path = DASHER, state: str = "Zone1.Act1") -> Path:
    """Seed ``store`` as a machine that once loaded ``game``'s shipped ``state`` on its ROM knows it, and return it.

    A shipped state needs no probe and is then known by its bytes, so the same state in another file (re-gzipped,
    or a movie's Core.bin) is not probed again.
    """
    import pytest

    from retrokit.data.games import find_game
    from retrokit.data.statecheck import vet_state
    from retrokit.data.states import read_state

    seed = store / ".seed"
    found = find_game(game)
    state_file = found.state_path(state)
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RETROKIT_DATA", str(seed))
        vet_state(read_state(state_file), found.system.name, found.rom_path(), shipped=state_file)
    for verdict in (seed / "state-probes").glob("*"):
        shutil.copy(verdict, store / verdict.name)
    shutil.rmtree(seed)
    return store
