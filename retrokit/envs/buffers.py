"""Reusing the arrays a step hands out, without ever overwriting one still in use.

A fresh 200 KiB observation every step costs page faults worth a sixth of a
Genesis step when the last one was just freed (the allocator hands such
sizes back to the system at once), and a vector step's handful of small
arrays costs more than its emulation's share when numpy's code is cold in
the caches after the frames. So a step's arrays come from a pool, and a set
of them is handed out again only when its reference counts show that
nobody outside the pool holds any of them, or a view of one.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import Generic, TypeVar

import numpy as np

T = TypeVar("T", bound="Tracked")


class Tracked:
    """Arrays handed to callers, and their reference counts when no caller holds one.

    Args:
        arrays: Every array a caller may get, or get a view of (a view of a
            view refers to the array that owns the memory, so list that too).
    """

    def __init__(self, arrays: Sequence[np.ndarray]) -> None:
        self.arrays = list(arrays)
        self.idle: list[int] | None = None

    def counts(self) -> list[int]:
        return [sys.getrefcount(a) for a in self.arrays]

    def free(self) -> bool:
        """Whether nobody outside the pool holds any of the arrays."""
        return self.counts() == self.idle


class Pool(Generic[T]):
    """Items of tracked arrays, reused once nobody else holds them.

    Args:
        make: Makes a new item.
        size: How many items the pool keeps; past that, new ones are not kept.
    """

    def __init__(self, make: Callable[[], T], size: int = 4) -> None:
        self.make, self.size = make, size
        self.items: list[T] = []

    def take(self) -> T:
        """Return an item none of whose arrays anybody outside the pool refers to."""
        for item in self.items:
            if item.free():
                return item
        item = self.make()
        if len(self.items) < self.size:
            self.items.append(item)
            # Counted here, where nothing but the item and the pool's list refer to its arrays.
            item.idle = item.counts()
        return item


class Batch(Tracked):
    """One observation array, and a view of each of its rows (for a batch of envs)."""

    def __init__(self, shape: tuple[int, ...], dtype: type) -> None:
        self.array = np.empty(shape, dtype=dtype)
        self.rows = list(self.array) if self.array.ndim > 1 else []
        super().__init__([self.array])


class BufferPool:
    """Observation arrays, reused once nobody else holds them (or a view of them).

    Args:
        shape: Each array's shape.
        dtype: Each array's type.
        size: How many arrays the pool keeps.
    """

    def __init__(self, shape: tuple[int, ...], dtype: type = np.uint8, size: int = 4) -> None:
        self.shape, self.dtype = shape, dtype
        self._pool: Pool[Batch] = Pool(lambda: Batch(shape, dtype), size)

    def take(self) -> np.ndarray:
        """Return an array of the pool's shape that nothing outside the pool refers to."""
        return self._pool.take().array

    def take_rows(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """Like :meth:`take`, with a view of each row of the array, made once per array."""
        batch = self._pool.take()
        return batch.array, batch.rows


class StepArrays(Tracked):
    """A vector step's small arrays: rewards, terminations, truncations, and its info.

    The info is Gymnasium's batched form for envs whose info is exactly their
    integer fields: a column per field, and a ``_field`` mask that says every
    env has it. Env ``i``'s fields are copied into ``rows[i]``.

    Args:
        num_envs: The number of envs.
        keys: The fields' names.
    """

    def __init__(self, num_envs: int, keys: Sequence[str]) -> None:
        self.rewards = np.zeros(num_envs, dtype=np.float64)
        self.terminations = np.zeros(num_envs, dtype=np.bool_)
        self.truncations = np.zeros(num_envs, dtype=np.bool_)
        self.fields = np.zeros((num_envs, len(keys)), dtype=np.int64)
        self.masks = np.ones((len(keys), num_envs), dtype=np.bool_)
        self.rows = [memoryview(row) for row in self.fields]
        columns = [self.fields[:, j] for j in range(len(keys))]
        mask_rows = list(self.masks)
        self.info = dict(zip(keys, columns)) | dict(zip((f"_{key}" for key in keys), mask_rows))
        # Plain memoryviews write single items without a trip through numpy.
        self.flags = (memoryview(self.rewards), memoryview(self.terminations), memoryview(self.truncations))
        # No fields (info_keys=[]): nothing to refill, and a memoryview of no items cannot be cast.
        self._all_masks = memoryview(self.masks).cast("B") if self.masks.size else None
        self._ones = b"\x01" * self.masks.size
        super().__init__([self.rewards, self.terminations, self.truncations, self.fields, self.masks, *columns, *mask_rows])

    def refill_masks(self) -> None:
        """Set every mask back to True, in case a caller changed one before letting go."""
        if self._all_masks is not None:
            self._all_masks[:] = self._ones
