"""The native runner beside a process that keeps a CPU busy: a worker stalled behind it is moved, results unchanged.

The vector env's worker threads are kept off the caller's CPU. When another
process shares the worker's CPU, the scheduler takes it from the worker in
the middle of a step while the caller, its own envs done, only waits; the
caller then moves the worker onto its own CPU. Here the caller is pinned to
one CPU and a burner to the other, where the worker is kept, so the worker
is sure to stall; the test checks that the runner moved it, and that every
observation and reward still equals a single env's.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

CPUS = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []

CHILD = textwrap.dedent(
    """
    import json, os, subprocess, sys
    import numpy as np
    import retrokit

    caller_cpu, busy_cpu, n, one_cpu = (int(a) for a in sys.argv[1:])
    options = {"frameskip": 4, "sticky_prob": 0.25, "action_type": "discrete"}
    # The burner runs as long as the child: stop 40 steps after the first move (moves come within some 30
    # steps on a quiet machine), or after 3,000 steps with none (episodes end from step 343 on: the envs reset as
    # the vector's do, and the comparison goes on). With every CPU busy besides (a CPU hog on each core, and the
    # rest of the suite), the caller is descheduled too and may miss stalls for hundreds of steps.
    # Confined to one CPU, where a move is a bug, 120 steps give a move four times the chance it needs.
    steps, seed, after_move = (120 if one_cpu else 3000), 3, 40
    first_move = None
    if one_cpu:  # the whole process on the caller's CPU, before the runner starts: there is nowhere to move to
        os.sched_setaffinity(0, {caller_cpu})
    vec = retrokit.make_vec("Airstriker-Genesis", n, threads=2, **options)
    singles = [retrokit.make("Airstriker-Genesis", **options) for _ in range(n)]
    burner = subprocess.Popen(
        [sys.executable, "-c", f"import os; os.sched_setaffinity(0, {{{busy_cpu}}})\\nwhile True: pass"]
    )
    try:
        os.sched_setaffinity(0, {caller_cpu})  # this thread only: the workers are kept on the other CPU
        obs, _ = vec.reset(seed=seed)
        expected = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
        same = all((obs[i] == expected[i]).all() for i in range(n))
        ended = [False] * n  # a single env whose episode ended resets on its next step, as the vector's do
        for step in range(steps):
            actions = np.random.default_rng(step).integers(0, 126, n)
            obs, rewards, terms, truncs, _ = vec.step(actions)
            for i, env in enumerate(singles):
                o, r, term, trunc = (env.reset()[0], 0.0, False, False) if ended[i] else env.step(actions[i])[:4]
                ended[i] = term or trunc
                same = same and (obs[i] == o).all() and rewards[i] == r and terms[i] == term and truncs[i] == trunc
            if first_move is None and vec._runner.moved:
                first_move = step
            if first_move is not None and step - first_move >= after_move:
                break  # the runner moved a worker and went on stepping, compared, after the move
        print(json.dumps({"moved": vec._runner.moved, "same": bool(same), "steps": step + 1}))
    finally:
        burner.kill()
        burner.wait()
        vec.close()
    """
)


def run_child(n: int, one_cpu: bool) -> dict:
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, str(CPUS[0]), str(CPUS[1]), str(n), str(int(one_cpu))],
        capture_output=True, text=True, timeout=300, check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


needs_two_cpus = pytest.mark.skipif(len(CPUS) < 2, reason="needs two CPUs: the caller's, and the worker's and burner's")


@needs_two_cpus
@pytest.mark.parametrize("n", [2, 5], ids=["2-envs", "5-envs-on-2-threads"])
def test_a_worker_stalled_behind_a_busy_process_is_moved_onto_the_waiting_callers_cpu(n: int) -> None:
    got = run_child(n, one_cpu=False)
    assert got["same"], "the vector's observations or rewards differ from single envs' under load"
    assert got["moved"] > 0, f"no stalled worker was moved, though a burner shared its CPU for {got['steps']} steps"


@needs_two_cpus
def test_a_process_confined_to_one_cpu_moves_nothing_and_steps_the_same() -> None:
    got = run_child(2, one_cpu=True)
    assert got["same"], "the vector's observations or rewards differ from single envs' on one CPU"
    assert got["moved"] == 0, f"the runner moved a worker, though the process may use one CPU only ({got['steps']} steps)"
