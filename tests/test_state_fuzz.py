"""Corrupt states behind a real state's valid header: none kills the process that loads it.

Each state is Dasher's Zone1.Act1 with its header kept and a random body
(the fuzz of issue 24, where 3 of 120 passed the first probe). Each goes through the
public API: ``retrokit.make(game, path)``, then 3,000 frames with random
input and a reset every 500. Two fuzzes:

- the issue's: the whole body random. Its random cartridge memory map points
  banks past the core's ROM area, which crashes the core or not by the process's
  memory layout (one such state passed the probe and killed an env at reset()
  about one run in two), and so does a random Z80 bank address:
  :mod:`retrokit.host.statelayout` refuses every one, before any probe;
- a harder one: the same, with the real state's memory map and Z80 bank kept
  (tests/corrupt.py), so the probe
  (:mod:`retrokit.data.probe`) decides: it must refuse every state that would
  crash the core, and the ones it passes must play.

The probes run first, two at a time, each in its own child, through
``statecheck.load_state`` (their verdicts are cached, so ``make`` reads them);
the play of both fuzzes runs in one child process, so a state the probe missed
fails this test instead of killing the suite. The states play on a copy of Dasher without
its fields' ranges, which would refuse nearly every random body at ``make``
before it ever plays.

24 states of each run always (about a quarter of the harder ones pass the probe and play);
the issue's full 120 with ``RETROKIT_FUZZ_STATES=120``.
"""

from __future__ import annotations

import json
import os
import random
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import yaml
from childproc import MAX_RSS_MB, REPO, Child, run_child
from corrupt import random_body

from retrokit.data.states import compress_state, read_state

DASHER = REPO / "games" / "Dasher-Genesis"
COUNT = int(os.environ.get("RETROKIT_FUZZ_STATES", "24"))

PLAY = """
import json
import numpy as np
import retrokit
from retrokit.errors import StateError

counts = {}
for kind, paths in json.load(open(STATES)).items():
    played = refused = 0
    for path in paths:
        try:
            env = retrokit.make(GAME, path, obs_type="ram", frameskip=4)
        except StateError:
            refused += 1
            continue
        rng = np.random.default_rng(0)
        env.reset(seed=0)
        for step in range(750):  # 3,000 frames
            env.step(rng.integers(0, 2, env.action_space.shape))
            if step % 125 == 124:
                env.reset()  # every reset loads the state again
        env.close()
        played += 1
    counts[kind] = {"played": played, "refused": refused}
print(json.dumps(counts))
"""


def corrupt_states(good: bytes, count: int, *, keep_pointers: bool) -> list[bytes]:
    """Copies of ``good`` with its header and a random body (and its pointer bytes, with ``keep_pointers``)."""
    rng = random.Random(2024)
    return [random_body(good, rng, keep_pointers=keep_pointers) for _ in range(count)]


def unranged_dasher(folder: Path) -> Path:
    """A copy of Dasher's integration whose fields declare no ranges, so make() lets a random body play."""
    game = folder / "Dasher-Genesis"
    game.mkdir()
    for name in ("rom.md", "scenario.yaml", "Zone1.Act1.state"):
        (game / name).write_bytes((DASHER / name).read_bytes())
    data = yaml.safe_load((DASHER / "game.yaml").read_text())
    for spec in data["fields"].values():
        spec.pop("range", None)
    (game / "game.yaml").write_text(yaml.safe_dump(data))
    return game


#: Each fuzz, and whether its states keep the real state's memory map and Z80 bank.
KINDS = {"random-body": False, "random-body-real-pointers": True}


@pytest.fixture(scope="module")
def fuzzed(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, list[bool]], Child]:
    """Each fuzz's states probed (whether each passed), then all played in ONE child (a child each was a second
    interpreter start and import, for a fuzz whose states are all refused before any probe).

    Returns:
        Whether each state of each fuzz passed the probe, and the play child (its last line: each fuzz's counts).
    """
    from retrokit.data.games import find_game
    from retrokit.data.statecheck import load_state
    from retrokit.errors import StateError

    root = tmp_path_factory.mktemp("fuzz")
    data = root / "data"
    folder = unranged_dasher(root)
    good = read_state(DASHER / "Zone1.Act1.state")
    files: dict[str, list[str]] = {}
    for kind, keep_pointers in KINDS.items():
        files[kind] = []
        for i, state in enumerate(corrupt_states(good, COUNT, keep_pointers=keep_pointers)):
            path = root / f"{kind}-{i:03d}.state"
            path.write_bytes(compress_state(state))
            files[kind].append(str(path))

    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RETROKIT_DATA", str(data))
        game = find_game(folder)

        def probe(path: str) -> bool:
            try:
                load_state(game, path)
            except StateError:
                return False
            return True

        passed = {}
        for kind in KINDS:
            began = time.monotonic()
            with ThreadPoolExecutor(2) as pool:
                passed[kind] = list(pool.map(probe, files[kind]))
            print(f"{kind}: probing {COUNT} states took {time.monotonic() - began:.0f} s")

    (root / "states.json").write_text(json.dumps(files))
    code = f"STATES = {str(root / 'states.json')!r}\nGAME = {str(folder)!r}\n" + PLAY
    return passed, run_child(code, env={"RETROKIT_DATA": str(data)}, timeout=600)


@pytest.mark.timeout(120 + 20 * COUNT)  # a probe takes a few seconds a state on a busy machine (both fuzzes: the fixture)
@pytest.mark.parametrize("kind", list(KINDS))
def test_corrupt_states_never_kill_the_process(fuzzed, kind: str) -> None:
    probed, child = fuzzed
    passed = probed[kind]
    assert len(passed) == COUNT
    if KINDS[kind]:
        assert not all(passed) and any(passed)  # the probe decides, and the fuzz makes both kinds
    else:
        assert not any(passed)  # every random memory map points outside the ROM area

    assert child.signal is None and child.returncode == 0, child.describe()
    counts = json.loads(child.stdout.strip().splitlines()[-1])[kind]
    assert counts == {"played": sum(passed), "refused": COUNT - sum(passed)}, child.describe()
    assert child.peak_rss_mb < MAX_RSS_MB, child.describe()
    print(f"{COUNT} states: {sum(passed)} played, {COUNT - sum(passed)} refused")
