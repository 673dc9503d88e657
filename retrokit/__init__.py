"""retrokit: emulated console games as reinforcement-learning environments."""

from __future__ import annotations

__version__ = "0.1.0"
