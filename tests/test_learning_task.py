"""What a learner plays: the paper's seven actions, the max-x reward, and the benchmark's ``learning:`` block."""

from __future__ import annotations

import numpy as np
import pytest

import retrokit
from retrokit.benchmark.definition import BUILTIN_FILES, LearningTask, load_benchmark, read_benchmark, sonic
from retrokit.envs import sonic as preset
from retrokit.errors import BenchmarkFileError, InvalidArgumentError, UnknownNameError
from retrokit.learning.task import TaskView, learning_task

# The paper's actions, as its text lists them.
PAPER_ACTIONS = [{"LEFT"}, {"RIGHT"}, {"LEFT", "DOWN"}, {"RIGHT", "DOWN"}, {"DOWN"}, {"DOWN", "B"}, {"B"}]


def test_sonics_task_is_the_presets_seven_actions() -> None:
    task = learning_task(sonic())
    assert task.actions is preset.ACTIONS  # one definition, not a copy
    assert [set(combo) for combo in task.actions] == PAPER_ACTIONS and task.x is None


@pytest.fixture(scope="module")
def dasher_env():
    env = retrokit.make("Dasher-Genesis", "Zone1.Act1", action_type="all", frameskip=4, obs_type="ram")
    yield env
    env.close()


def test_the_seven_actions_press_exactly_the_papers_buttons(dasher_env) -> None:
    task = learning_task(load_benchmark("dasher"))
    view = TaskView(dasher_env, task, 1.0, 7)
    system = dasher_env.emulator.system
    pressed = view.buttons(np.arange(7))
    assert [set(system.buttons_of(int(np.dot(bits, 1 << np.arange(len(bits)))))) for bits in pressed] == PAPER_ACTIONS
    with pytest.raises(InvalidArgumentError, match="choices from 0 to 6"):
        view.buttons(np.array([0, 1, 2, 3, 4, 5, 7]))


def test_the_max_x_reward_never_pays_for_going_back(dasher_env) -> None:
    """Right, then left, then right again over ground already covered: only new ground pays, by its pixels."""
    task = learning_task(load_benchmark("dasher"))
    env = preset.AllowBacktracking(preset.Discretizer(dasher_env, task.actions), x=task.x)
    _, info = env.reset(seed=0)
    right, left = 1, 0
    xs, rewards = [info["p1_x"]], []
    for action in [right] * 15 + [left] * 8 + [right] * 25:  # before Zone1.Act1's first enemy
        _, reward, terminated, truncated, info = env.step(action)
        assert not (terminated or truncated)
        xs.append(info["p1_x"])
        rewards.append(reward)
    best = np.maximum.accumulate(xs)
    assert rewards == list(np.diff(best).astype(float))  # each step earns how far it pushed the best x
    back = [i for i in range(48) if xs[i + 1] < xs[i]]
    assert len(back) > 3 and all(rewards[i] == 0 for i in back)  # going back costs nothing, pays nothing
    again = [i for i in range(23, 48) if xs[i] < xs[i + 1] <= best[i]]
    assert len(again) > 2 and all(rewards[i] == 0 for i in again)  # covering the same ground again pays nothing
    assert sum(rewards) == best[-1] - xs[0] > best[23] - xs[0] > 0  # and new ground pays again


def test_the_vector_learners_reward_is_the_same_scaled(dasher_env) -> None:
    task = learning_task(load_benchmark("dasher"))
    view = TaskView(dasher_env, task, 0.5, 1)
    episodes = []
    view.on_episode = lambda i, reward, steps: episodes.append((i, reward, steps))
    view.start(0, {"p1_x": 100})
    got = [view.rewards([9.0], [{"p1_x": x}], [x == 100])[0] for x in (110, 105, 112, 100)]
    assert got == [5.0, 0.0, 1.0, 0.0]  # the max-x reward times 0.5, whatever the benchmark's reward (9 a step)
    assert episodes == [(0, 36.0, 4)]  # the episode as the benchmark scores it


@pytest.mark.parametrize("name", sorted(BUILTIN_FILES))
def test_every_cartridge_benchmark_has_a_checked_learning_block(name) -> None:
    benchmark = load_benchmark(name)
    assert benchmark.learning is not None and len(benchmark.learning.actions) == 7
    benchmark.check_levels(list(benchmark.levels()))  # its buttons are its system's, its x a field of its game
    assert benchmark.as_dict()["learning"]["x"] == benchmark.learning.x


BASE = "name: mine\nbudget: 100\nlevels: {test: [Dasher-Genesis/Zone1.Act2]}\n"


@pytest.mark.parametrize(("block", "message"), [
    ("learning: [1]", "'learning' must be a mapping of actions and x, got list"),
    ("learning: {actons: [[LEFT]]}", "unknown key 'actons' \\(Did you mean 'actions'\\?\\)"),
    ("learning: {x: p1_x}", "'learning.actions' must be a list of 1 to 64 button lists, got None"),
    ("learning: {actions: [LEFT, RIGHT]}", "'learning.actions' item 1 must be a list of button names"),
    ("learning: {actions: [[LEFT], [LEFT]]}", "lists a combination twice"),
    ("learning: {actions: [[LEFT]], x: 5}", "'learning.x' must be the name of a field of the game, got 5"),
], ids=["not-a-mapping", "unknown-key", "no-actions", "not-lists", "twice", "x-not-a-name"])
def test_bad_learning_blocks_are_one_line(tmp_path, block, message) -> None:
    path = tmp_path / "mine.yaml"
    path.write_text(BASE + block + "\n")
    with pytest.raises(BenchmarkFileError, match=message) as caught:
        read_benchmark(path)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(("block", "message"), [
    ("learning: {actions: [[LEFT], [RIHGT]], x: p1_x}", "got 'RIHGT'.* Did you mean 'RIGHT'\\?"),
    ("learning: {actions: [[LEFT]], x: p1_xx}", "learning.x to be a field of Dasher-Genesis, got 'p1_xx'.*'p1_x'"),
], ids=["unknown-button", "unknown-field"])
def test_learning_blocks_are_checked_against_the_game(tmp_path, block, message) -> None:
    path = tmp_path / "mine.yaml"
    path.write_text(BASE + block + "\n")
    benchmark = read_benchmark(path)
    with pytest.raises(UnknownNameError, match=message):
        benchmark.check_levels(list(benchmark.levels()))


def test_a_benchmark_without_a_learning_block(tmp_path) -> None:
    path = tmp_path / "mine.yaml"
    path.write_text(BASE)
    with pytest.raises(InvalidArgumentError, match="has no learning: block; add one"):
        learning_task(read_benchmark(path))
    sonic_levels = tmp_path / "sonic-mine.yaml"
    sonic_levels.write_text(BASE.replace("Dasher-Genesis/Zone1.Act2", "SonicTheHedgehog-Genesis/GreenHillZone.Act1"))
    assert learning_task(read_benchmark(sonic_levels)) == LearningTask(preset.ACTIONS)
