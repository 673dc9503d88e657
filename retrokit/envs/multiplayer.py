"""PettingZoo environments for games with several players.

:class:`RetroParallelEnv` is written once, over a :class:`retrokit.envs.env.RetroEnv`
with every player; the AEC form comes from PettingZoo's conversion wrapper.
Every agent sees the whole screen (or RAM) and gets its own reward from the
scenario's per-player rewards. A scenario's per-player done conditions
(``dones:``) take a player out for good: its agent is terminated and leaves
``agents``, as PettingZoo's rules ask, and presses nothing from then on; the
others play on until the scenario's ``done``, or until every player is out.

Both pickle as their arguments (:mod:`retrokit.envs.pickling`), as SuperSuit's
``concat_vec_envs_v1(..., num_cpus=N)`` needs: unpickled, each is a fresh env
made from them, without the emulator's state or the episode.
"""

from __future__ import annotations

import functools
from typing import Any

from gymnasium import spaces
from pettingzoo import AECEnv, ParallelEnv
from pettingzoo.utils.conversions import parallel_to_aec_wrapper
from pettingzoo.utils.wrappers import OrderEnforcingWrapper

from retrokit.data.games import find_game
from retrokit.envs.env import RetroEnv, State
from retrokit.envs.pickling import PicklesAsArguments
from retrokit.envs.viewer import render_modes
from retrokit.errors import InvalidArgumentError, UnknownNameError, did_you_mean


class RetroParallelEnv(PicklesAsArguments, ParallelEnv):
    """A multi-player game as a PettingZoo ``ParallelEnv``.

    Args:
        game: The game's name.
        state: A state name, a ``.state`` path, or a :class:`retrokit.envs.env.State`.
        scenario: The scenario (see :class:`retrokit.envs.env.RetroEnv`); it must
            give one reward per player.
        **options: Other :class:`retrokit.envs.env.RetroEnv` options, except ``players``.
    """

    metadata = {"render_modes": render_modes(), "name": "retrokit_v0", "is_parallelizable": True}

    def __init__(self, game: str, state: Any = State.DEFAULT, scenario: Any = None, **options: Any) -> None:
        PicklesAsArguments.__init__(self, game, state, scenario, **options)
        if "players" in options:
            raise InvalidArgumentError("Expected no 'players' option: a PettingZoo env has every player of the game.")
        players = find_game(game).players
        if players < 2:
            raise InvalidArgumentError(
                f"Expected a game with two or more players, got {game!r} with {players}. Use retrokit.make for it."
            )
        self._env = RetroEnv(game, state, scenario, players=players, **options)
        scenario_players = getattr(self._env.scenario, "players", 1)
        if scenario_players < players:
            self._env.close()
            raise InvalidArgumentError(
                f"Expected a scenario with one reward per player ({players}), got one with {scenario_players}. "
                f"Give the scenario per-player rewards (retrokit docs scenarios)."
            )
        self.possible_agents = [f"player_{i + 1}" for i in range(players)]
        self.agents: list[str] = []
        self.render_mode = self._env.render_mode
        # Its frame rate, over its frame skip; its name is the game's, as PettingZoo names each environment.
        self.metadata = {**self.metadata, **self._env.metadata, "name": f"{self._env.game.name}_v0"}
        self._obs_space = self._env.observation_space
        self._act_space = self._env.actions.single_player_space()

    @functools.cache  # noqa: B019 - one space object per agent, every call
    def observation_space(self, agent: str) -> spaces.Space:
        self._check_agent(agent)
        return self._obs_space

    @functools.cache  # noqa: B019
    def action_space(self, agent: str) -> spaces.Space:
        self._check_agent(agent)
        return self._act_space

    def _check_agent(self, agent: str) -> None:
        if agent not in self.possible_agents:
            raise UnknownNameError(
                f"Expected an agent of {self.possible_agents}, got {agent!r}." + did_you_mean(agent, self.possible_agents)
            )

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        obs, info = self._env.reset(seed=seed, options=options)
        self.agents = list(self.possible_agents)
        return {a: obs.copy() for a in self.agents}, {a: dict(info) for a in self.agents}

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise InvalidArgumentError(f"Expected an action for every live agent; missing {missing}.")
        idle = self._act_space.sample() * 0 if not isinstance(self._act_space, spaces.Discrete) else 0
        # A player out of the game presses nothing, whatever is passed for it.
        joint = self._env.actions.combine([actions[a] if a in self.agents else idle for a in self.possible_agents])
        obs, _, terminated, truncated, info = self._env.step(joint)
        rewards, dones = info.pop("rewards"), info.pop("dones")
        agents = self.agents
        index = {a: self.possible_agents.index(a) for a in agents}
        out = {a: bool(terminated or dones[index[a]]) for a in agents}
        result = (
            {a: obs.copy() for a in agents},
            {a: float(rewards[index[a]]) for a in agents},
            out,
            {a: bool(truncated) and not out[a] for a in agents},
            {a: dict(info) for a in agents},
        )
        self.agents = [] if terminated or truncated else [a for a in agents if not out[a]]
        return result

    def render(self) -> Any:
        return self._env.render()

    def state(self) -> Any:
        """The global state: the same screen (or RAM) every agent sees."""
        return self._env.observe()

    def close(self) -> None:
        self._env.close()


def parallel_env(game: str, state: Any = State.DEFAULT, scenario: Any = None, **options: Any) -> RetroParallelEnv:
    """Make the PettingZoo ``ParallelEnv`` of a multi-player game."""
    return RetroParallelEnv(game, state, scenario, **options)


class RetroAECEnv(PicklesAsArguments, OrderEnforcingWrapper):
    """A multi-player game as a PettingZoo AEC env: PettingZoo's conversion of :class:`RetroParallelEnv`.

    It is what ``pettingzoo.utils.conversions.parallel_to_aec`` makes (the
    conversion, under the order-enforcing wrapper), as a class of its own so
    that it pickles as its arguments rather than as the wrappers' state.
    The arguments are :class:`RetroParallelEnv`'s.
    """

    def __init__(self, game: str, state: Any = State.DEFAULT, scenario: Any = None, **options: Any) -> None:
        PicklesAsArguments.__init__(self, game, state, scenario, **options)
        OrderEnforcingWrapper.__init__(self, parallel_to_aec_wrapper(RetroParallelEnv(game, state, scenario, **options)))


def env(game: str, state: Any = State.DEFAULT, scenario: Any = None, **options: Any) -> AECEnv:
    """Make the PettingZoo AEC env of a multi-player game, by conversion of the parallel one."""
    return RetroAECEnv(game, state, scenario, **options)
