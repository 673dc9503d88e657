"""Pooled arrays are reused only when nobody else holds them, or a view of them."""

from __future__ import annotations

import numpy as np
import pytest

import retrokit
from retrokit.envs.buffers import BufferPool, Pool, StepArrays

KEYS = ("score", "lives")


def test_buffer_is_reused_once_dropped() -> None:
    pool = BufferPool((4, 3))
    first = pool.take()
    address = first.ctypes.data
    del first
    assert pool.take().ctypes.data == address


@pytest.mark.parametrize(
    "keep",
    [lambda a: a, lambda a: a[1:], lambda a: a[1:][1:], lambda a: a.reshape(-1), lambda a: memoryview(a)],
    ids=["array", "view", "view-of-view", "reshaped", "memoryview"],
)
def test_buffer_is_not_reused_while_anything_refers_to_it(keep) -> None:
    pool = BufferPool((4, 3))
    array, rows = pool.take_rows()
    held = keep(array)
    del array, rows
    assert pool.take() is not held and not np.shares_memory(pool.take(), np.asarray(held))


def test_buffer_rows_are_views_of_their_array() -> None:
    array, rows = BufferPool((2, 4, 3)).take_rows()
    rows[1][:] = 7
    assert (array[1] == 7).all()
    assert all(np.shares_memory(row, array) for row in rows)


def step_parts(arrays: StepArrays) -> dict[str, object]:
    info = dict(arrays.info)
    return {
        "rewards": arrays.rewards,
        "terminations": arrays.terminations,
        "truncations": arrays.truncations,
        "column": info["score"],
        "view-of-column": info["lives"][:1],
        "mask": info["_score"],
    }


def test_step_arrays_are_reused_once_dropped() -> None:
    pool = Pool(lambda: StepArrays(2, KEYS))
    first = pool.take()
    parts = step_parts(first)
    del parts
    assert pool.take() is first


@pytest.mark.parametrize("part", list(step_parts(StepArrays(2, KEYS))))
def test_step_arrays_are_not_reused_while_a_part_is_held(part: str) -> None:
    pool = Pool(lambda: StepArrays(2, KEYS))
    first = pool.take()
    held = step_parts(first)[part]
    assert pool.take() is not first
    del held
    assert pool.take() is first


def test_a_full_pool_hands_out_unkept_arrays() -> None:
    pool = Pool(lambda: StepArrays(1, KEYS), size=2)
    kept = [pool.take().rewards for _ in range(3)]
    assert len(pool.items) == 2 and len({id(a) for a in kept}) == 3


def test_refill_sets_every_mask_back() -> None:
    arrays = StepArrays(3, KEYS)
    arrays.masks[:] = False
    arrays.refill_masks()
    assert arrays.masks.all()


def test_vector_results_kept_by_the_caller_never_change() -> None:
    vec = retrokit.make_vec("Airstriker-Genesis", 2, frameskip=4, max_episode_steps=6)
    vec.reset(seed=0)
    rng = np.random.default_rng(0)
    kept = []
    for _ in range(20):
        result = vec.step(rng.integers(0, 2, (2, 12)).astype(np.int8))
        kept.append((result, [np.copy(a) for a in result[:4]], {k: np.copy(v) for k, v in result[4].items()}))
    for result, arrays, info in kept:
        assert all((a == b).all() for a, b in zip(result[:4], arrays))
        assert result[4].keys() == info.keys() and all((result[4][k] == v).all() for k, v in info.items())
    assert any(result[2].any() or result[3].any() for result, _, _ in kept)  # episodes ended along the way
    vec.close()


def test_vector_masks_changed_by_a_caller_do_not_leak_into_later_steps() -> None:
    vec = retrokit.make_vec("Airstriker-Genesis", 2, frameskip=4)
    vec.reset(seed=0)
    action = np.zeros((2, 12), dtype=np.int8)
    for _ in range(6):
        infos = vec.step(action)[4]
        assert all(infos[f"_{key}"].all() for key in ("score", "lives", "gameover"))
        infos["_score"][:] = False
        del infos
    vec.close()
