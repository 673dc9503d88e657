"""The Sonic contest and xpos scenarios against a transcription of the original Lua.

Each game's ``script.lua`` (in stable-retro's integration folders) is
transcribed below into plain Python, function for function, with its quirks:
``prev_lives`` starts at 3 and is only updated when ``done`` did not return
early, the offset and level end are set on the first call, a missing level
gives nil (an error as soon as it is used), a division by zero gives NaN.
The harness calls them as Gym Retro does: a fresh Lua state per episode, and
``done`` then ``reward`` once at reset (results dropped) and once per step,
with ``scenario.frame`` the frames since reset.

Synthetic trajectories (forward, backtracking, dying, finishing, late finish,
fewer than 3 lives, bonus and special stages, S3K's mid-level act change, and
random walks) must give the same rewards and dones, every step, both ways.
"""

from __future__ import annotations

import math
import random
import re
from pathlib import Path

import pytest
import yaml

from retrokit.dsl.scenario import load_scenario
from retrokit.errors import ScenarioRuntimeError

REPO = Path(__file__).resolve().parents[1]
WHEEL = Path(__file__).resolve().parents[0]  # replaced below if stable-retro is installed
try:
    import stable_retro

    WHEEL = Path(stable_retro.__file__).parent / "data" / "stable"
except ImportError:  # pragma: no cover - stable-retro is a dependency
    pass

GAMES = ("SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis")
needs_wheel = pytest.mark.skipif(not (WHEEL / "SonicTheHedgehog-Genesis-v0").is_dir(), reason="stable-retro's Sonic data not installed")


# --- The original Lua, transcribed -------------------------------------------------------------


class LuaError(Exception):
    """What Lua raises on arithmetic or comparison with nil."""


def lua_table(game: str) -> dict[str, int]:
    """level_max_x of a game's script.lua, read from the wheel (commented entries skipped)."""
    text = (WHEEL / f"{game}-v0" / "script.lua").read_text()
    table: dict[str, int] = {}
    for line in text.split("level_max_x = {", 1)[1].split("\n}", 1)[0].splitlines():
        line = line.split("--", 1)[0]
        match = re.search(r'\["(zone=\d+,act=\d+)"\]\s*=\s*([^,]+),', line)
        if match:
            table[match.group(1)] = sum(int(part, 16) for part in match.group(2).split("+"))
    return table


def lua_clip(v, lo, hi):
    if v < lo:
        return lo
    elif v > hi:
        return hi
    return v


def lua_div(a, b):
    """Lua's ``/`` on numbers: IEEE division, so 0/0 is NaN rather than an error."""
    if b == 0:
        return math.nan if a == 0 else math.copysign(math.inf, a)
    return a / b


class Sonic1Lua:
    """script.lua of Sonic The Hedgehog; one instance is one loaded Lua state."""

    frame_limit = 18000

    def __init__(self, level_max_x: dict[str, int]) -> None:
        self.level_max_x = dict(level_max_x)
        self.data: dict = {}
        self.frame = 0
        self.prev_lives = 3
        self.offset_x = None
        self.end_x = None
        self.prev_progress = 0
        self.xpos_last_x = None

    def level_key(self) -> str:
        return f"zone={self.data['zone']},act={self.data['act']}"

    def max_x(self):
        return self.level_max_x.get(self.level_key())  # nil when missing

    def contest_done(self) -> bool:
        if self.data["lives"] < self.prev_lives:
            return True
        self.prev_lives = self.data["lives"]
        return self.calc_progress() >= 1

    def calc_progress(self):
        if self.offset_x is None:
            self.offset_x = -self.data["x"]
            if self.max_x() is None:
                raise LuaError("attempt to perform arithmetic on a nil value")
            self.end_x = self.max_x() - self.data["x"]
        cur_x = lua_clip(self.data["x"] + self.offset_x, 0, self.end_x)
        return lua_div(cur_x, self.end_x)

    def contest_reward(self):
        progress = self.calc_progress()
        reward = (progress - self.prev_progress) * 9000
        self.prev_progress = progress
        if progress >= 1:
            reward = reward + (1 - lua_clip(self.frame / self.frame_limit, 0, 1)) * 1000
        return reward

    def xpos_done(self) -> bool:
        if self.data["lives"] < self.prev_lives:
            return True
        self.prev_lives = self.data["lives"]
        if self.frame >= self.frame_limit:
            return True
        return self.x_past_end()

    def x_past_end(self) -> bool:
        if self.max_x() is None:
            raise LuaError("attempt to compare number with nil")
        return self.data["x"] > self.max_x()

    def xpos_rew(self):
        if self.xpos_last_x is None:
            self.xpos_last_x = self.data["x"]
        result = self.data["x"] - self.xpos_last_x
        self.xpos_last_x = self.data["x"]
        return result


class Sonic2Lua(Sonic1Lua):
    """script.lua of Sonic 2: its done functions also end on game mode 16 (bonus stage)."""

    def contest_done(self) -> bool:
        if self.data["game_mode"] == 16:
            return True
        return super().contest_done()

    def xpos_done(self) -> bool:
        if self.data["lives"] < self.prev_lives:
            return True
        self.prev_lives = self.data["lives"]
        if self.frame >= self.frame_limit:
            return True
        if self.data["game_mode"] == 16:
            return True
        return self.x_past_end()


class Sonic3KLua(Sonic1Lua):
    """script.lua of Sonic 3 & Knuckles: special stages, and the offset shift on an act change."""

    def __init__(self, level_max_x: dict[str, int]) -> None:
        super().__init__(level_max_x)
        self.prev_screen_x = None
        self.prev_act = None

    def contest_done(self) -> bool:
        if self.data["special_stage"] != 0:
            return True
        return super().contest_done()

    def calc_progress(self):
        d = self.data
        if self.offset_x is None:
            self.offset_x = -d["x"]
            self.prev_act = d["act"]
            self.prev_screen_x = d["screen_x"]
            if self.max_x() is None:
                raise LuaError("attempt to perform arithmetic on a nil value")
            self.end_x = self.max_x() - d["x"]
        if d["act"] != self.prev_act:
            self.offset_x = self.offset_x - (d["screen_x"] - self.prev_screen_x)
        cur_x = lua_clip(d["x"] + self.offset_x, 0, self.end_x)
        self.prev_act = d["act"]
        self.prev_screen_x = d["screen_x"]
        return lua_div(cur_x, self.end_x)

    def xpos_done(self) -> bool:
        self.level_max_x["zone=0,act=0"] = 0x2F20
        if self.prev_act is None:
            self.prev_act = self.data["act"]
        if self.data["act"] != self.prev_act:
            return True
        if self.data["special_stage"] != 0:
            return True
        if self.data["lives"] < self.prev_lives:
            return True
        self.prev_lives = self.data["lives"]
        if self.frame >= self.frame_limit:
            return True
        return self.x_past_end()


LUA = {"SonicTheHedgehog-Genesis": Sonic1Lua, "SonicTheHedgehog2-Genesis": Sonic2Lua, "SonicAndKnuckles3-Genesis": Sonic3KLua}
FUNCTIONS = {"contest": ("contest_reward", "contest_done"), "xpos": ("xpos_rew", "xpos_done")}


def run_lua(game: str, scenario: str, reset: dict, steps: list[tuple[dict, int]]) -> list[tuple[float, bool]]:
    """Gym Retro's calls: a fresh state, done then reward at reset (dropped) and at each step."""
    lua = LUA[game](lua_table(game))
    reward_fn, done_fn = (getattr(lua, name) for name in FUNCTIONS[scenario])
    lua.data, lua.frame = reset, 0
    done_fn()
    reward_fn()
    out = []
    for values, frame in steps:
        lua.data, lua.frame = values, frame
        done = done_fn()
        out.append((reward_fn(), bool(done)))
    return out


def run_dsl(game: str, scenario: str, reset: dict, steps: list[tuple[dict, int]]) -> list[tuple[float, bool]]:
    compiled = load_scenario(REPO / "games" / game / f"{scenario}.yaml", list(reset))
    run = compiled.start()
    run.reset(reset)
    out = []
    for i, (values, frame) in enumerate(steps, 1):
        rewards, done = run.step(values, frame, i)
        assert len(rewards) == 1 and isinstance(rewards[0], float) and isinstance(done, bool)
        out.append((rewards[0], done))
    return out


# --- Trajectories --------------------------------------------------------------------------------


def fields_of(game: str) -> list[str]:
    return list(yaml.safe_load((REPO / "games" / game / "game.yaml").read_text())["fields"])


class Trajectory:
    """Builds RAM values step by step: a reset, then changes applied at each step."""

    def __init__(self, game: str, zone: int, act: int, x: int, lives: int = 3, frames_per_step: int = 4) -> None:
        self.ram = {name: 0 for name in fields_of(game)}
        self.ram.update(zone=zone, act=act, x=x, lives=lives, screen_x=max(0, x - 0xA0))
        self.reset = dict(self.ram)
        self.steps: list[tuple[dict, int]] = []
        self.frames_per_step = frames_per_step

    def step(self, n: int = 1, dx: int = 0, **changes: int) -> Trajectory:
        for _ in range(n):
            self.ram.update(changes)
            self.ram["x"] += dx
            self.ram["screen_x"] = max(0, self.ram["screen_x"] + dx)
            self.steps.append((dict(self.ram), self.frames_per_step * (len(self.steps) + 1)))
        return self


def end_of(game: str, zone: int, act: int) -> int:
    return lua_table(game)[f"zone={zone},act={act}"]


def trajectories(game: str) -> dict[str, Trajectory]:
    """The named synthetic trajectories for one game (first level of each game: zone 0, act 0)."""
    end = end_of(game, 0, 0)
    t = {
        "forward": Trajectory(game, 0, 0, 0x50).step(40, dx=24),
        "backtracking": Trajectory(game, 0, 0, 0x400).step(10, dx=30).step(25, dx=-40).step(20, dx=35),
        "dying": Trajectory(game, 0, 0, 0x50).step(15, dx=20).step(1, lives=2).step(5, dx=3),
        "dying_then_extra_life": Trajectory(game, 0, 0, 0x50).step(5, dx=20).step(1, lives=2).step(3, lives=3),
        "finishing": Trajectory(game, 0, 0, end - 0x300).step(20, dx=64).step(5),
        "starting_past_the_end": Trajectory(game, 0, 0, end + 0x10).step(3, dx=8),
        "finishing_late": Trajectory(game, 0, 0, end - 0x40, frames_per_step=1200).step(20, dx=4),
        "fewer_than_3_lives": Trajectory(game, 0, 0, 0x50, lives=2).step(5, dx=10),
        "more_than_3_lives": Trajectory(game, 0, 0, 0x50, lives=5).step(5, dx=10).step(1, lives=4).step(2),
        "frame_limit": Trajectory(game, 0, 0, 0x50, frames_per_step=1000).step(25, dx=1),
        "zone_act_from_ram": Trajectory(game, *_second_level(game), 0x80).step(30, dx=50),
    }
    if game == "SonicTheHedgehog2-Genesis":
        t["bonus_stage"] = Trajectory(game, 0, 0, 0x50).step(8, dx=20).step(1, game_mode=16).step(3, game_mode=12)
    if game == "SonicAndKnuckles3-Genesis":
        # Angel Island: act 1 begins midway; x and the camera jump back by the same amount.
        act_change = Trajectory(game, 0, 0, 0x2E00).step(10, dx=40)
        act_change.step(1, act=1, x=act_change.ram["x"] - 0x2C00, screen_x=act_change.ram["screen_x"] - 0x2C00)
        t["act_change"] = act_change.step(60, dx=48)
        t["act_change_and_camera_drift"] = (
            Trajectory(game, 0, 0, 0x2E00).step(5, dx=40).step(1, act=1, x=0x300, screen_x=0x180).step(10, dx=-20).step(30, dx=90)
        )
        t["special_stage"] = Trajectory(game, 0, 0, 0x50).step(10, dx=20).step(1, special_stage=1).step(3, special_stage=0)
        t["special_stage_at_reset"] = Trajectory(game, 0, 0, 0x50, lives=2)
        t["special_stage_at_reset"].reset["special_stage"] = -1
        t["special_stage_at_reset"].step(3, dx=5)
    return t


def _second_level(game: str) -> tuple[int, int]:
    keys = list(lua_table(game))
    zone, act = re.match(r"zone=(\d+),act=(\d+)", keys[3]).groups()  # type: ignore[union-attr]
    return int(zone), int(act)


def random_trajectory(game: str, seed: int) -> Trajectory:
    """A random walk with random deaths, extra lives, act changes and stage flags."""
    rng = random.Random(seed)
    key = rng.choice(list(lua_table(game)))
    zone, act = (int(v) for v in re.findall(r"\d+", key))
    end = end_of(game, zone, act)
    t = Trajectory(game, zone, act, rng.randrange(0, max(1, end - 0x100)), lives=rng.choice([1, 2, 3, 3, 3, 4]),
                   frames_per_step=rng.choice([1, 4, 4, 400]))
    for _ in range(rng.randrange(20, 120)):
        event = rng.random()
        if event < 0.03:
            t.step(1, lives=max(0, t.ram["lives"] + rng.choice([-1, 1])))
        elif event < 0.05 and "special_stage" in t.ram:
            t.step(1, special_stage=rng.choice([0, 0, 1]))
        elif event < 0.07 and "game_mode" in t.ram:
            t.step(1, game_mode=rng.choice([12, 12, 16]))
        elif event < 0.09:
            jump = rng.randrange(0, 0x1000)
            t.step(1, act=rng.choice([act, act + 1]), x=max(0, t.ram["x"] - jump), screen_x=max(0, t.ram["screen_x"] - jump))
            act = t.ram["act"]
        else:
            t.step(1, dx=rng.randrange(-60, 120))
    return t


# --- Tests ----------------------------------------------------------------------------------------


def _cases():
    for game in GAMES:
        for scenario in ("contest", "xpos"):
            for name in sorted(trajectories(game)) if (WHEEL / f"{game}-v0").is_dir() else []:
                yield pytest.param(game, scenario, name, id=f"{game.split('-')[0]}-{scenario}-{name}")


@needs_wheel
@pytest.mark.parametrize("game,scenario,name", list(_cases()))
def test_dsl_matches_lua_on_trajectory(game: str, scenario: str, name: str) -> None:
    t = trajectories(game)[name]
    expected = run_lua(game, scenario, t.reset, t.steps)
    assert run_dsl(game, scenario, t.reset, t.steps) == expected


@needs_wheel
@pytest.mark.parametrize("game", GAMES)
@pytest.mark.parametrize("scenario", ["contest", "xpos"])
def test_dsl_matches_lua_on_random_walks(game: str, scenario: str) -> None:
    for seed in range(40):
        t = random_trajectory(game, seed)
        try:
            expected = run_lua(game, scenario, t.reset, t.steps)
        except LuaError:
            with pytest.raises(ScenarioRuntimeError):
                run_dsl(game, scenario, t.reset, t.steps)
            continue
        assert run_dsl(game, scenario, t.reset, t.steps) == expected, f"seed {seed}"


@needs_wheel
@pytest.mark.parametrize("game", GAMES)
def test_trajectories_cover_every_outcome(game: str) -> None:
    """The named trajectories really move forward and back, die, finish, and earn the bonus."""
    t = trajectories(game)
    rewards = {name: [r for r, _ in run_lua(game, "contest", tr.reset, tr.steps)] for name, tr in t.items()}
    dones = {name: [d for _, d in run_lua(game, "contest", tr.reset, tr.steps)] for name, tr in t.items()}
    assert all(r > 0 for r in rewards["forward"]) and not any(dones["forward"])
    assert any(r < 0 for r in rewards["backtracking"]) and any(r == 0 for r in rewards["backtracking"])
    assert dones["dying"].index(True) == 15
    assert dones["fewer_than_3_lives"][0] is True
    finish = dones["finishing"].index(True)
    assert rewards["finishing"][finish] > 900  # progress up to 1, plus a bonus near 1000
    late = dones["finishing_late"].index(True)
    assert late == 15 and rewards["finishing_late"][late] == 4 / 0x40 * 9000  # after frame 18000: no bonus
    if game == "SonicAndKnuckles3-Genesis":
        # x jumps back with the camera at the act change (step 11): progress holds, then grows on.
        assert rewards["act_change"][10] == 0 and all(r > 0 for r in rewards["act_change"][11:20])
        assert dones["special_stage"].index(True) == 10


@needs_wheel
@pytest.mark.parametrize("game", GAMES)
@pytest.mark.parametrize("scenario", ["contest", "xpos"])
def test_unknown_level_fails_in_both(game: str, scenario: str) -> None:
    """A level missing from the table: nil in Lua (an error), a clear error in the DSL."""
    t = Trajectory(game, 30, 2, 0x100).step(3, dx=10)
    with pytest.raises(LuaError):
        run_lua(game, scenario, t.reset, t.steps)
    with pytest.raises(ScenarioRuntimeError) as info:
        run_dsl(game, scenario, t.reset, t.steps)
    message = str(info.value)
    assert f"scenario {scenario!r}" in message
    assert "table 'level_end' has no entry for zone=30, act=2" in message
    assert "levels.yaml" in message and "^" in message


@needs_wheel
@pytest.mark.parametrize("game", GAMES)
def test_start_at_level_end_is_nan_in_lua_and_an_error_here(game: str) -> None:
    end = end_of(game, 0, 0)
    t = Trajectory(game, 0, 0, end).step(2)
    assert math.isnan(run_lua(game, "contest", t.reset, t.steps)[0][0])
    with pytest.raises(ScenarioRuntimeError) as info:
        run_dsl(game, "contest", t.reset, t.steps)
    assert "division by zero: the divisor end_x is 0" in str(info.value)
    assert "contest.yaml:" in str(info.value) and "(in define 'progress')" in str(info.value)


# --- The data carried over ------------------------------------------------------------------------


@needs_wheel
@pytest.mark.parametrize("game", GAMES)
def test_level_tables_match_lua(game: str) -> None:
    doc = yaml.safe_load((REPO / "games" / game / "include" / "levels.yaml").read_text())
    values = doc["tables"]["level_end"]["values"]
    ours = {}
    for key, value in values.items():
        zone, act = (int(p) for p in key.split(","))
        ours[f"zone={zone},act={act}"] = value if isinstance(value, int) else sum(int(p, 16) for p in value.split("+"))
    assert ours == lua_table(game)


@needs_wheel
@pytest.mark.parametrize("game", GAMES)
def test_game_yaml_matches_gym_retro_data(game: str) -> None:
    import json

    ours = yaml.safe_load((REPO / "games" / game / "game.yaml").read_text())
    wheel = WHEEL / f"{game}-v0"
    info = json.loads((wheel / "data.json").read_text())["info"]
    assert ours["fields"] == {name: {"address": f["address"], "type": f["type"]} for name, f in info.items()}
    assert [r["sha1"] for r in ours["roms"]] == (wheel / "rom.sha").read_text().split()
    assert ours["states"]["default"] == json.loads((wheel / "metadata.json").read_text())["default_state"]
    text = (REPO / "games" / game / "game.yaml").read_text()
    assert re.search(r"address: 0x[0-9A-F]{6}", text), "addresses are written in hex"
