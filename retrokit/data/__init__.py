"""The data layer: games, their files, states and ROMs, on disk.

- ``games``: finding a game's folders (``games/``, the user's data, stable-retro's wheel).
- ``gamefiles``: reading ``game.yaml`` (or Gym Retro's JSON) into plain data.
- ``states``: reading and writing ``.state`` files.
- ``roms``: hashing and grooming ROM files.
- ``importer``: ``retrokit import``, ROMs found by SHA-1.
- ``integrate``: making and checking save states from recipes.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.data.<module>
