"""The data layer: games on disk, and every file of theirs that retrokit reads or writes.

Above the host layer (systems, type codes, the emulator for probes), below the
scenario language and the envs. One module a concern:

- ``games``: finding a game's folders (``RETROKIT_GAMES``, the user's data,
  ``games/``, stable-retro's wheel) and its states, scenarios and ROM.
- ``gamefiles``: reading ``game.yaml`` (or Gym Retro's ``data.json``,
  ``metadata.json``, ``rom.sha``) into a :class:`~retrokit.data.gamefiles.GameInfo`.
- ``yamlfile``: the one YAML reader (a size cap, FIFOs and devices refused,
  aliases capped, duplicate keys refused); ``schema`` (with ``schemas/``): the
  JSON Schemas of game.yaml and scenario files, and checking files against them.
- ``states``: ``.state`` files and the record retrokit writes in them;
  ``names``: the one check of a state's name; ``statecheck``: whether a state
  may be loaded in this process; ``probe``: trying an unseen state in a child.
- ``roms``: a ROM's SHA-1 and stored form; ``importer``: ``retrokit import``.
- ``integrate``: making and checking save states from game.yaml's recipes.
- ``sonic_levels``: the levels of the Sonic benchmark.
"""
