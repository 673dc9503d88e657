"""Watch: every field of the game with its live value, and editing a field's address, type and range.

Values are decoded by :class:`~retrokit.host.memory.FieldReader`, the reader
every env uses, so the page shows what an agent would get. A frame hook
pushes them to the page (``{"type": "fields", "frame", "values"}``) 20
times a second. An edit rewrites the field's line in the game's game.yaml through
:meth:`RamSearch.save_field` (the one game.yaml writer, with its checks and
its atomic write), then the session reads the game's fields again.

Routes (under ``/api``):

- ``GET /fields``: every field: name, address, type, range, value.
- ``PATCH /fields/{name}`` ``{"address"?, "type"?, "range"?}``: edit a field (``"range": null`` drops its range).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from starlette.requests import Request
from starlette.responses import JSONResponse
from starlette.routing import Route

from retrokit.errors import InvalidArgumentError
from retrokit.host.memory import FieldReader
from retrokit.studio.search import Pacer, save_field
from retrokit.studio.security import json_body, session_of

if TYPE_CHECKING:
    from retrokit.studio.session import Session


@dataclass
class _Reader:
    """The session's field reader, built again when the game's fields change."""

    game: Any = None
    reader: FieldReader | None = None
    pacer: Pacer = field(default_factory=Pacer)
    remove: Any = None


_readers: weakref.WeakKeyDictionary[Session, _Reader] = weakref.WeakKeyDictionary()


def field_reader(session: Session) -> FieldReader:
    """A reader of the session's game's fields, as an env reads them (emulator thread)."""
    entry = _readers.setdefault(session, _Reader())
    game = session.search.game
    if entry.game is not game or entry.reader is None or entry.reader.space is not session.search.emulator.space:
        entry.game, entry.reader = game, game.reader(session.search.emulator.space)
    if entry.remove is None:
        entry.remove = session.on_frame(_push)
    return entry.reader


def _push(session: Session) -> None:
    """Frame hook: push every field's value (20 times a second)."""
    if not _readers[session].pacer.ready(session):
        return
    session.publish({"type": "fields", "frame": session.frame, "values": field_reader(session).read()})


def _fields(session: Session) -> dict[str, Any]:
    search = session.search
    values = field_reader(session).read()
    rows = [
        {
            "name": spec.name,
            "address": spec.address,
            "hex": search.layout.format(spec.address),
            "type": spec.type,
            "range": list(spec.range) if spec.range else None,
            "mask": spec.mask,
            "value": values[spec.name],
        }
        for spec in search.game.fields.values()
    ]
    return {"game": search.game.name, "frame": session.frame, "fields": rows}


def _edit(session: Session, name: str, changes: dict[str, Any]) -> dict[str, Any]:
    spec = field_reader(session).spec(name)  # an unknown name: FieldNotFoundError, with a did-you-mean
    if spec.mask is not None:
        raise InvalidArgumentError(
            f"Expected a field without a mask to edit here; {name!r} has mask {spec.mask:#x}, which the studio does "
            "not write. Edit its line in game.yaml by hand."
        )
    value_range = changes["range"] if "range" in changes else (list(spec.range) if spec.range else None)
    return save_field(
        session, name, changes.get("address", spec.address), changes.get("type", spec.type), value_range, True
    )


async def fields(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_fields))


async def edit(request: Request) -> JSONResponse:
    name = request.path_params["name"]
    body = await json_body(request)
    changes = {key: body[key] for key in ("address", "type", "range") if key in body}
    if not changes or len(changes) != len(body):
        raise InvalidArgumentError(
            f"Expected one or more of address, type and range to change; got {', '.join(body) or 'none'}."
        )
    return JSONResponse(await session_of(request).call(_edit, name, changes))


routes = [
    Route("/fields", fields, methods=["GET"]),
    Route("/fields/{name}", edit, methods=["PATCH"]),
]
