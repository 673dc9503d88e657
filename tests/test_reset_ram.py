"""Episodes that start differently on purpose: a scenario's ``reset_ram`` (issue 44 item 5), on the NES cartridge.

Hopper's crawlers pause for times drawn from its random state ``rng``
(0x0048, tools/nescart/README.md): from one state every episode plays alike,
unless the scenario writes ``rng`` at reset from the env's seeded generator.
"""

from __future__ import annotations

import pytest

import retrokit
from retrokit.data.schema import check_text
from retrokit.dsl.scenario import scenario_from_text
from retrokit.errors import InvalidArgumentError, ScenarioError

RNG = 0x0048
CRAWLERS = slice(0x0300, 0x0350)  # eight crawlers' records: x, patrol, feet, state, direction, pause
SEEDED = {"reward": "p1_x", "reset_ram": {RNG: {"type": "<u2", "range": [1, 65535]}}}
STEPS = 40  # 160 frames standing still: the crawlers walk and pause meanwhile


def compile_text(text: str):
    """The scenario of a YAML text, read as the file seeded.yaml would be."""
    return scenario_from_text(text, [], source="seeded.yaml", name="seeded")


def episode_start(env, seed: int) -> tuple[int, bytes]:
    """The rng at reset, and the crawlers' RAM after :data:`STEPS` steps without a button."""
    _, info = env.reset(seed=seed)
    rng = info["rng"]
    for _ in range(STEPS):
        obs, *_ = env.step(env.action_space.sample() * 0)
    return rng, bytes(obs[CRAWLERS])


@pytest.fixture(scope="module")
def starts() -> dict[str, list[tuple[int, bytes]]]:
    """Episodes of Hopper's Level1-1 with and without reset_ram, at seeds 0, 0 again, 1 and 2."""
    found = {}
    for name, scenario in (("seeded", SEEDED), ("plain", {"reward": "p1_x"})):
        with retrokit.make("Hopper-Nes", "Level1-1", scenario=scenario, obs_type="ram") as env:
            found[name] = [episode_start(env, seed) for seed in (0, 0, 1, 2)]
    return found


def test_one_seed_gives_the_same_episode(starts):
    assert starts["seeded"][0] == starts["seeded"][1]


def test_seeds_give_different_starts_and_crawlers(starts):
    rngs = [rng for rng, _ in starts["seeded"][1:]]
    assert len(set(rngs)) == 3 and all(1 <= r <= 65535 for r in rngs)
    assert len({crawlers for _, crawlers in starts["seeded"][1:]}) == 3  # the game plays differently
    # the control: without reset_ram the state decides alone, whatever the seed
    assert len({start for start in starts["plain"]}) == 1


def test_the_draws_come_after_the_envs_own():
    """A write to a byte the game never reads leaves everything else as without it: sticky frames and noops too."""
    rams = []
    for scenario in ({"reward": "p1_x"}, {"reward": "p1_x", "reset_ram": {0x0700: "random_u8"}}):
        with retrokit.make("Hopper-Nes", "Level1-1", scenario=scenario, obs_type="ram", sticky_prob=0.25,
                           noop_max=8) as env:  # fmt: skip
            env.reset(seed=5)
            right = env.action_space.sample() * 0
            right[env.unwrapped.buttons.index("RIGHT")] = 1
            for step in range(30):
                obs, *_ = env.step(right if step % 3 else right * 0)
            rams.append(obs.copy())
    rams[1][0x0700] = rams[0][0x0700]  # the written byte aside (tools/nescart/README.md: the last page is unused)
    assert (rams[0] == rams[1]).all()


def test_random_names_draw_whole_bytes():
    scenario = compile_text("reward: 0\nreset_ram: {0x0017: random_u16, 0x20: random_u8, 0x30: random_u32}\n")
    assert scenario.reset_ram == {0x17: ("<u2", 0, 0xFFFF), 0x20: ("|u1", 0, 0xFF), 0x30: ("<u4", 0, 0xFFFFFFFF)}


@pytest.mark.parametrize(
    ("entries", "message"),
    [
        ("{0x17: random_u61}", "Did you mean 'random_u16'?"),
        ("{0x17: {type: '<u2', range: [0, 70000]}}", "within 0 to 65535"),
        ("{0x17: {type: '<u2', range: [9, 3]}}", "LO <= HI"),
        ("{0x17: {type: 'u2', range: [0, 3]}}", "type code"),
        ("{0x17: {type: '<u2'}}", "expected random_u8"),
        ("{0x17: random_u8, 23: random_u8}", "gives address 0x17 twice"),
        ("{lives: random_u8}", "a reset_ram key is a console address"),
        ("{}", "maps 1 to 64 console addresses"),
        ("[random_u8]", "reset_ram must be a mapping"),
        ("{" + ", ".join(f"{a}: random_u8" for a in range(65)) + "}", "maps 1 to 64 console addresses"),
    ],
    ids=["name-typo", "range-too-wide", "range-backwards", "bad-type", "no-range", "twice", "not-an-address",
         "empty", "a-list", "too-many"],
)  # fmt: skip
def test_the_loader_and_the_schema_refuse_bad_entries(entries, message):
    text = f"reward: 0\nreset_ram: {entries}\n"
    with pytest.raises(ScenarioError) as caught:
        compile_text(text)
    assert message in str(caught.value) and str(caught.value).startswith("seeded.yaml:2:")  # the entry's place
    # The schema sees the shapes; what a range may hold, which key is an address and repeats, the loader alone.
    if not any(word in message for word in ("twice", "key is", "within", "LO <= HI")):
        assert check_text(text, "scenario"), "the schema let it through"
    assert not check_text("reward: 0\nreset_ram: {0x17: random_u16, 0x18: {type: '>d2', range: [0, 99]}}\n", "scenario")


def test_writes_outside_ram_and_recording_are_refused_at_make(tmp_path):
    with pytest.raises(InvalidArgumentError, match=r"reset_ram's addresses inside the console's RAM; 0x7FF \(<u2\)"):
        retrokit.make("Hopper-Nes", "Level1-1", scenario={"reward": 0, "reset_ram": {0x07FF: "random_u16"}})
    with pytest.raises(InvalidArgumentError, match="Expected record= without a scenario that writes reset_ram"):
        retrokit.make("Hopper-Nes", "Level1-1", scenario=SEEDED, record=tmp_path)
