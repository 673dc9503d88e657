"""The order the suite's files start in: the longest first, so the run does not end on one long file alone.

pytest-xdist (``--dist loadfile``) hands each worker whole files, in the order it is given them; by default it
sorts them by their number of tests, which put the browser, Ray and evaluation files (few tests, long waits) all
in the last minutes, where they left the cores idle half the time. Started longest first (the longest-processing-
time rule), the files that wait on a child, a browser or a stall timeout run beside the ones that emulate, and the
last minutes are many short files that spread over every worker.

``SECONDS`` is each heavy file's time, its tests' wall time summed, from two quiet full runs on 2 cores (3 workers,
2026-11-28, after the day's cuts). It is a hint for the order only: a test passes or fails alike in any order (each has its own
tmp_path and data folder). A file not listed starts after the listed ones, in collection order; refresh the
table when a file's time changes much.
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest

SECONDS = {
    "test_systems": 79, "test_evaluate": 70, "test_atari": 58, "test_validate": 49, "test_systems_studio": 47,
    "test_evaluate_hostile": 47, "test_evaluate_ray": 46, "test_studio_browser": 41,
    "test_studio_browser_panels": 32, "test_video_skip": 32, "test_walkthrough": 31, "test_state_fuzz": 31,
    "test_sound_skip": 25, "test_cartridges": 24, "test_hostile_game_folders": 24, "test_ramsearch_cli": 23,
    "test_studio_browser_guard": 20, "test_trust": 20, "test_evaluate_compare": 20, "test_recording_safety": 15,
    "test_host": 13, "test_hostile_movies": 12, "test_studio_ctrl_c": 12, "test_build_core_hostile": 11,
    "test_preprocessing": 11, "test_pcecart": 10, "test_retro_scripts": 37, "test_retro_face": 14,
}  # fmt: skip


def longest_first(items: Sequence[pytest.Item]) -> list[pytest.Item]:
    """``items`` with the listed files' tests first, longest file first; each file's tests in their own order."""
    return sorted(items, key=lambda item: -SECONDS.get(item.path.stem, 0))  # stable: ties keep collection order


def configure(config: pytest.Config) -> None:
    """Tell xdist to keep the order it is given (it sorts files by their number of tests otherwise)."""
    if getattr(config.option, "loadscopereorder", None) is not None:
        config.option.loadscopereorder = False
