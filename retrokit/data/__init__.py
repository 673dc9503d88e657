"""The data layer: games, their files, states and ROMs, on disk.

- ``games``: the one answer to "which game" (``find_game``: a name or a folder), and a game's folders.
- ``resolve``: what ``make(game, state, scenario)`` means, found once: game, ROM, checked state, scenario.
- ``gamefiles``: reading ``game.yaml`` (or Gym Retro's JSON) into plain data.
- ``states``: reading and writing ``.state`` files; ``names``: what a state's name may be.
- ``statecheck``: the one checked load of a state; ``probe``: trust (this machine's records,
  the shipped hashes of ``shipped``) and the crash probe in a child process.
- ``roms``: hashing and grooming ROM files.
- ``importer``: ``retrokit import``, ROMs found by SHA-1.
- ``integrate``: making and checking save states from recipes.
"""
