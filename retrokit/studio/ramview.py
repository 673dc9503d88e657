"""RAM view: a grid of a RAM region's bytes, live, with what changed.

The region is given in console addresses and read as the RAM search reads
it (:class:`~retrokit.ramsearch.ram.RamLayout`: console byte order, whatever
the core's), so a cell shows what the console's CPU sees. While a region is
watched, a frame hook compares it with the frame before and pushes
``{"type": "ram", "start", "frame", "values", "changed", "differs"}`` 20
times a second: ``changed`` lists the offsets that changed in any frame since the
last push, ``differs`` those that differ from the chosen snapshot of the RAM
search (``null`` without one).

Routes (under ``/api``):

- ``GET /ram?start=ADDRESS&length=N&snapshot=K``: the region's bytes now, and the same lists.
- ``POST /ram/watch`` ``{"start", "length", "snapshot"?}``: push the region live; ``DELETE /ram/watch`` stops.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from starlette.requests import Request
from starlette.responses import JSONResponse
from starlette.routing import Route

from retrokit.errors import RamSearchError
from retrokit.studio.search import Pacer, address_of, integer_of
from retrokit.studio.security import json_body, session_of

if TYPE_CHECKING:
    from retrokit.studio.session import Session

MAX_LENGTH = 4096
"""The most bytes a view shows: 256 rows of 16, more than a page can draw live."""


@dataclass
class _View:
    """A region of RAM watched frame by frame."""

    start: int
    length: int
    position: int  # where the region starts in a RamLayout snapshot
    buffer: int  # which of the core's memory buffers holds it
    offsets: np.ndarray  # the buffer offset of each byte, in console order
    snapshot: int | None
    search: Any
    last: np.ndarray  # the bytes after the newest frame
    before: np.ndarray  # and after the frame before it
    changed: np.ndarray  # which changed in any frame since the last push
    pacer: Pacer = field(default_factory=Pacer)
    remove: Any = None


_views: weakref.WeakKeyDictionary[Session, _View] = weakref.WeakKeyDictionary()


def _region(session: Session, start: object, length: object, snapshot: object) -> tuple[int, int, int, int | None]:
    """The region's start, length, snapshot position, and snapshot index, checked (emulator thread).

    Raises:
        InvalidArgumentError: It is not inside one RAM region, or too long.
        RamSearchError: The snapshot does not exist.
    """
    search = session.search
    begin = address_of(start, "start")
    count = integer_of(length, "length", 1, MAX_LENGTH)
    position = search.layout.position(begin, count)
    index = None
    if snapshot is not None:
        taken = len(search.engine.snapshots)
        index = integer_of(snapshot, "snapshot", 0, None)
        if index >= taken:
            raise RamSearchError(
                f"Expected a snapshot from 0 to {taken - 1} of the RAM search; got {index}. Take one first."
            )
    return begin, count, position, index


def _where(session: Session, start: int, length: int) -> tuple[int, np.ndarray]:
    """The buffer holding a region, and the offset of each of its bytes there (in console order)."""
    index, offsets = session.search.emulator.space.offsets(start, length)
    return index, np.array(offsets, dtype=np.intp)


def _bytes(session: Session, buffer: int, offsets: np.ndarray) -> np.ndarray:
    """The region's bytes now: only those (the whole RAM's console-order copy costs half a frame)."""
    return np.frombuffer(session.search.emulator.space.buffers[buffer], dtype=np.uint8)[offsets]


def _differs(session: Session, view: _View, now: np.ndarray, snapshot: int | None) -> list[int] | None:
    if snapshot is None or snapshot >= len(session.search.engine.snapshots):  # a new search has fewer
        return None
    then = session.search.engine.snapshots[snapshot][view.position : view.position + view.length]
    return np.flatnonzero(then != now).tolist()


def _report(
    session: Session, view: _View, now: np.ndarray, changed: np.ndarray, snapshot: int | None
) -> dict[str, Any]:
    return {
        "type": "ram",
        "start": view.start,
        "hex": session.search.layout.format(view.start),
        "length": view.length,
        "frame": session.frame,
        "snapshot": snapshot,
        "values": now.tolist(),
        "changed": np.flatnonzero(changed).tolist(),
        "differs": _differs(session, view, now, snapshot),
    }


def _on_frame(session: Session) -> None:
    """Frame hook: note what changed since the frame before; push every few frames."""
    view = _views.get(session)
    if view is None or view.search is not session.search:
        return
    now = _bytes(session, view.buffer, view.offsets)
    view.changed |= now != view.last
    view.before, view.last = view.last, now
    if view.pacer.ready(session):
        session.publish(_report(session, view, now, view.changed, view.snapshot))
        view.changed[:] = False


def _view(session: Session, start: object, length: object, snapshot: object, watch: bool) -> dict[str, Any]:
    """The region now; with ``watch``, watched from now on. ``changed``: what the last frame changed."""
    begin, count, position, index = _region(session, start, length, snapshot)
    buffer, offsets = _where(session, begin, count)
    now = _bytes(session, buffer, offsets)
    old = _views.get(session)
    same = old is not None and old.search is session.search and (old.start, old.length) == (begin, count)
    if same:  # the hook saw the frames: what the last one changed (and any poke since)
        view = old
        changed = now != view.before
        if watch:
            view.snapshot = index
    else:  # no frame seen yet: nothing known to have changed
        view = _View(begin, count, position, buffer, offsets, index, session.search, now, now,
                     np.zeros(count, dtype=bool), remove=old.remove if old is not None else None)
        changed = view.changed
    if watch and not same:
        _views[session] = view
    if watch and view.remove is None:
        view.remove = session.on_frame(_on_frame)
    return _report(session, view, now, changed, index)


def _unwatch(session: Session) -> dict[str, Any]:
    view = _views.pop(session, None)
    if view is not None and view.remove is not None:
        view.remove()
    return {"watching": False}


async def ram(request: Request) -> JSONResponse:
    query = request.query_params
    start, length = query.get("start"), query.get("length", "256")
    result = await session_of(request).call(_view, start, length, query.get("snapshot"), False)
    return JSONResponse(result)


async def watch(request: Request) -> JSONResponse:
    body = await json_body(request)
    result = await session_of(request).call(
        _view, body.get("start"), body.get("length", 256), body.get("snapshot"), True
    )
    return JSONResponse(result)


async def unwatch(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_unwatch))


routes = [
    Route("/ram", ram, methods=["GET"]),
    Route("/ram/watch", watch, methods=["POST"]),
    Route("/ram/watch", unwatch, methods=["DELETE"]),
]
