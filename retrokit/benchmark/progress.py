"""How an evaluation shows its progress: a bar per level on a terminal, a line per level elsewhere.

Parallel progress bars redraw in place, which only a terminal can show: in a
log file or CI they become hundreds of lines of escapes. So when the output is
not a terminal, each level prints one line when it ends instead.
"""

from __future__ import annotations

import sys
from typing import Any


def is_terminal() -> bool:
    """Whether both stdout and stderr are terminals (the bars draw on stderr, the table on stdout)."""
    return sys.stdout.isatty() and sys.stderr.isatty()


class LevelProgress:
    """The progress of one evaluation's levels.

    Args:
        levels: Every level of the run, in order.
        budget: Timesteps per level.
        done_before: The levels a resumed run finished earlier.
        show: Show anything at all.
        bars: Draw bars (default: when :func:`is_terminal`); else print a line per level that ends.
    """

    def __init__(self, levels: list[str], budget: int, done_before: set[str], *, show: bool = True,
                 bars: bool | None = None) -> None:
        self.budget, self.show = budget, show
        self.total, self.ended = len(levels), len(done_before)
        self.bars: dict[str, Any] = {}
        if show and (is_terminal() if bars is None else bars):
            from tqdm import tqdm

            width = max(map(len, levels))
            for position, level in enumerate(levels):
                bar = tqdm(total=budget, desc=level.ljust(width), unit="step", position=position, leave=True,
                           dynamic_ncols=True, mininterval=0.5)
                if level in done_before:
                    bar.update(budget)
                    bar.set_postfix_str("done before")
                self.bars[level] = bar

    def step(self, level: str, timesteps: int) -> None:
        """``level`` has taken ``timesteps``."""
        if level in self.bars:
            self.bars[level].update(timesteps - self.bars[level].n)

    def restart(self, level: str, why: str) -> None:
        """``level`` plays again from its beginning, because of ``why``."""
        if level in self.bars:
            self.bars[level].reset()
            self.bars[level].set_postfix_str("restarted")
        elif self.show:
            print(f"{level}: {why}", flush=True)

    def end(self, level: str, outcome: str) -> None:
        """``level`` ended: ``outcome`` is ``done, score 12.3`` or ``failed: why``."""
        self.ended += 1
        if level in self.bars:
            if outcome.startswith("done"):
                self.bars[level].update(self.budget - self.bars[level].n)
            self.bars[level].set_postfix_str(outcome.split(":")[0])
        elif self.show:
            print(f"[{self.ended}/{self.total}] {level}: {outcome}", flush=True)

    def close(self) -> None:
        """Close the bars."""
        for bar in self.bars.values():
            bar.close()
