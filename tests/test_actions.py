"""Action maps: the native button packer agrees with the Python translation for every input."""

from __future__ import annotations

import numpy as np
import pytest

from retrokit.envs.actions import ACTION_TYPES, ActionMap
from retrokit.errors import InvalidArgumentError
from retrokit.host.systems import get_system
from retrokit.native import _host

GENESIS = get_system("Genesis")
BUTTON_DTYPES = [np.int8, np.uint8, np.bool_, np.int16, np.int32, np.int64, np.uint64, np.float32, np.float64]


def random_actions(actions: ActionMap, rng: np.random.Generator, dtype: type, n: int = 200) -> list[np.ndarray]:
    """Button arrays of 0s and 1s of every density."""
    return [(rng.random(actions.space.n) < rng.random()).astype(dtype) for _ in range(n)]


def not_binary(dtype: type) -> list[object]:
    """Values a MultiBinary item of this dtype can hold that are neither 0 nor 1."""
    values: list[object] = [] if dtype is np.bool_ else [2, 255 if np.dtype(dtype).kind == "u" else 127]
    if np.dtype(dtype).itemsize > 1 and dtype is not np.bool_:
        values.append(256)  # only its high byte is set
    if np.issubdtype(dtype, np.signedinteger) or np.issubdtype(dtype, np.floating):
        values.append(-1)
    if np.issubdtype(dtype, np.floating):
        values += [0.5, np.nan, np.inf]
    return values


@pytest.mark.parametrize("players", [1, 2], ids=["1p", "2p"])
@pytest.mark.parametrize("action_type", ["all", "filtered"])
@pytest.mark.parametrize("dtype", BUTTON_DTYPES, ids=lambda d: np.dtype(d).name)
def test_native_packing_equals_python(action_type: str, dtype: type, players: int) -> None:
    actions = ActionMap(GENESIS, action_type, players=players)
    rng = np.random.default_rng(players)
    out = np.zeros(_host.MAX_PORTS, dtype=np.uint16)
    for action in random_actions(actions, rng, dtype):
        out[:] = 0xFFFF
        actions.write_masks(action, out)
        assert out[:players].tolist() == actions.to_masks(action), action
        assert (out[players:] == 0xFFFF).all()  # ports past the players are left alone


@pytest.mark.parametrize("action_type", ["all", "filtered"])
@pytest.mark.parametrize("dtype", [*BUTTON_DTYPES, np.float16], ids=lambda d: np.dtype(d).name)
def test_items_other_than_0_and_1_are_refused(action_type: str, dtype: type) -> None:
    actions = ActionMap(GENESIS, action_type, players=2)
    out = np.zeros(_host.MAX_PORTS, dtype=np.uint16)
    for value in not_binary(dtype):
        for position in (0, 23):  # player 1's first button, player 2's last
            action = np.zeros(24, dtype=dtype)
            action[position] = value
            out[:] = 0xFFFF
            assert _host.pack_buttons(action, 12, out) is False
            assert (out == 0xFFFF).all()  # nothing written
            for form in (action, action.tolist()):
                with pytest.raises(InvalidArgumentError, match="0s and 1s"):
                    actions.write_masks(form, out)
            with pytest.raises(InvalidArgumentError, match="0s and 1s"):
                actions.combine([action[:12], action[12:]])


@pytest.mark.parametrize("action_type", ACTION_TYPES)
def test_write_masks_takes_every_form_of_action(action_type: str) -> None:
    actions = ActionMap(GENESIS, action_type, players=2)
    out = np.zeros(2, dtype=np.uint16)
    for action in [actions.space.sample() for _ in range(50)]:
        expected = actions.to_masks(action)
        for form in (action, np.asarray(action).tolist(), np.asarray(action, dtype=object)):
            out[:] = 0
            actions.write_masks(form, out)
            assert out.tolist() == expected


def test_filter_table_is_the_filter_of_every_mask() -> None:
    actions = ActionMap(GENESIS, "filtered")
    table = actions._filter_table
    assert table is not None and len(table) == 1 << len(GENESIS.buttons)
    assert [int(v) for v in table] == [actions.filter(m) for m in range(len(table))]


@pytest.mark.parametrize(
    "action, message",
    [
        (np.zeros(11, dtype=np.int8), "12 buttons"),
        (np.zeros(13, dtype=np.int8), "12 buttons"),
        (np.zeros(12 * 9, dtype=np.int8), "12 buttons"),
    ],
    ids=["short", "long", "too-many-players"],
)
def test_packer_refuses_the_wrong_size(action: np.ndarray, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        _host.pack_buttons(action, 12, np.zeros(_host.MAX_PORTS, dtype=np.uint16))


def test_packer_refuses_a_table_of_the_wrong_size() -> None:
    with pytest.raises(InvalidArgumentError, match="2\\*\\*12"):
        _host.pack_buttons(np.zeros(12, dtype=np.int8), 12, np.zeros(1, dtype=np.uint16), np.zeros(10, dtype=np.uint16))


def test_packer_leaves_non_numbers_to_python() -> None:
    out = np.zeros(1, dtype=np.uint16)
    assert _host.pack_buttons(np.zeros(12, dtype="U1"), 12, out) is False
    assert _host.pack_buttons(np.zeros(12, dtype=np.float16), 12, out) is False


def test_a_wrong_sized_action_is_a_clear_error() -> None:
    actions = ActionMap(GENESIS, "all")
    with pytest.raises(InvalidArgumentError, match="12 buttons"):
        actions.write_masks(np.zeros(11, dtype=np.int8), np.zeros(1, dtype=np.uint16))
