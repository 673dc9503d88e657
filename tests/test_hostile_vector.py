"""make_vec(...).close() frees its emulators at once, not at the next garbage collection."""

from __future__ import annotations

import pytest
from childproc import run_child

CYCLES = """
import gc, weakref
import retrokit

def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20

gc.disable()  # what close() frees must not wait for the collector
alive, base = [], None
for cycle in range({cycles}):
    vec = retrokit.make_vec("Dasher-Genesis", 2, {options})
    vec.reset(seed=0)
    vec.step(vec.action_space.sample())
    alive += [weakref.ref(vec)] + [weakref.ref(env) for env in vec.envs]
    vec.close()
    del vec
    if cycle == 4:
        base = rss_mb()
print("alive", sum(ref() is not None for ref in alive))
print("growth", rss_mb() - base)
"""


@pytest.mark.parametrize("options", ["", "obs_type='ram'"], ids=["rgb", "ram"])
def test_make_vec_close_frees_everything_without_gc(options: str) -> None:
    child = run_child(CYCLES.format(cycles=15, options=options), timeout=120)
    assert child.returncode == 0, child.describe()
    lines = dict(line.split() for line in child.stdout.splitlines())
    assert int(lines["alive"]) == 0, child.describe()
    assert float(lines["growth"]) < 20, child.describe()  # a leaked cycle held about 3.4 MB per cycle
