"""The data layer: games on disk, and every file of theirs that retrokit reads or writes.

Above the host layer (systems, type codes, the emulator for probes), below the
scenario language and the envs. One module a concern:

- ``games``: the one answer to "which game" (``find_game``: a name, a folder or a
  Game), and a game's folders (``RETROKIT_GAMES``, the user's data, ``games/``,
  stable-retro's wheel), states, scenarios and ROM.
- ``resolve``: what ``make(game, state, scenario)`` means, found once: game, ROM,
  checked state, scenario.
- ``gamefiles``: reading ``game.yaml`` (or Gym Retro's ``data.json``,
  ``metadata.json``, ``rom.sha``) into a :class:`~retrokit.data.gamefiles.GameInfo`.
- ``yamlfile``: the one YAML reader (a size cap, FIFOs and devices refused,
  aliases capped, duplicate keys refused); ``schema`` (with ``schemas/``): the
  JSON Schemas of game.yaml and scenario files, and checking files against them.
- ``states``: reading and writing ``.state`` files; ``names``: the one check of a
  state's name; ``statecheck``: the one checked load of a state; ``probe``: trust
  (this machine's records, the shipped hashes of ``shipped``) and the crash probe
  in a child process.
- ``roms``: a ROM's SHA-1 and stored form; ``importer``: ``retrokit import``.
- ``integrate``: making and checking save states from game.yaml's recipes.
- ``sonic_levels``: the levels of the Sonic benchmark.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.data.<module>
