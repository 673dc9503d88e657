"""The studio: a game's integration tools in a browser page, served by ``retrokit studio``.

One :class:`~retrokit.studio.session.Session` (an emulator thread around a
:class:`~retrokit.ramsearch.RamSearch`) behind a Starlette application
(:mod:`retrokit.studio.app`) whose routes each tool module provides. The
JSON/WebSocket API is documented in docs/studio-api.md.
"""
