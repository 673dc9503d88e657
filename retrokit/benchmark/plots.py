"""The PNG plots, drawn with matplotlib.

The object API is used (no pyplot), so drawing changes no global state and
needs no display. The margins are fixed in inches (the level names' width
estimated from their length) rather than found by matplotlib's constrained
layout, which measured every label's box and took about as long as the drawing.
"""

from __future__ import annotations

import io
import math

from retrokit.benchmark.monitor import Episode

#: Inches a character of a tick label takes at font size 8 (DejaVu Sans averages about 0.53 em; a little more).
_CHAR_INCHES = 8 * 0.56 / 72


def _figure(width: float, height: float, *, left: float, bottom: float, top: float, right: float = 0.25,
            gaps: tuple[float, float] = (0.0, 0.0)):  # a matplotlib Figure
    """A figure whose margins and gaps between panels (across, down) are the given inches."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=100)
    FigureCanvasAgg(figure)
    figure.subplotpars.update(left=left / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height)
    figure.subplotpars.update(wspace=gaps[0] / 4.2, hspace=gaps[1] / 3.0)  # in units of a panel's size
    return figure


def _png(figure) -> bytes:  # a matplotlib Figure
    out = io.BytesIO()
    figure.savefig(out, format="png")
    return out.getvalue()


def _smooth(values: list[float], window: int) -> list[float]:
    """The running mean of the last ``window`` values at each point."""
    out, total = [], 0.0
    for i, value in enumerate(values):
        total += value
        if i >= window:
            total -= values[i - window]
        out.append(total / min(i + 1, window))
    return out


def learning_curves(episodes: dict[str, list[Episode]], budget: int, title: str) -> bytes:
    """One panel per level: each episode's reward at the timestep it ended, and their running mean.

    The paper's figures draw the same: episode reward against timesteps.
    """
    levels = list(episodes)
    columns = min(3, max(1, len(levels)))
    rows = max(1, math.ceil(len(levels) / columns))
    figure = _figure(4.2 * columns, 3.0 * rows + 0.4, left=0.7, bottom=0.5, top=0.75, gaps=(0.8, 0.8))
    figure.suptitle(title)
    for i, level in enumerate(levels):
        axes = figure.add_subplot(rows, columns, i + 1)
        records = sorted(episodes[level], key=lambda e: e.episode)
        x = [e.timesteps for e in records]
        y = [e.reward for e in records]
        # Markers on a line without its segments: drawn as one path, a little cheaper than a scatter's collection.
        axes.plot(x, y, linestyle="none", marker="o", markersize=2.5, alpha=0.35, color="tab:blue", label="episode")
        if records:
            axes.plot(x, _smooth(y, max(1, len(y) // 10)), color="tab:red", linewidth=1.5, label="running mean")
        axes.set_title(level, fontsize=9)
        axes.set_xlim(0, budget)
        axes.set_xlabel("timesteps", fontsize=8)
        axes.set_ylabel("episode reward", fontsize=8)
        axes.tick_params(labelsize=7)
        axes.grid(alpha=0.3)
        if i == 0 and records:
            axes.legend(fontsize=7, loc="lower right")
    return _png(figure)


def mean_learning_curve(curves: dict[str, dict[str, list]], budget: int, title: str) -> bytes:
    """The paper's Figure 3: each run's instantaneous score against timesteps, averaged over its levels.

    Args:
        curves: ``{label: Summary.curve}``: one line each (an agent, or one run).
        budget: The timesteps per level (the x axis).
        title: The figure's title (a subtitle says what is drawn).
    """
    figure = _figure(6.4, 4.0, left=0.8, bottom=0.55, top=0.6)
    axes = figure.add_subplot(1, 1, 1)
    for label, curve in curves.items():
        points = [(t, s) for t, s in zip(curve["timesteps"], curve["score"], strict=True) if s is not None]
        axes.plot([t for t, _ in points], [s for _, s in points], marker="." if len(points) < 3 else None,
                  linewidth=1.6, label=label)
    figure.suptitle(title, fontsize=10)
    axes.set_title("the mean reward of the episodes that ended in the last 10% of the budget, averaged over levels",
                   fontsize=7)
    axes.set_xlim(0, budget)
    axes.set_xlabel("timesteps", fontsize=8)
    axes.set_ylabel("instantaneous score", fontsize=8)
    axes.tick_params(labelsize=7)
    axes.grid(alpha=0.3)
    if curves:
        axes.legend(fontsize=7, loc="lower right")
    return _png(figure)


def score_bars(series: dict[str, dict[str, float | None]], levels: list[str], title: str) -> bytes:
    """Per-level scores as grouped horizontal bars, one colour per series (an agent, or the paper's)."""
    height = 1.0 + 0.28 * len(levels) * max(1, len(series)) + 0.6
    names = max((len(level) for level in levels), default=0) * _CHAR_INCHES
    figure = _figure(8.0, max(3.0, height), left=0.2 + names, bottom=0.55, top=0.4)
    axes = figure.add_subplot(1, 1, 1)
    band = 0.8 / max(1, len(series))
    for k, (label, scores) in enumerate(series.items()):
        ys = [i + (k - (len(series) - 1) / 2) * band for i in range(len(levels))]
        values = [scores.get(level) for level in levels]
        bars = axes.barh(ys, [v or 0.0 for v in values], height=band, label=label)
        for bar, value in zip(bars, values, strict=True):
            text = "–" if value is None else f"{value:,.0f}"
            axes.annotate(text, (bar.get_width(), bar.get_y() + bar.get_height() / 2), xytext=(3, 0),
                          textcoords="offset points", va="center", fontsize=7)
    axes.set_yticks(range(len(levels)), levels, fontsize=8)
    axes.invert_yaxis()
    axes.set_xlabel("mean episode reward (score)")
    axes.set_title(title)
    axes.grid(axis="x", alpha=0.3)
    axes.margins(x=0.12)
    axes.legend(fontsize=8, loc="lower right")
    return _png(figure)
