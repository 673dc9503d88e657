"""Record a solution movie for each Dasher act with a scripted agent, for ``retrokit validate``.

    python tools/record_dasher_solutions.py [--write-yaml]

The agent searches with save states: it strings together short button
patterns (run, jump, run then jump), backtracking whenever player 1 is hurt,
falls or dies, until the act is cleared (``level_done``). So each movie ends
where Dasher's scenario must say done and pay the clear bonus.

Movies go to ``games/Dasher-Genesis/movies/<State>.bk2``. The outcome of each
under the default scenario is printed; with ``--write-yaml`` it replaces the
``movies:`` section of the game's ``game.yaml``. ``retrokit validate`` then
replays them and checks that the scenario still agrees.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from retrokit.data.games import find_game
from retrokit.data.statecheck import load_state
from retrokit.host.emulator import Emulator
from retrokit.host.memory import FieldReader
from retrokit.movie import Movie, write_bk2
from retrokit.testing.movies import MOVIES_FOLDER, replay

ACTS = ("Zone1.Act1", "Zone1.Act2", "Zone2.Act1", "Zone2.Act2", "Zone3.Act1", "Zone3.Act2")
CHUNK = 8
MAX_WAITS = 3  # standing still at most this many patterns in a row


class BacktrackingAgent:
    """Depth-first search over short button patterns, backtracking from any fall or death.

    Each node is a save state; patterns are tried in order of preference (run,
    then jumps of several heights and start frames) and a pattern that kills
    player 1, or gets it no further, is abandoned for the next one, or, when
    none is left, the node's own pattern.
    """

    def __init__(self, emu: Emulator, reader: FieldReader) -> None:
        self.emu, self.reader = emu, reader
        right = emu.system.mask(["RIGHT"])
        jump = emu.system.mask(["RIGHT", "B"])
        # Running first; then jumps of three heights, started 0 to 6 frames later; then
        # long jumps taken late; last, standing still, to let a crawler walk off.
        self.patterns = [[right] * CHUNK] + [
            [right] * delay + [jump] * hold + [right] * (2 * CHUNK - hold)
            for hold in (CHUNK, 2 * CHUNK, CHUNK // 2) for delay in (0, 2, 4, 6)
        ] + [[right] * CHUNK + [jump] * (2 * CHUNK), [jump] * (3 * CHUNK), [0] * (2 * CHUNK)]
        self.wait = len(self.patterns) - 1

    def _play(self, masks: list[int], frames: list[tuple[int, ...]], *, still: bool = False) -> bool:
        """Run the masks, recording them; return whether player 1 got further right without falling or dying."""
        before = self.reader.read()
        v = before
        for mask in masks:
            self.emu.run([mask, 0], 1)
            frames.append((mask,))
            v = self.reader.read()
            if v["level_done"]:
                return True
            if v["p1_state"] != 0 or v["p1_lives"] < before["p1_lives"] or v["p1_y"] > 192:  # below every floor: in a pit
                return False
        return still or v["p1_x"] > before["p1_x"]  # standing at a wall is no way forward

    def solve(self, max_nodes: int = 20_000) -> list[tuple[int, ...]]:
        """Search from the emulator's current state to the act's clear; return the frames of the way."""
        frames: list[tuple[int, ...]] = []
        # A position reached once (same place, speed, rings) is not searched again:
        # without this, every backtrack re-explores the same ground.
        seen: set[tuple[int, ...]] = set()
        stack = [[self.emu.get_state().pack(), 0, 0, 0]]  # state, next pattern, frames so far, waits
        for _ in range(max_nodes):
            if not stack:
                break
            node = stack[-1]
            state, index, length, waits = node
            if index == self.wait and waits >= MAX_WAITS:
                index = node[1] = index + 1
            if index >= len(self.patterns):
                stack.pop()  # its parent already moved on to its next pattern
                continue
            self.emu.set_state(state.unpack())
            del frames[length:]
            still = index == self.wait
            node[1] += 1
            if self._play(self.patterns[index], frames, still=still):
                v = self.reader.read()
                if v["level_done"]:
                    return frames
                key = (v["p1_x"], v["p1_y"], v["p1_vx"], v["p1_vy"], v["p1_rings"], v["p1_invuln"], v["frame"] if still else 0)
                if key not in seen:
                    seen.add(key)
                    stack.append([self.emu.get_state().pack(), 0, len(frames), waits + 1 if still else 0])
        raise RuntimeError(f"no way to clear the act found (reached x = {self.reader.read()['p1_x']})")


def solve(game, state: str) -> Movie:
    """Play the act from its state until it is cleared; return the movie of it."""
    start = load_state(game, game.state_path(state))
    with Emulator(game.system, game.require_rom()) as emu:
        emu.set_sticky(0.0, 0)
        emu.set_state(start)
        frames = BacktrackingAgent(emu, FieldReader(game.fields, emu.space)).solve()
    return Movie(game=game.name, system=game.system.name, players=1, state=start, frames=frames)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write-yaml", action="store_true", help="replace the movies: section of game.yaml")
    args = parser.parse_args()
    game = find_game("Dasher-Genesis")
    folder = game.folders[0] / MOVIES_FOLDER
    lines = ["movies:"]
    for state in ACTS:
        movie = solve(game, state)
        path = folder / f"{state}.bk2"
        write_bk2(path, movie, overwrite=True)
        outcome = replay(game, path)
        print(f"{state}: {len(movie.frames)} frames, done at {outcome.done_at}, reward {outcome.reward:g}")
        lines.append(f"  {state}: {{scenario: scenario, done_at: {outcome.done_at}, reward: {outcome.reward:g}, "
                     "tolerance: 0.001}")
    if args.write_yaml:
        yaml_path = game.folders[0] / "game.yaml"
        text = yaml_path.read_text()
        head = text.split("\nmovies:", 1)[0].rstrip("\n")
        marker = "# Solution movies (tools/record_dasher_solutions.py): the default scenario must say done\n" \
                 "# when the act is cleared, at this frame, with this total reward (progress + the 1000 bonus)."
        if marker not in head:
            head += "\n\n" + marker
        yaml_path.write_text(head + "\n" + "\n".join(lines) + "\n")
    else:
        print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
