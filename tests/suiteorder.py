"""The order the suite's files start in: the longest first, so the run does not end on one long file alone.

pytest-xdist (``--dist loadfile``) hands each worker whole files, in the order it is given them; by default it
sorts them by their number of tests, which put the browser, Ray and evaluation files (few tests, long waits) all
in the last minutes, where they left the cores idle half the time. Started longest first (the longest-processing-
time rule), the files that wait on a child, a browser or a stall timeout run beside the ones that emulate, and the
last minutes are many short files that spread over every worker.

``SECONDS`` is each heavy file's time, its tests' wall time summed, from a quiet full run on 2 cores (3 workers,
2026-11-28). It is a hint for the order only: a test passes or fails alike in any order (each has its own
tmp_path and data folder). A file not listed starts after the listed ones, in collection order; refresh the
table when a file's time changes much.
"""

from __future__ import annotations

from collections.abc import Sequence

import pytest

SECONDS = {
    "test_systems": 134, "test_evaluate_ray": 81, "test_systems_studio": 78, "test_atari": 74, "test_evaluate": 71,
    "test_video_skip": 65, "test_sound_skip": 62, "test_validate": 56, "test_evaluate_hostile": 52,
    "test_studio_browser": 50, "test_walkthrough": 43, "test_preprocessing": 42, "test_studio_browser_panels": 41,
    "test_host": 34, "test_hostile_game_folders": 33, "test_other_games_state": 33, "test_evaluate_compare": 31,
    "test_ramsearch_cli": 30, "test_state_fuzz": 29, "test_studio_browser_guard": 29, "test_trust": 25,
    "test_cartridges": 24, "test_hostile_movies": 23, "test_recording_safety": 22, "test_cli_pipes": 22,
    "test_concurrent_writers": 21, "test_hostile_states": 17, "test_dotted_paths": 17, "test_runner_load": 16,
    "test_demo": 15, "test_studio_ctrl_c": 13, "test_build_core_hostile": 12, "test_stable_retro_parity": 12,
    "test_pcecart": 12, "test_ramsearch_loop": 12, "test_import": 12, "test_dsl_fuzz": 12, "test_field_ranges": 12,
    "test_vector": 12, "test_evaluate_speed": 11, "test_lua_scenarios": 11, "test_docs": 11,
}  # fmt: skip


def longest_first(items: Sequence[pytest.Item]) -> list[pytest.Item]:
    """``items`` with the listed files' tests first, longest file first; each file's tests in their own order."""
    return sorted(items, key=lambda item: -SECONDS.get(item.path.stem, 0))  # stable: ties keep collection order


def configure(config: pytest.Config) -> None:
    """Tell xdist to keep the order it is given (it sorts files by their number of tests otherwise)."""
    if getattr(config.option, "loadscopereorder", None) is not None:
        config.option.loadscopereorder = False
