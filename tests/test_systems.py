"""Every tool on every system we have a cartridge for (issue 29 §4), on the real cores.

Parametrized over tools/cartridges.yaml: each cartridge is a small real game of ours, so each test
here is one tool on one system's core, RAM map, byte order, buttons and screen. stable-retro is the
reference where it has an answer (tests/stable_retro_game.py writes its integration of the cartridge):

- the env matches stable-retro frame for frame: observation, reward, done and info;
- states saved by either load in the other and play on alike; movies recorded by either play alike;
- ``ramsearch`` finds each field, at its console address, in the system's RAM region;
- ``validate`` passes the game, and fails it with another game's state in its folder;
- ``render_fps`` is the descriptor's frame rate, and native preprocessing equals Gymnasium's
  wrappers on the system's screen size;
- JERK beats random with ``retrokit evaluate`` on the cartridge's benchmark (a small budget).

The studio's part (its buttons, keys and RAM region) is in tests/test_systems_studio.py.
Each cartridge's fixtures are module-scoped and the plays short, so the suite stays quick.
"""

from __future__ import annotations

import gzip
import json
import re
import shutil
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import yaml
from dashercopy import game_copy
from stable_retro_game import Integration, pressed, wandering, write_integration

import retrokit
from retrokit.cli import main
from retrokit.data.games import Game, find_game
from retrokit.data.statecheck import load_state
from retrokit.data.states import StateRecord, write_state
from retrokit.host.emulator import Emulator
from retrokit.host.fields import FieldSpec
from retrokit.host.memory import FieldReader
from retrokit.host.systems import all_systems
from retrokit.movie import layout, play, read_bk2
from retrokit.paths import wheel_dir
from retrokit.ramsearch import RamSearch
from retrokit.ramsearch.engine import Engine
from retrokit.ramsearch.scales import SCALES
from retrokit.ramsearch.types import search_type

stable_retro = pytest.importorskip("stable_retro")

REPO = Path(__file__).resolve().parent.parent
CARTRIDGES = yaml.safe_load((REPO / "tools" / "cartridges.yaml").read_text())
# The differential's steps (frames: frame skip 1). In 300 the episode ends and restarts at least once on every
# cartridge whose episode ends within 600 (Hopper-Sms at 245, Hopper-GameGear 149, the Trekkers 192, Skipper-Snes
# 275: the dones and resets are compared too), and the fewest screens any cartridge shows is 143 (Hopper-Sms).
STEPS = 300
PLAY = 240  # frames of the ramsearch's play
STATE_PLAY = 120  # frames played before a state is saved, after it is loaded, and in a movie


@dataclass
class Cartridge:
    """One cartridge, with its stable-retro integration (written once per module)."""

    name: str
    game: Game
    benchmark: str
    integration: Integration

    @property
    def system(self):
        return self.game.system

    def stable_env(self, **kwargs):
        """stable-retro's env of the cartridge, every button reaching the core as pressed."""
        return stable_retro.make(
            self.integration.name, inttype=stable_retro.data.Integrations.CUSTOM_ONLY,
            use_restricted_actions=stable_retro.Actions.ALL, render_mode=None, **kwargs,
        )  # fmt: skip


@pytest.fixture(scope="module", params=list(CARTRIDGES), ids=list(CARTRIDGES))
def cart(request, tmp_path_factory) -> Iterator[Cartridge]:
    name = request.param
    root = tmp_path_factory.mktemp(f"stable-retro-{name}")
    integration = write_integration(find_game(name), root)
    stable_retro.data.Integrations.add_custom_path(str(root))
    try:
        yield Cartridge(name, find_game(name), CARTRIDGES[name]["benchmark"], integration)
    finally:
        stable_retro.data.Integrations.clear_custom_paths()


def inputs(cart: Cartridge, seed: int, frames: int, *, recordable: bool = False) -> list[list[str]]:
    """Button sets for ``frames`` frames; ``recordable``: only buttons stable-retro's .bk2 letters hold (a PC Engine's
    I to VI and RUN have none: stable-retro drops them; retrokit writes them as BizHawk does, docs/movies.md)."""
    source = wandering(cart.system, seed)
    keep = set(cart.system.buttons_of(layout(cart.system.name).stable_retro)) if recordable else None
    return [[b for b in next(source) if keep is None or b in keep] for _ in range(frames)]


# --- the env against stable-retro ---------------------------------------------------------------------


def test_the_env_matches_stable_retro_frame_for_frame(cart: Cartridge) -> None:
    ours = retrokit.make(cart.name, state=cart.integration.after_reset, scenario=cart.integration.scenario,
                         action_type="all")  # fmt: skip
    theirs = cart.stable_env()
    try:
        assert list(ours.buttons) == list(theirs.unwrapped.buttons)
        ours.reset(seed=0)
        theirs.reset(seed=0)
        rewards, dones, screens = 0.0, 0, set()
        for step, names in enumerate(inputs(cart, 0, STEPS)):
            action = pressed(ours.buttons, names)
            obs, reward, done, _, info = ours.step(action)
            their_obs, their_reward, their_done, _, their_info = theirs.step(action)
            assert obs.shape == their_obs.shape, f"step {step}"
            assert np.array_equal(obs, their_obs), f"step {step}: {np.argwhere(obs != their_obs)[:3]}"
            assert info == their_info, f"step {step}: {set(info.items()) ^ set(their_info.items())}"
            assert (reward, done) == (their_reward, their_done), f"step {step}"
            rewards += abs(reward)
            screens.add(obs.tobytes())
            if done:
                dones += 1
                ours.reset(seed=0)
                theirs.reset(seed=0)
        # A game in motion, scoring: not a title screen both sides would agree on.
        assert len(screens) > STEPS // 4 and rewards > 0, (len(screens), rewards)
    finally:
        ours.close()
        theirs.close()


RAM_STEPS = 40  # steps of the RAM comparison: enough for the game to write its RAM, every block read each step


def test_ram_observations_and_get_ram_are_stable_retros(cart: Cartridge) -> None:
    # stable-retro's RAM is its memory map's blocks in address order: on the NES 10,240 bytes (the cartridge RAM at
    # 0x6000 after the 2 KiB), on a Game Boy video, cartridge, work, object and high RAM; the env, get_ram() and the
    # vector env all give those bytes, in that order and length.
    theirs = cart.stable_env(obs_type=stable_retro.Observations.RAM)
    ours = retrokit.make(cart.name, state=cart.integration.after_reset, obs_type="ram", action_type="all")
    vec = retrokit.make_vec(cart.name, 2, state=cart.integration.after_reset, obs_type="ram", action_type="all")
    try:
        their_obs, _ = theirs.reset(seed=0)
        obs, _ = ours.reset(seed=0)
        batch, _ = vec.reset(seed=0)
        assert ours.observation_space.shape == their_obs.shape == vec.single_observation_space.shape
        changed = 0
        for step, names in enumerate(inputs(cart, 7, RAM_STEPS)):
            action = pressed(ours.buttons, names)
            before = obs
            their_obs = theirs.step(action)[0]
            obs = ours.step(action)[0]
            batch = vec.step(np.stack([action, action]))[0]
            assert np.array_equal(obs, their_obs), f"step {step}: bytes {np.flatnonzero(obs != their_obs)[:5]}"
            assert np.array_equal(batch[0], their_obs) and np.array_equal(batch[1], their_obs), f"vector env, step {step}"
            changed += not np.array_equal(before, obs)
        assert np.array_equal(ours.get_ram(), theirs.unwrapped.get_ram())
        assert changed > RAM_STEPS // 2  # a game writing its RAM, not two frozen copies
        # docs/systems.md says the system's layout, with its length
        page = (REPO / "docs" / "systems.md").read_text()
        row = re.search(rf"(?ms)^## {cart.system.name}\n.*?^\| `get_ram\(\)`, `obs_type=\"ram\"` \| ([^\n]*)", page)
        assert row is not None and row[1].startswith(f"{len(their_obs):,} bytes"), cart.system.name
    finally:
        vec.close()
        ours.close()
        theirs.close()


def test_the_nes_ram_is_the_internal_ram_then_the_cartridge_ram() -> None:
    # The layout, on the console: 0x0000-0x07FF, then 0x6000-0x7FFF, each byte where peek finds it.
    with retrokit.make("Hopper-Nes", obs_type="ram") as env:
        env.reset(seed=0)
        emulator = env.unwrapped.emulator
        emulator.poke(0x0123, 0xA5)
        emulator.poke(0x6001, 0x5A)
        emulator.poke(0x7FFF, 0x3C)
        ram = env.get_ram()
        assert len(ram) == 10240 == env.observation_space.shape[0]
        assert (ram[0x0123], ram[0x800 + 0x0001], ram[-1]) == (0xA5, 0x5A, 0x3C)
        assert np.array_equal(ram[:0x800], emulator.ram)  # the system RAM is its first 2 KiB


# --- states and movies, both ways ---------------------------------------------------------------------


def run_ours(emu: Emulator, cart: Cartridge, names: list[list[str]]) -> list[np.ndarray]:
    screens = []
    for pressed_now in names:
        emu.run([cart.system.mask(pressed_now), 0], 1)
        screens.append(emu.screen().copy())
    return screens


def run_theirs(env, names: list[list[str]]) -> list[np.ndarray]:
    return [env.step(pressed(env.unwrapped.buttons, n))[0].copy() for n in names]


def first_difference(ours: list[np.ndarray], theirs: list[np.ndarray]) -> int | None:
    assert len(ours) == len(theirs)
    return next((i for i, (a, b) in enumerate(zip(ours, theirs)) if not np.array_equal(a, b)), None)


def shared_ram_agrees(emu: Emulator, env) -> list[int]:
    """Compare each of stable-retro's memory blocks that retrokit maps too, as the core keeps the bytes; return
    where the blocks compared start.

    The two map different blocks: on the NES stable-retro adds FCEUmm's cartridge RAM at 0x6000, on a Game Boy
    Color it maps 8 KiB of work RAM where retrokit's system RAM is all 32 KiB of it.
    """
    compared = []
    for start, block in env.unwrapped.data.memory.blocks.items():
        theirs = np.frombuffer(block, np.uint8)
        if not emu.space.holds(start, len(theirs)):
            continue
        index, offsets = emu.space.offsets(start, len(theirs))
        ours = np.asarray(emu.space.buffers[index])[min(offsets) : max(offsets) + 1]  # the core's order, both sides
        assert np.array_equal(ours, theirs), f"RAM from {start:#x}"
        compared.append(start)
    return compared


def test_a_state_retrokit_saved_loads_in_stable_retro(cart: Cartridge, tmp_path: Path) -> None:
    emu = Emulator(cart.system, cart.game.require_rom())
    try:
        emu.set_state(load_state(cart.game, cart.game.state_path()))
        run_ours(emu, cart, inputs(cart, 1, STATE_PLAY))
        data = emu.get_state()
        path = write_state(tmp_path / "Middle.state", data, record=StateRecord.of(cart.name, cart.game.sha1s[0], data))
        env = cart.stable_env()
        try:
            env.load_state(str(path))
            env.reset(seed=0)  # loads it, then runs a frame with no buttons
            emu.run([0, 0], 1)
            later = inputs(cart, 2, STATE_PLAY)
            assert first_difference(run_ours(emu, cart, later), run_theirs(env, later)) is None
            assert cart.system.ram_base in shared_ram_agrees(emu, env)  # the system RAM at least
        finally:
            env.close()
    finally:
        emu.close()


def test_a_state_stable_retro_saved_loads_in_retrokit(cart: Cartridge, tmp_path: Path) -> None:
    env = cart.stable_env()
    try:
        env.reset(seed=0)
        run_theirs(env, inputs(cart, 3, STATE_PLAY))
        path = tmp_path / "Theirs.state"
        path.write_bytes(gzip.compress(env.unwrapped.em.get_state()))  # stable-retro's .state: plain gzip
        ours = retrokit.make(cart.name, state=path, action_type="all")
        try:
            ours.reset(seed=0)
            later = inputs(cart, 4, STATE_PLAY)
            mine = [ours.step(pressed(ours.buttons, n))[0].copy() for n in later]
            assert first_difference(mine, run_theirs(env, later)) is None
        finally:
            ours.close()
    finally:
        env.close()


def test_a_retrokit_movie_plays_in_stable_retro(cart: Cartridge, tmp_path: Path) -> None:
    ours = retrokit.make(cart.name, record=tmp_path, action_type="all")
    names = inputs(cart, 5, STATE_PLAY, recordable=True)
    try:
        ours.reset(seed=0)
        mine = [ours.step(pressed(ours.buttons, n))[0].copy() for n in names]
    finally:
        ours.close()
    (path,) = tmp_path.glob("*.bk2")
    movie = stable_retro.Movie(str(path))
    emulator = stable_retro.RetroEmulator(str(cart.game.require_rom()))
    try:
        emulator.set_state(movie.get_state())
        width = len(cart.system.buttons)
        theirs = []
        for frame, now in enumerate(names):
            assert movie.step(), f"stable-retro's movie ended at frame {frame}"
            keys = [movie.get_key(i, 0) for i in range(width)]
            assert keys == [bool(b) for b in pressed(list(cart.system.buttons), now)], f"frame {frame}"
            emulator.set_button_mask(np.array(keys, dtype=np.uint8), 0)
            emulator.step()
            theirs.append(emulator.get_screen().copy())
    finally:
        del emulator
    assert first_difference(mine, theirs) is None


def test_a_stable_retro_movie_plays_in_retrokit(cart: Cartridge, tmp_path: Path) -> None:
    env = cart.stable_env(record=str(tmp_path))
    try:
        env.reset(seed=0)
        screens = [env.unwrapped.em.get_screen().copy()]
        screens += run_theirs(env, inputs(cart, 6, STATE_PLAY, recordable=True))
        env.unwrapped.stop_record()
    finally:
        env.close()
    (path,) = tmp_path.glob("*.bk2")
    movie = read_bk2(path)
    assert (movie.game, movie.system) == (cart.name, cart.system.name)
    assert first_difference(list(play(movie)), screens) is None


# --- ramsearch ----------------------------------------------------------------------------------------


def searched_as(spec: FieldSpec) -> str | None:
    """The type a search finds a field as: its own, or a bit type for a one-bit flag (None: no search type reads it)."""
    if spec.mask is None:
        return spec.type
    if spec.type == "|u1" and spec.mask in BIT_MASKS:
        return f"|u1&0x{spec.mask:02X}"
    return None


BIT_MASKS = [1 << bit for bit in range(8)]


def test_ramsearch_finds_each_field_at_its_console_address(cart: Cartridge, capsys, tmp_path: Path) -> None:
    """Each field's values along a play, searched for as a user would (``equal VALUE`` at each snapshot),
    leave its address and type among the candidates, in the system's RAM region and byte order."""
    fields = [f for f in cart.game.fields.values() if searched_as(f)]
    with RamSearch(cart.game) as search:
        base = cart.system.ram_base
        assert base in [start for start, _ in search.layout.regions], search.layout.describe()
        reader = FieldReader(fields, search.emulator.space)
        snapshots, values = [], []
        for names in [inputs(cart, 7, PLAY)[i : i + 20] for i in range(0, PLAY, 20)]:
            for now in names:
                search.step(now, 1)
            search.snapshot()
            snapshots.append(search.engine.snapshots[-1])
            values.append(reader.read())
        layout = search.layout
    as_stored = 1 << next(i for i, scale in enumerate(SCALES) if not scale.label)  # the value itself
    for spec in fields:
        engine = Engine(layout, [search_type(searched_as(spec))])
        for snapshot, value in zip(snapshots, values):
            engine.add_snapshot(snapshot)
            engine.filter("equal", value[spec.name])
        found = engine.candidates.alive[0] & (engine.candidates.scale[0] & as_stored != 0)
        where = f"{spec.name} ({layout.format(spec.address)}, {spec.type})"
        assert found[layout.position(spec.address, spec.field_type.width)], f"{where} not found"
        if len({v[spec.name] for v in values}) >= 4:  # a value that moved pins its address down
            assert np.count_nonzero(found) <= 8, f"{where}: {np.count_nonzero(found)} candidates"
    # The command shows the RAM region in console addresses.
    session = tmp_path / "s.session"
    assert main(["ramsearch", "new", cart.name, "--session", str(session)]) == 0
    assert f"at every address of {layout.describe()})" in capsys.readouterr().out


# --- validate -----------------------------------------------------------------------------------------


def another_games_state(cart: Cartridge) -> Path:
    """A state of another game of the same system from the wheel or, where it has none, of another system on the
    same core (Game Gear, Game Boy Color), or else of another system (the wheel has no PC Engine game)."""
    others = sorted(all_systems().values(), key=lambda s: (s.core != cart.system.core, s.name))
    systems = [cart.system] + [s for s in others if s != cart.system]
    stable = wheel_dir() / "data" / "stable"
    return next(state for system in systems for folder in sorted(stable.glob(f"*-{system.name}-v0"))
                for state in sorted(folder.glob("*.state")))  # fmt: skip


def test_validate_passes_the_game_and_catches_a_state_from_another_game(cart: Cartridge, tmp_path: Path) -> None:
    # One run (validate plays every state and scenario): the copy with a foreign state fails on that state alone,
    # so everything of the game's own passes. Dasher's solution movies are left out of the copy: their replays
    # (5,700 frames) are no system's, and tests/test_validate.py validates every folder of games/ with its movies.
    # Its smoke runs are short here (24 frames: 6 steps, one held action) for the same reason: test_validate's
    # every-game test plays 120 frames of each state and scenario of each cartridge.
    folder = game_copy(cart.game.folders[0], tmp_path)  # every state, no solution movie
    shutil.copy(another_games_state(cart), folder / "Foreign.state")
    assert main(["validate", str(folder), "--quiet", "--frames", "24", "--json", str(tmp_path / "report.json")]) == 1
    (report,) = json.loads((tmp_path / "report.json").read_text())["games"]
    failed = [r for r in report["results"] if r["status"] == "fail"]
    assert failed and all(r["state"] == "Foreign" for r in failed), failed
    assert {r["state"] for r in report["results"] if r["status"] == "pass"} >= set(cart.game.states)


# --- render_fps and preprocessing ---------------------------------------------------------------------


def test_render_fps_is_the_descriptors_frame_rate(cart: Cartridge) -> None:
    for frameskip in (1, 4):
        env = retrokit.make(cart.name, frameskip=frameskip)
        try:
            rate = cart.system.frame_rate(env.unwrapped.emulator.av_info()["fps"])
            assert cart.system.frame_rates, f"{cart.system.name} lists no frame_rate in systems.yaml"
            assert rate in cart.system.frame_rates.values()
            assert env.metadata["render_fps"] == pytest.approx(rate / frameskip)
        finally:
            env.close()


def test_native_preprocessing_equals_gymnasiums_wrappers_on_its_screen(cart: Cartridge) -> None:
    from test_preprocessing import SKIP, as_native, reference

    options = {"grayscale": True, "resize": (84, 84), "frame_stack": 4, "max_pool": True}
    native = retrokit.make(cart.name, frameskip=SKIP, sticky_prob=0.0, **options)
    ref = reference(cart.name, grayscale=True, max_pool=True, resize=(84, 84), frame_stack=4)
    try:
        obs, _ = native.reset(seed=3)
        expected, _ = ref.reset(seed=3)
        height, width = native.unwrapped.emulator.screen_shape()
        assert (height, width) == ref.unwrapped.observation_space.shape[:2]
        source = wandering(cart.system, 8, hold=1)
        for step in range(60):
            diff = np.abs(obs.astype(int) - as_native(expected, False).astype(int))
            assert diff.max() <= 1, f"{width}x{height}: step {step} differs by {diff.max()}"
            action = pressed(native.buttons, next(source))
            obs, _, done, truncated, _ = native.step(action)
            expected, _, ref_done, ref_truncated, _ = ref.step(action)
            if done or truncated or ref_done or ref_truncated:
                break
    finally:
        native.close()
        ref.close()


# --- JERK beats random --------------------------------------------------------------------------------


def test_jerk_beats_random_on_its_benchmark(cart: Cartridge, tmp_path: Path, capsys) -> None:
    from retrokit.benchmark.definition import load_benchmark

    # One run compares both agents (each into OUT/<agent>/). 300 timesteps a level: with seed 0 JERK scores 1.8
    # (Skipper-Snes) to 29 (Hopper-GameGear) times random's on every cartridge, as it did with 600.
    levels = ",".join(level.name for level in load_benchmark(cart.benchmark).test[:2])
    args = ["evaluate", "--benchmark", cart.benchmark, "--levels", levels, "--timesteps", "300", "--no-progress",
            "--agent", "jerk", "--agent", "random", "--out", str(tmp_path)]  # fmt: skip
    assert main(args) == 0, capsys.readouterr().err
    scores = {
        agent: json.loads((tmp_path / agent / "summary.json").read_text())["aggregate"] for agent in ("jerk", "random")
    }
    assert scores["jerk"] > 1.5 * scores["random"], scores
