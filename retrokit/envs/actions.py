"""Action spaces: from what an agent chooses to the button masks a console sees.

Four types, as in Gym Retro:

- ``"all"``: a MultiBinary over every button of the system, in Gym Retro's
  order (the RetroPad id order), per player.
- ``"filtered"``: the same MultiBinary, but each group of buttons keeps only
  the combinations the scenario (or the system) lists; anything else in that
  group is dropped, as Gym Retro's filter does.
- ``"discrete"``: one Discrete choice that picks one combination from every
  group (a product), per player.
- ``"multi_discrete"``: one choice per group, per player.

Groups come from the scenario's ``actions`` or, failing that, the system's,
numbered as stable-retro numbers them (:func:`stable_retro_order`).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

import numpy as np
from gymnasium import spaces

from retrokit.errors import InvalidArgumentError, did_you_mean, shown
from retrokit.host.primitives import pack_buttons
from retrokit.host.systems import System

ACTION_TYPES = ("all", "filtered", "discrete", "multi_discrete")


def stable_retro_order(groups: Sequence[Sequence[int]]) -> list[list[int]]:
    """Groups of button masks in the order stable-retro numbers discrete and multi-discrete actions.

    stable-retro keeps a scenario's groups in a map from each group's mask (every
    button it mentions) to the set of its combinations, so the groups come in
    ascending order of that mask, each group's combinations in ascending order
    of their own masks, once each; a group whose mask an earlier group already
    has is dropped. Using its order, not the listed one, makes action 9 press
    the same buttons here as there (a policy trained there, a logged action
    sequence or a hand-written table carries over).
    """
    by_mask: dict[int, list[int]] = {}
    for group in groups:
        by_mask.setdefault(int(np.bitwise_or.reduce(group)) if group else 0, sorted(set(group)))
    return [by_mask[mask] for mask in sorted(by_mask)]


class ActionMap:
    """Translates an action of one type into one RetroPad mask per player.

    Args:
        system: The console, for its buttons.
        action_type: One of :data:`ACTION_TYPES`.
        groups: Groups of button-name combinations; ``None`` uses the system's.
        players: How many players act.
    """

    def __init__(
        self,
        system: System,
        action_type: str,
        groups: Sequence[Sequence[Sequence[str]]] | None = None,
        players: int = 1,
    ) -> None:
        if action_type not in ACTION_TYPES:
            raise InvalidArgumentError(
                f"Expected an action type in {ACTION_TYPES}, got {action_type!r}." + did_you_mean(str(action_type), ACTION_TYPES)
            )
        self.system, self.action_type, self.players = system, action_type, players
        groups = system.actions if groups is None else groups
        if action_type != "all" and not groups:
            raise InvalidArgumentError(
                f"Expected button combinations for action type {action_type!r}, but neither the scenario nor the "
                f"{system.name} system lists any. Use action_type='all', or add 'actions' to the scenario."
            )
        self.combos = stable_retro_order([[system.mask(combo) for combo in group] for group in groups])
        self.group_masks = [int(np.bitwise_or.reduce(c)) if c else 0 for c in self.combos]
        self.valid = [set(c) for c in self.combos]
        self.num_buttons = len(system.buttons)
        self._weights = np.left_shift(1, np.arange(self.num_buttons, dtype=np.int64))
        self.space = self._player_space()
        self._packs = action_type in ("all", "filtered")
        self._size = self.num_buttons * players
        self._filter_table = self._make_filter_table() if action_type == "filtered" else None

    def _player_space(self) -> spaces.Space:
        if self.action_type in ("all", "filtered"):
            return spaces.MultiBinary(self.num_buttons * self.players)
        if self.action_type == "discrete":
            return spaces.Discrete(math.prod(len(c) for c in self.combos) ** self.players)
        return spaces.MultiDiscrete([len(c) for c in self.combos] * self.players)

    def single_player_space(self) -> spaces.Space:
        """The action space of one player, for multi-agent envs."""
        return ActionMap(self.system, self.action_type, self._groups_as_names(), 1).space

    def _groups_as_names(self) -> list[list[list[str]]]:
        return [[self.system.buttons_of(m) for m in group] for group in self.combos]

    def press(self, buttons: Sequence[str]) -> np.ndarray | int:
        """The one-player action of this map's type that presses the named buttons.

        With ``"discrete"`` and ``"multi_discrete"``, the buttons must be one listed
        combination of each group (``["RIGHT", "B"]``: ``RIGHT`` of the D-pad's group,
        ``B`` of the face buttons').

        Raises:
            UnknownNameError: A name is not one of the system's buttons.
            InvalidArgumentError: The buttons are no choice of this map's groups.
        """
        mask = self.system.mask(buttons)
        if self._packs:
            return ((mask >> np.arange(self.num_buttons)) & 1).astype(np.int8)
        picks = []
        for combos, group_mask in zip(self.combos, self.group_masks):
            if mask & group_mask not in combos:
                break
            picks.append(combos.index(mask & group_mask))
        if len(picks) < len(self.combos) or mask & ~int(np.bitwise_or.reduce(self.group_masks)):
            listed = "; ".join(" ".join("+".join(self.system.buttons_of(m)) or "none" for m in c) for c in self.combos)
            raise InvalidArgumentError(
                f"Expected buttons that make one listed combination of each group of the {self.action_type!r} "
                f"actions ({listed}), got {list(buttons)}. Use action_type='all', or list the combination in "
                f"the scenario's actions."
            )
        if self.action_type == "multi_discrete":
            return np.array(picks, dtype=self.space.dtype)
        index, radix = 0, 1
        for pick, combos in zip(picks, self.combos):
            index, radix = index + pick * radix, radix * len(combos)
        return index

    def leave_switches(self, action: object) -> object:
        """``action`` with the console switches released (an agent that samples ``"all"`` leaves them alone)."""
        if not self._packs or not self.system.switches:
            return action  # the groups of the other types hold switches only where a scenario asked for them
        array = np.array(action, copy=True)
        for name in self.system.switches:
            bit = self.system.button_bit(name)
            array.reshape(self.players, self.num_buttons)[:, bit] = 0
        return array

    def combine(self, per_player: Sequence[object]) -> object:
        """Join one action per player (each of :meth:`single_player_space`) into one action of this map."""
        if len(per_player) != self.players:
            raise InvalidArgumentError(f"Expected {self.players} actions, one per player, got {len(per_player)}.")
        if self.action_type == "discrete":
            size = math.prod(len(c) for c in self.combos)
            # Each index is checked against one player's choices: past them it would pick another player's.
            return sum(self._discrete_index(a, size) * size**p for p, a in enumerate(per_player))
        parts = [np.asarray(a).ravel() for a in per_player]
        width = len(self.combos) if self.action_type == "multi_discrete" else self.num_buttons
        for p, part in enumerate(parts):
            if part.size != width:
                raise InvalidArgumentError(
                    f"Expected player {p + 1}'s action to have {width} items, got {part.size}; "
                    f"pass one like its action_space(agent).sample()."
                )
        joint = np.concatenate(parts)
        if self.action_type == "multi_discrete":
            self._check_choices(joint)  # before the cast, which would turn 1.5 into 1
        else:
            self._check_buttons(joint)  # before the cast, which would turn 0.5 into 0 and 256 into 0
        return joint.astype(self.space.dtype)

    def _make_filter_table(self) -> np.ndarray:
        """What :meth:`filter` makes of every possible mask, for the native packer."""
        masks = np.arange(1 << self.num_buttons, dtype=np.int64)
        out = np.zeros_like(masks)
        for group_mask, valid in zip(self.group_masks, self.valid):
            part = masks & group_mask
            out |= np.where(np.isin(part, list(valid)), part, 0)
        return out.astype(np.uint16)

    def filter(self, mask: int) -> int:
        """Drop, group by group, any buttons that do not form a listed combination."""
        out = 0
        for group_mask, valid in zip(self.group_masks, self.valid):
            part = mask & group_mask
            if part in valid:
                out |= part
        return out

    def write_masks(self, action: object, out: np.ndarray) -> None:
        """Write one RetroPad mask per player into ``out`` (uint16) for an action of this map's type.

        A button array of 0s and 1s is packed natively, the common case of
        every step; anything else goes through :meth:`to_masks`, which
        refuses an item other than 0 or 1.
        """
        if (
            self._packs
            and type(action) is np.ndarray
            and action.size == self._size
            and pack_buttons(action, self.num_buttons, out, self._filter_table)
        ):
            return
        out[: self.players] = self.to_masks(action)

    def _discrete_index(self, action: object, n: int | None = None) -> int:
        """A Discrete action as an int, refused unless it is a whole number below ``n`` (the space's size)."""
        n = self.space.n if n is None else n  # type: ignore[attr-defined]
        if isinstance(action, np.ndarray) and action.size == 1:
            action = action.reshape(()).item()
        if isinstance(action, (bool, np.bool_)) or not isinstance(action, numbers.Integral):
            raise InvalidArgumentError(
                f"Expected a discrete action, a whole number from 0 to {n - 1}, got {shown(action)} "
                f"({type(action).__name__}); pass e.g. env.action_space.sample()."
            )
        index = int(action)
        if not 0 <= index < n:
            raise InvalidArgumentError(
                f"Expected a discrete action from 0 to {n - 1}, got {index}; "
                f"other values would press other buttons."
            )
        return index

    def _check_choices(self, flat: np.ndarray) -> None:
        """Refuse a multi-discrete action of the wrong length, or choosing past a group's combinations."""
        nvec = self.space.nvec  # type: ignore[attr-defined]
        values = flat.tolist()
        whole = all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in values)
        if flat.size != nvec.size or not whole:
            raise InvalidArgumentError(
                f"Expected a multi-discrete action of {nvec.size} whole numbers (one per button group and player), "
                f"got {shown(values)}; pass an array like env.action_space.sample()."
            )
        bad = [(i, int(v), int(n)) for i, (v, n) in enumerate(zip(values, nvec.tolist())) if not 0 <= v < n]
        if bad:
            i, value, n = bad[0]
            raise InvalidArgumentError(
                f"Expected choice {i} of the multi-discrete action from 0 to {n - 1}, got {value}; "
                f"the space is {self.space}."
            )

    def _check_buttons(self, flat: np.ndarray) -> None:
        """Refuse a button array holding anything but 0s and 1s (2, -1 or 0.5 is no button's state)."""
        if not ((flat == 0) | (flat == 1)).all():
            bad = [v for v in flat.tolist() if v not in (0, 1)]
            raise InvalidArgumentError(
                f"Expected a MultiBinary action of 0s and 1s (one per button), got {shown(bad[:4])} in it; "
                f"pass an array like env.action_space.sample()."
            )

    def to_masks(self, action: object) -> list[int]:
        """Return one RetroPad mask per player for an action of this map's type."""
        if self.action_type == "discrete":
            index = self._discrete_index(action)
            per_player = math.prod(len(c) for c in self.combos)
            masks = []
            for _ in range(self.players):
                index, choice = divmod(index, per_player) if self.players > 1 else (0, index)
                mask = 0
                for combos in self.combos:
                    choice, pick = divmod(choice, len(combos))
                    mask |= combos[pick]
                masks.append(mask)
            return masks
        flat = np.asarray(action).ravel()
        if self.action_type == "multi_discrete":
            n = len(self.combos)
            self._check_choices(flat)
            return [
                int(np.bitwise_or.reduce([combos[int(i)] for combos, i in zip(self.combos, flat[p * n : (p + 1) * n])]))
                for p in range(self.players)
            ]
        if flat.size != self._size:
            raise InvalidArgumentError(
                f"Expected an action of {self._size} buttons ({self.players} player(s) x {self.num_buttons}), got "
                f"{flat.size} items. Pass an array shaped like env.action_space.sample()."
            )
        self._check_buttons(flat)
        pressed = flat.reshape(self.players, self.num_buttons) == 1
        masks = (pressed @ self._weights).tolist()  # one bit per button, every player at once
        return [self.filter(m) for m in masks] if self.action_type == "filtered" else masks
