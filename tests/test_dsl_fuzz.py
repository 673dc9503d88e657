"""Mutated copies of the shipped scenarios fail only with retrokit's own errors.

Issue 13 found 136 of 15,000 mutated scenarios escaping as lark, yaml, codec
or Python errors. This test makes a few thousand mutants of the scenario
files the repository ships (and their includes), with a fixed seed so a
failure reproduces, loads each one, and runs the ones that compile for a few
steps on random field values. Every failure must be a
:class:`~retrokit.errors.RetrokitError`; anything else is reported with the
mutant's bytes.
"""

from __future__ import annotations

import random
import shutil
import traceback
from pathlib import Path

import pytest

from retrokit.data.games import find_game
from retrokit.dsl.scenario import load_scenario
from retrokit.errors import RetrokitError

SEED = 13
MUTANTS = 2500
GAMES = ("Dasher-Genesis", "SonicTheHedgehog-Genesis", "SonicTheHedgehog2-Genesis", "SonicAndKnuckles3-Genesis")

#: What a mutation inserts: the language's own tokens, YAML's, and the inputs issue 13 found escaping.
TOKENS = [
    b"+", b"-", b"*", b"/", b"//", b"%", b"&", b"|", b"^", b"~", b"<<", b">>", b"==", b"!=", b"<", b">=",
    b"(", b")", b"[", b"]", b",", b" if ", b" else ", b" and ", b" or ", b"not ", b"true", b"false",
    b"prev(", b"delta(", b"initial(", b"peak(", b"abs(", b"min(", b"clip(", b"sign(", b"`", b"`a b`",
    b"0", b"1", b"0x", b"0xFFFFFFFFFFFFFFFFFF", b"1e999", b"1e308", b"-1e308", b".5", b"1_000", b"007",
    b"9" * 5000, b"nan", b"inf", b"frame", b"step", b"x",
    b":", b": ", b"- ", b"\n", b"\n  ", b"  ", b"\t", b"#", b"'", b'"', b"{", b"}", b"|", b">", b"&a", b"*a",
    b"!!python/object:os.system ", b"!!binary ", b"!x ", b"? ", b"---\n", b"...\n", b"%YAML 1.1\n", b"<<: ",
    b"\x00", b"\xff", b"\xe9", b"\xef\xbb\xbf", b"\r", b"\x1b", "é".encode(), "\u2028".encode(),
    b"include: [s.yaml]\n", b"include: [../../etc/passwd]\n", b"include: [include]\n",
    b"tables:\n", b"define:\n", b"rewards:\n", b"done:\n", b"actions:\n", b"crop:\n",
    b"[-1, 0, 1, 1]", b"[[[B]]]", b"{a: 1}", b"~", b"null", b"2001-13-45",
]


def _mutate(data: bytes, rng: random.Random) -> bytes:
    """Apply one to three random edits: delete, insert, replace, duplicate or swap lines, nest."""
    for _ in range(rng.randint(1, 3)):
        i = rng.randrange(len(data) + 1)
        j = min(len(data), i + rng.randint(1, 12))
        kind = rng.randrange(7)
        if kind == 0:
            data = data[:i] + data[j:]
        elif kind == 1:
            data = data[:i] + rng.choice(TOKENS) + data[i:]
        elif kind == 2:
            data = data[:i] + rng.choice(TOKENS) + data[j:]
        elif kind == 3:
            data = data[:i] + data[i:j] * rng.randint(2, 300) + data[j:]
        elif kind == 4:
            lines = data.split(b"\n")
            a, b = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[a], lines[b] = lines[b], lines[a]
            data = b"\n".join(lines)
        elif kind == 5:
            depth = rng.choice((2, 50, 150, 400))
            data = data[:i] + b"abs(" * depth + data[i:j] + b")" * depth + data[j:]
        else:
            data = data[:i] + bytes([rng.randrange(256)]) + data[j:]
    return data


class Target:
    """A shipped file to mutate, and the scenario that reads it (itself, or one including it)."""

    def __init__(self, folder: Path, mutated: str, loaded: str, fields: list[str]) -> None:
        self.folder, self.mutated, self.loaded, self.fields = folder, mutated, loaded, fields
        self.original = (folder / mutated).read_bytes()

    def write(self, number: int, mutant: bytes) -> list[Path]:
        """Write the mutant, and the scenario to load if another, under new names; the scenario is last.

        New names, never a rewrite: rewriting a file in place makes some file
        systems flush it (ext4's auto_da_alloc), which costs milliseconds.
        """
        mutated = self.folder / self.mutated.replace(".yaml", f".{number}.yaml")
        mutated.write_bytes(mutant)
        if self.mutated == self.loaded:
            return [mutated]
        loaded = self.folder / self.loaded.replace(".yaml", f".{number}.yaml")
        text = (self.folder / self.loaded).read_bytes()
        loaded.write_bytes(text.replace(self.mutated.encode(), mutated.relative_to(self.folder).as_posix().encode()))
        return [mutated, loaded]


def _targets(tmp_path: Path) -> list[Target]:
    """Every shipped YAML scenario, and every file one includes, in a copy of its game's folder."""
    targets = []
    for name in GAMES:
        game = find_game(name)
        copy = tmp_path / name
        shutil.copytree(game.folders[0], copy, ignore=shutil.ignore_patterns("*.state", "rom.*", "*.md"))
        for scenario in sorted(p.name for p in game.scenarios.values() if p.suffix == ".yaml"):
            targets.append(Target(copy, scenario, scenario, list(game.fields)))
            if scenario == "contest.yaml":
                included = sorted(p.relative_to(copy).as_posix() for p in (copy / "include").glob("*.yaml"))
                targets += [Target(copy, n, scenario, list(game.fields)) for n in included]
    return targets


def _run(scenario, fields: list[str], rng: random.Random) -> None:
    run = scenario.start()
    values = {f: rng.choice((0, 1, 3, -1, 255, 2**31 - 1, rng.randrange(-(2**16), 2**16))) for f in fields}
    run.reset(values)
    for step in range(1, 4):
        values = {f: v + rng.randrange(-300, 300) for f, v in values.items()}
        run.step(values, step * 4, step)


def test_mutated_shipped_scenarios_raise_only_retrokit_errors(tmp_path) -> None:
    rng = random.Random(SEED)
    targets = _targets(tmp_path)
    assert len(targets) >= 10  # every game's scenarios, and the Sonic level tables
    escaped, outcomes = [], {"loaded": 0, "refused": 0}
    for number in range(MUTANTS):
        target = targets[number % len(targets)]
        mutant = _mutate(target.original, rng)
        written = target.write(number, mutant)
        try:
            _run(load_scenario(written[-1], target.fields), target.fields, rng)
            outcomes["loaded"] += 1
        except RetrokitError:
            outcomes["refused"] += 1
        except Exception as exc:  # noqa: BLE001 - the point: anything else is a fault
            where = "".join(traceback.format_exception(exc)[-3:-1])
            escaped.append(f"mutant {number} of {target.mutated}: {type(exc).__name__}: {str(exc)[:200]}\n{where[:600]}")
        finally:
            for path in written:
                path.unlink()
    assert not escaped, f"{len(escaped)} of {MUTANTS} mutants escaped:\n" + "\n".join(escaped[:5])
    # Both sides are exercised: many mutants still load and run, many are refused.
    assert outcomes["loaded"] > MUTANTS // 10 and outcomes["refused"] > MUTANTS // 10, outcomes


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mutations_are_reproducible(seed: int) -> None:
    data = b"reward: delta(x) * 10\ndone: lives < prev(lives)\n"
    assert _mutate(data, random.Random(seed)) == _mutate(data, random.Random(seed))
