"""RAM search routes: the session's :class:`~retrokit.ramsearch.RamSearch`, over HTTP.

Every move goes through ``session.call``, so it runs on the emulator thread
between frames, and through the same :class:`RamSearch` methods as
``retrokit ramsearch``: the filters (every operation, type, ``than`` and
scale), snapshots, undo and redo, poke, and ``save_field`` (the one game.yaml
writer, range included). The candidate table lists groups of candidates as
``ramsearch show`` does; the rows listed last are watched, and their live
values are pushed to the page (``{"type": "candidates", ...}``) 20 times a second.

Routes (under ``/api``):

- ``GET /search``: count, snapshots, filters applied, types, whether undo/redo can.
- ``POST /search/new`` ``{"types"?}``: start afresh from the game's moment now.
- ``POST /search/snapshot`` ``{"label"?}``; ``POST /search/filter`` ``{"op", "value"?, "than"?}``.
- ``POST /search/undo``, ``POST /search/redo``.
- ``GET /search/candidates?limit=N``: groups of candidates, with values per snapshot and live.
- ``POST /search/poke`` ``{"address", "value", "type"?}``.
- ``POST /search/field`` ``{"name", "address", "type", "range"?, "force"?}``: add a field to game.yaml.
- ``POST /search/find`` ``{"name", "changes", "keeps", "kind"?, "value"?, "save"?, "range"?, "force"?}``: play
  both scripts in turn, filtering after each, until one value is left (:func:`~retrokit.ramsearch.find.find_field`,
  as ``ramsearch find``); with ``save``, add it as a field. The game waits while the scripts play.

This module also holds the number helpers the other tool modules share:
:func:`integer_of` and :func:`address_of` (JSON numbers, or hex text as the game files write addresses).
"""

from __future__ import annotations

import time
import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from starlette.requests import Request
from starlette.responses import JSONResponse
from starlette.routing import Route

from retrokit.data.script import parse_script, script_frames
from retrokit.errors import InvalidArgumentError, RamSearchError, shown
from retrokit.ramsearch.candidates import Candidate, list_groups
from retrokit.ramsearch.filters import OPS, THAN_FORMS
from retrokit.ramsearch.find import MAX_ROUNDS, find_field
from retrokit.ramsearch.gamefile import check_field_name
from retrokit.studio.security import check_inside, expect, game_roots, json_body, session_of

if TYPE_CHECKING:
    from retrokit.studio.session import Session

MAX_ROWS = 100
"""The most candidate groups one listing returns (and whose live values are pushed): a listing fetches up to
256 candidates a group, each with its value at every snapshot, on the emulator thread."""
MAX_SNAPSHOTS = 64
"""The most snapshots one search of the studio takes: with 100 rows listed, a listing then peaks under 200 MB
(at 256 snapshots it took 750 MB for 500 rows). A new search starts again from one."""
MAX_FIND_FRAMES = 36_000
"""The most frames one round of a find plays in the studio (both scripts: ten minutes of play at 60 a second):
the game, and every request to it, waits while they run."""
PUSH_PERIOD = 0.05
"""Seconds between two pushes of a tool's live values: 20 a second, whatever the game's speed."""


@dataclass
class Pacer:
    """When a frame hook pushes its live values: every :data:`PUSH_PERIOD`, and after each frame advanced by hand.

    A paused game moves a frame at a time at the user's request: each of those frames is shown.
    """

    due: float = 0.0

    def ready(self, session: Session) -> bool:
        """Whether to push after this frame."""
        now = time.monotonic()
        if now < self.due and not session.paused:
            return False
        self.due = now + PUSH_PERIOD
        return True


def integer_of(value: object, what: str, low: int | None = None, high: int | None = None) -> int:
    """A whole number given as JSON (a number, or text such as ``"0x2B"``), within ``[low, high]``.

    Raises:
        InvalidArgumentError: It is not a whole number, or out of range.
    """
    number = value
    if isinstance(value, str) and len(value) <= 40:
        try:
            number = int(value, 0)
        except ValueError:
            pass
    if not isinstance(number, int) or isinstance(number, bool):
        raise InvalidArgumentError(f"Expected {what} as a whole number (decimal, or hex as 0xFF002B); got {shown(value)}.")
    if low is not None and number < low or high is not None and number > high:
        bounds = f"from {low} to {high}" if high is not None else f"of {low} or more"
        raise InvalidArgumentError(f"Expected {what} {bounds}; got {number}.")
    return number


def address_of(value: object, what: str = "address") -> int:
    """A console address given as JSON: a number, or hex text such as ``"0xFF002B"``."""
    return integer_of(value, what, 0, (1 << 48) - 1)


def _than(value: object) -> str | int | None:
    """``than`` as :meth:`RamSearch.filter` takes it: hex text is an address, digits a snapshot's number."""
    if value is None or isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return None if value is None else str(value)
    if isinstance(value, str) and value.lower().startswith("0x"):
        return address_of(value, "than")
    if isinstance(value, str):
        return value
    raise InvalidArgumentError(f"Expected than as {THAN_FORMS}; got {shown(value)}.")


@dataclass
class _Watch:
    """The candidate rows a page shows, whose live values are pushed."""

    rows: list[tuple[int, str]] = field(default_factory=list)  # (address, type)
    search: Any = None  # the RamSearch they were listed from (a new game lists afresh)
    pacer: Pacer = field(default_factory=Pacer)
    remove: Any = None


_watches: weakref.WeakKeyDictionary[Session, _Watch] = weakref.WeakKeyDictionary()


def _push_live(session: Session) -> None:
    """Frame hook: push the watched rows' values (20 times a second)."""
    watch = _watches.get(session)
    if watch is None or not watch.rows or watch.search is not session.search or not watch.pacer.ready(session):
        return
    space = session.search.emulator.space
    values = [[address, code, space.peek(address, code)] for address, code in watch.rows]
    session.publish({"type": "candidates", "frame": session.frame, "values": values})


def _status(session: Session) -> dict[str, Any]:
    search = session.search
    return {
        "count": search.count,
        "snapshots": list(search.labels),
        "history": search.history,
        "types": list(search.types),
        "can_undo": bool(search.engine.history),
        "can_redo": bool(search.engine.redo_stack),
        "ops": list(OPS),
    }


def _row(session: Session, group: list[Candidate]) -> dict[str, Any]:
    first = group[0]
    return {
        "address": first.address,
        "hex": session.search.layout.format(first.address),
        "type": first.type,
        "also": [c.type for c in group[1:]],
        "values": list(first.values),
        "value": session.search.emulator.space.peek(first.address, first.type),
        "scale": first.scale,
        "scales": list(first.scales),
        "changes": first.changes,
    }


def _candidates(session: Session, limit: int) -> dict[str, Any]:
    search = session.search
    groups = list_groups(search.count, search.candidates, limit, len(search.types))
    rows = [_row(session, g) for g in groups.groups]
    watch = _watches.setdefault(session, _Watch())
    watch.rows, watch.search = [(r["address"], r["type"]) for r in rows], search
    if watch.remove is None:
        watch.remove = session.on_frame(_push_live)
    return {"total": groups.total, "groups": groups.count, "more": groups.more, "rows": rows}


def _filter(session: Session, op: str, value: object, than: object) -> dict[str, Any]:
    number = None if value is None else integer_of(value, "the filter's number")
    before = session.search.count
    session.search.filter(op, number, _than(than))
    return {"before": before, "filter": session.search.history[-1], **_status(session)}


def _snapshot(session: Session, label: str) -> dict[str, Any]:
    if len(label) > 200:
        raise InvalidArgumentError(f"Expected a snapshot label of at most 200 characters; got {shown(label)}.")
    if len(session.search.labels) >= MAX_SNAPSHOTS:
        raise RamSearchError(
            f"Expected at most {MAX_SNAPSHOTS} snapshots in one search; this one has them all. Filter with what "
            "you have, or start a new search (POST /api/search/new) from the game now."
        )
    index = session.search.snapshot(label)
    return {"snapshot": index, **_status(session)}


def _poke(session: Session, address: int | str, value: int | str, type_code: str) -> dict[str, Any]:
    where = address_of(address)
    session.search.poke(where, integer_of(value, "the value to poke"), type_code)
    return {"address": where, "type": type_code, "value": session.search.emulator.space.peek(where, type_code)}


def save_field(session: Session, name: object, address: object, type_code: object, value_range: object, force: bool) -> dict:
    """Write a field into the game's game.yaml through :meth:`RamSearch.save_field`, then reload the game's fields."""
    if not isinstance(type_code, str):
        raise InvalidArgumentError(f"Expected a type code such as \"|u1\"; got {shown(type_code)}.")
    if value_range is not None:
        if not isinstance(value_range, list) or len(value_range) != 2:
            raise InvalidArgumentError(f"Expected range as [LO, HI]; got {shown(value_range)}.")
        value_range = tuple(integer_of(v, "range") for v in value_range)
    search = session.search
    where = address_of(address)
    check_inside(search.default_game_file(), game_roots(search.game), what="game.yaml")  # not a planted link
    path = search.save_field(name, where, type_code, force=force, value_range=value_range)
    search.reload_game()
    spec = search.game.fields[name]
    return {"name": name, "address": spec.address, "hex": search.layout.format(spec.address), "type": spec.type,
            "range": list(spec.range) if spec.range else None, "path": str(path)}


def _find(session: Session, body: dict[str, Any]) -> dict[str, Any]:
    """Run :func:`find_field` from the game now; say what it left, and add the field found if asked."""
    search = session.search
    changes, keeps = expect(body, "changes", str), expect(body, "keeps", str)
    kind, value = expect(body, "kind", str, "changes"), body.get("value")
    value = None if value is None else integer_of(value, "the number it becomes")
    save, force, value_range = expect(body, "save", bool, False), expect(body, "force", bool, False), body.get("range")
    name = expect(body, "name", str) if save else None
    if save:
        check_field_name(name)  # before anything plays: a find is not played twice for a typo
    rounds = min(MAX_ROUNDS, (MAX_SNAPSHOTS - len(search.labels)) // 2)
    if rounds < 1:
        raise RamSearchError(
            f"Expected room for two snapshots a round; this search has {len(search.labels)} of its {MAX_SNAPSHOTS}. "
            "Start a new search (POST /api/search/new) from the game now."
        )
    per_round = sum(script_frames(parse_script(script, search.buttons)) for script in (changes, keeps))
    if per_round > MAX_FIND_FRAMES:
        raise InvalidArgumentError(
            f"Expected scripts of at most {MAX_FIND_FRAMES:,} frames together in the studio; got {per_round:,}. "
            "Play longer ones with `retrokit ramsearch find`."
        )
    finding = find_field(search, changes, keeps, kind, value, rounds=rounds)
    session.frame += finding.frames  # the game moved on by them, all at once: the page sees where it is now
    session.send_screen()
    session.publish(session.status())
    answer = {"found": finding.found, "reason": finding.reason, "left": finding.count, "steps": finding.steps,
              "frames": finding.frames, "rows": [_row(session, g) for g in finding.groups], **_status(session)}  # fmt: skip
    if finding.found and save:
        found = finding.candidate
        answer["field"] = save_field(session, name, found.address, found.type, value_range, force)
    return answer


async def find(request: Request) -> JSONResponse:
    body = await json_body(request)
    return JSONResponse(await session_of(request).call(_find, body))


async def status(request: Request) -> JSONResponse:
    return JSONResponse(await session_of(request).call(_status))


async def new(request: Request) -> JSONResponse:
    types = expect(await json_body(request), "types", list, None)
    if types is not None and not all(isinstance(t, str) for t in types):
        raise InvalidArgumentError(f'Expected types as a list of type codes such as ["|u1", ">u2"]; got {shown(types)}.')

    def restart(session: Session) -> dict[str, Any]:
        session.search.new_search(types)
        return _status(session)

    return JSONResponse(await session_of(request).call(restart))


async def snapshot(request: Request) -> JSONResponse:
    label = expect(await json_body(request), "label", str, "snapshot")
    return JSONResponse(await session_of(request).call(_snapshot, label))


async def filter_(request: Request) -> JSONResponse:
    body = await json_body(request)
    op = expect(body, "op", str)
    return JSONResponse(await session_of(request).call(_filter, op, body.get("value"), body.get("than")))


async def undo(request: Request) -> JSONResponse:
    def step(session: Session) -> dict[str, Any]:
        return {"undone": session.search.undo(), **_status(session)}

    return JSONResponse(await session_of(request).call(step))


async def redo(request: Request) -> JSONResponse:
    def step(session: Session) -> dict[str, Any]:
        return {"redone": session.search.redo(), **_status(session)}

    return JSONResponse(await session_of(request).call(step))


async def candidates(request: Request) -> JSONResponse:
    limit = integer_of(request.query_params.get("limit", "100"), "limit", 1, MAX_ROWS)
    return JSONResponse(await session_of(request).call(_candidates, limit))


async def poke(request: Request) -> JSONResponse:
    body = await json_body(request)
    address, value = expect(body, "address", (int, str)), expect(body, "value", (int, str))
    type_code = expect(body, "type", str, "|u1")
    return JSONResponse(await session_of(request).call(_poke, address, value, type_code))


async def add_field(request: Request) -> JSONResponse:
    body = await json_body(request)
    name, address, type_code = expect(body, "name", str), expect(body, "address", (int, str)), expect(body, "type", str)
    value_range, force = expect(body, "range", list, None), expect(body, "force", bool, False)
    result = await session_of(request).call(save_field, name, address, type_code, value_range, force)
    return JSONResponse(result)


routes = [
    Route("/search", status, methods=["GET"]),
    Route("/search/new", new, methods=["POST"]),
    Route("/search/snapshot", snapshot, methods=["POST"]),
    Route("/search/filter", filter_, methods=["POST"]),
    Route("/search/undo", undo, methods=["POST"]),
    Route("/search/redo", redo, methods=["POST"]),
    Route("/search/candidates", candidates, methods=["GET"]),
    Route("/search/poke", poke, methods=["POST"]),
    Route("/search/field", add_field, methods=["POST"]),
    Route("/search/find", find, methods=["POST"]),
]
