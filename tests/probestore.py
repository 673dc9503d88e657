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
