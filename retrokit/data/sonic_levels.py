"""The levels of the Sonic benchmark of "Gotta Learn Fast" (Nichol et al., 2018).

58 levels, every save state of Sonic 1, Sonic 2 and Sonic 3 & Knuckles,
split 47 for training and 11 for testing. Only data: the preset that plays
them is :mod:`retrokit.envs.sonic`, which names these too. Kept below the envs
so that Gymnasium ids can be registered for every level without loading an env.
"""

from __future__ import annotations

from retrokit.data.games import find_game

GAMES = ("SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis")

#: The paper's test levels; every other state of the three games is a training level.
TEST_LEVELS = {
    "SonicTheHedgehog-Genesis": ("SpringYardZone.Act1", "GreenHillZone.Act2", "StarLightZone.Act3", "ScrapBrainZone.Act1"),
    "SonicTheHedgehog2-Genesis": ("MetropolisZone.Act3", "HillTopZone.Act2", "CasinoNightZone.Act2"),
    "SonicAndKnuckles3-Genesis": ("LavaReefZone.Act1", "FlyingBatteryZone.Act2", "HydrocityZone.Act1", "AngelIslandZone.Act2"),
}


def levels() -> list[tuple[str, str]]:
    """Return every benchmark level as ``(game, state)``, in a stable order."""
    return [(game, state) for game in GAMES for state in sorted(find_game(game).states)]


def test_levels() -> list[tuple[str, str]]:
    """Return the paper's 11 test levels."""
    return [(game, state) for game, states in TEST_LEVELS.items() for state in states]


def train_levels() -> list[tuple[str, str]]:
    """Return the paper's 47 training levels."""
    test = set(test_levels())
    return [level for level in levels() if level not in test]
