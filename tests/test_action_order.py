"""Discrete and multi-discrete actions press the buttons stable-retro's do, action for action, on every system whose
games the wheel integrates (one game each, its own scenario's button groups).

stable-retro is the reference here, run in a child (one emulator per process). It needs a ROM to build an env, but
not a game: a ROM of zeros (an empty iNES image for the NES) loads in these cores, and the action numbering is the
scenario's, not the game's.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from retrokit.data.games import find_game
from retrokit.dsl.scenario import load_scenario
from retrokit.envs.actions import ActionMap
from retrokit.host.systems import get_system
from retrokit.paths import wheel_dir

stable_retro = pytest.importorskip("stable_retro")

EMPTY_NES = b"NES\x1a" + bytes([1, 1, 0, 0]) + bytes(8) + bytes(16384 + 8192)
# system: (ROM extension, ROM bytes). N64 and Saturn are left out: their cores load no empty image.
SYSTEMS = {
    "Genesis": ("md", bytes(131072)),
    "Atari2600": ("a26", bytes(4096)),
    "Nes": ("nes", EMPTY_NES),
    "Snes": ("sfc", bytes(131072)),
    "GameBoy": ("gb", bytes(32768)),
    "Sms": ("sms", bytes(32768)),
    "32x": ("32x", bytes(262144)),
}

REFERENCE = """
import json, sys
import numpy as np
import stable_retro as retro
retro.data.Integrations.add_custom_path(sys.argv[1])
out = {}
for kind in ("DISCRETE", "MULTI_DISCRETE"):
    env = retro.make(sys.argv[2], inttype=retro.data.Integrations.CUSTOM_ONLY, render_mode=None,
                     use_restricted_actions=getattr(retro.Actions, kind))
    if kind == "DISCRETE":
        out[kind] = [env.get_action_meaning(i) for i in range(env.action_space.n)]
    else:
        nvec = env.action_space.nvec.tolist()
        out[kind] = [[env.get_action_meaning(np.eye(len(nvec), dtype=int)[g] * c) for c in range(n)]
                     for g, n in enumerate(nvec)]
    env.close()
print(json.dumps(out))
"""


def _first_game(system: str) -> Path:
    root = wheel_dir() / "data" / "stable"
    return sorted(p for p in root.iterdir() if p.name.endswith(f"-{system}-v0"))[0]


@pytest.mark.parametrize("system", SYSTEMS)
def test_discrete_and_multi_discrete_actions_press_what_stable_retro_presses(system: str, tmp_path: Path) -> None:
    folder = _first_game(system)
    extension, rom = SYSTEMS[system]
    copy = tmp_path / folder.name
    copy.mkdir()
    for path in [*folder.glob("*.json"), *folder.glob("*.state")]:
        shutil.copy(path, copy)
    (copy / f"rom.{extension}").write_bytes(rom)
    result = subprocess.run(
        [sys.executable, "-c", REFERENCE, str(tmp_path), folder.name], capture_output=True, text=True, timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    reference = json.loads(result.stdout.splitlines()[-1])

    game = find_game(folder.name.removesuffix("-v0"), check=False)
    scenario = load_scenario(game.scenario_path(), list(game.fields), game_dir=game.folders[0])
    sys_ = get_system(system)

    def meaning(actions: ActionMap, action: object) -> list[str]:
        return sys_.buttons_of(int(actions.to_masks(action)[0]))

    discrete = ActionMap(sys_, "discrete", scenario.actions)
    assert discrete.space.n == len(reference["DISCRETE"])
    assert [meaning(discrete, i) for i in range(discrete.space.n)] == reference["DISCRETE"]

    multi = ActionMap(sys_, "multi_discrete", scenario.actions)
    nvec = multi.space.nvec.tolist()
    assert nvec == [len(group) for group in reference["MULTI_DISCRETE"]]
    ours = [[meaning(multi, np.eye(len(nvec), dtype=np.int64)[g] * c) for c in range(n)] for g, n in enumerate(nvec)]
    assert ours == reference["MULTI_DISCRETE"]
