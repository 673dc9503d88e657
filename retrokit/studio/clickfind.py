"""Click to find: the RAM cells whose poke changes a pixel of the screen.

OCAtari's REM GUI finds what draws a pixel of an Atari game by poking each of
its 128 bytes and comparing frames. A Genesis has 64 KiB, so the search runs
over a region the user picks (the RAM search's current candidates, or an
address range) and is capped at :data:`MAX_CELLS` cells.

It never disturbs the game: the moment clicked is kept as an emulator state
(``base``); each try loads it, pokes one byte (``value + 1``, then
``value ^ 0xFF``), runs :data:`FRAMES` frames with no buttons held and reads
the pixel; after each chunk of tries the state the game had is loaded back.
The work runs on the emulator thread in chunks of about :data:`CHUNK_SECONDS`,
so the game's own frames go on between them; the job reports its progress
over the socket (``{"type": "clickfind", ...}``) and can be cancelled.

Routes (under ``/api``):

- ``POST /clickfind`` ``{"x", "y", "region", "frames"?}``: start a job (one per
  session: a new one cancels the old); ``region`` is ``"candidates"`` or
  ``{"start": ADDRESS, "length": N}``.
- ``GET /clickfind``: the job's progress and the cells found so far.
- ``POST /clickfind/cancel``: stop it.
"""

from __future__ import annotations

import asyncio
import itertools
import time
import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from starlette.requests import Request
from starlette.responses import JSONResponse
from starlette.routing import Route

from retrokit.errors import InvalidArgumentError, RamSearchError, RetrokitError
from retrokit.ramsearch.types import search_type
from retrokit.studio.search import address_of, integer_of
from retrokit.studio.security import json_body, session_of

if TYPE_CHECKING:
    from retrokit.studio.session import Session

MAX_CELLS = 8192
"""The most cells one job pokes: two tries of ~3 ms each per cell, about a minute at most."""
FRAMES = 2
"""Frames run after a poke: a sprite table built in a frame reaches the screen in the next one."""
MAX_FRAMES = 8
CHUNK_SECONDS = 0.03
"""Work done per visit to the emulator thread, so the game's frames and other requests go on between."""
_IDS = itertools.count(1)


@dataclass
class Job:
    """One click-to-find search: where, over which cells, and what it found so far."""

    id: int
    search: Any  # the RamSearch clicked: a job ends if the session plays another game
    x: int
    y: int
    frames: int
    addresses: list[int]
    base: bytes = b""
    base_ram: dict[int, int] = field(default_factory=dict)
    color: tuple[int, ...] = ()
    done: int = 0
    hits: list[dict[str, Any]] = field(default_factory=list)
    cancelled: bool = False
    error: str | None = None
    seconds: float = 0.0
    task: asyncio.Task | None = None  # the coroutine driving it, kept so it is not garbage-collected

    @property
    def finished(self) -> bool:
        return self.cancelled or self.error is not None or self.done >= len(self.addresses)

    def report(self) -> dict[str, Any]:
        """The job as the API shows it."""
        return {
            "type": "clickfind",
            "id": self.id,
            "x": self.x,
            "y": self.y,
            "color": list(self.color),
            "done": self.done,
            "total": len(self.addresses),
            "finished": self.finished,
            "cancelled": self.cancelled,
            "error": self.error,
            "seconds": round(self.seconds, 3),
            "hits": list(self.hits),
        }


_jobs: weakref.WeakKeyDictionary[Session, Job] = weakref.WeakKeyDictionary()  # each session's newest job


def _cells(session: Session, region: object) -> list[int]:
    """The byte addresses a job pokes (on the emulator thread: the candidates live there).

    Raises:
        InvalidArgumentError: The region is malformed, outside RAM, or over :data:`MAX_CELLS` cells.
        RamSearchError: ``"candidates"`` with none left.
    """
    search = session.search
    if region == "candidates":
        count = search.count
        if count == 0:
            raise RamSearchError("Expected candidates to poke; the search has none left. Start a new search.")
        cells: set[int] = set()
        for candidate in search.candidates(limit=MAX_CELLS + 1):
            cells.update(range(candidate.address, candidate.address + search_type(candidate.type).width))
            if len(cells) > MAX_CELLS:
                break
        what = f"the {count:,} candidates cover more than {MAX_CELLS:,} bytes"
        addresses = sorted(cells)
    elif isinstance(region, dict) and set(region) <= {"start", "length"} and "start" in region:
        start = address_of(region["start"], "region start")
        length = integer_of(region.get("length", 1), "region length", 1, 1 << 24)
        what = f"a region of {length:,} bytes"
        search.layout.position(start, min(length, MAX_CELLS + 1))  # inside one RAM region, or a clear error
        addresses = list(range(start, start + min(length, MAX_CELLS + 1)))
    else:
        raise InvalidArgumentError(
            'Expected the region as "candidates" or {"start": ADDRESS, "length": N}; got '
            f"{str(region)[:60]!r}."
        )
    if len(addresses) > MAX_CELLS:
        raise InvalidArgumentError(
            f"Expected at most {MAX_CELLS:,} cells to poke; {what}. Narrow the candidates, or pick a smaller region."
        )
    return addresses


def _pixel(emulator: Any, job: Job) -> tuple[int, ...]:
    emulator.run(0, job.frames)
    return tuple(int(c) for c in emulator.screen()[job.y, job.x])


def begin(session: Session, x: object, y: object, region: object, frames: object) -> Job:
    """Start a job at pixel (x, y): keep the moment, and the pixel's color a few frames on (emulator thread).

    Raises:
        InvalidArgumentError: The point is off the screen, or the region or frames are wrong.
    """
    emulator = session.search.emulator
    height, width = emulator.screen_shape()
    job = Job(
        next(_IDS),
        session.search,
        integer_of(x, "x", 0, width - 1),
        integer_of(y, "y", 0, height - 1),
        integer_of(frames, "frames", 1, MAX_FRAMES),
        _cells(session, region),
    )
    job.base = emulator.get_state()
    try:
        ram = {a: emulator.space.peek(a) for a in job.addresses}
        job.base_ram = ram
        job.color = _pixel(emulator, job)
    finally:
        emulator.set_state(job.base)
    return job


def work(session: Session, job: Job, seconds: float = CHUNK_SECONDS) -> None:
    """Try cells for about ``seconds``, then put the game back as it was (emulator thread).

    The job's progress changes only once the game is back, so whoever reads it from another thread
    never sees a job finished while its last chunk still holds the emulator.
    """
    if session.search is not job.search:
        job.error = "Expected the game that was clicked; the session plays another one now. Click again."
        return
    emulator = session.search.emulator
    now = emulator.get_state()
    started = time.perf_counter()
    names = _field_names(session)
    done, hits = job.done, []
    try:
        while done < len(job.addresses) and not job.cancelled and time.perf_counter() - started < seconds:
            address = job.addresses[done]
            value = job.base_ram[address]
            changed = []
            for poked in ((value + 1) & 0xFF, value ^ 0xFF):
                emulator.set_state(job.base)
                emulator.poke(address, poked, "|u1")
                color = _pixel(emulator, job)
                if color != job.color:
                    changed.append({"value": poked, "color": list(color)})
            if changed:
                hits.append(
                    {"address": address, "hex": session.search.layout.format(address), "value": value,
                     "fields": names.get(address, []), "pokes": changed}
                )
            done += 1
    finally:
        emulator.set_state(now)
        session.mark_loaded()  # the video buffer holds the last try: a paused page is shown the game's own picture
        job.hits.extend(hits)
        job.done = done
        job.seconds += time.perf_counter() - started


def _field_names(session: Session) -> dict[int, list[str]]:
    """The game's fields over each byte address, so a hit names the variable it is part of."""
    names: dict[int, list[str]] = {}
    for spec in session.search.game.fields.values():
        for address in range(spec.address, spec.address + spec.field_type.width):
            names.setdefault(address, []).append(spec.name)
    return names


async def _run(session: Session, job: Job) -> None:
    """Drive a job to its end a chunk at a time, publishing its progress."""
    try:
        while not job.finished:
            await session.call(work, job)
            session.publish(job.report())
    except RetrokitError as exc:  # e.g. the session closed mid-job: the job ends, and says why
        job.error = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    session.publish(job.report())


async def start(request: Request) -> JSONResponse:
    session = session_of(request)
    body = await json_body(request)
    old = _jobs.get(session)
    if old is not None:
        old.cancelled = True
    job = await session.call(
        begin, body.get("x"), body.get("y"), body.get("region", "candidates"), body.get("frames", FRAMES)
    )
    _jobs[session] = job
    job.task = asyncio.get_running_loop().create_task(_run(session, job))
    return JSONResponse(job.report(), status_code=202)


def _job(request: Request) -> Job:
    job = _jobs.get(session_of(request))
    if job is None:
        raise InvalidArgumentError("Expected a click-to-find job; none was started. Start one: POST /api/clickfind.")
    return job


async def status(request: Request) -> JSONResponse:
    return JSONResponse(_job(request).report())


async def cancel(request: Request) -> JSONResponse:
    job = _job(request)
    job.cancelled = not job.finished or job.cancelled
    return JSONResponse(job.report())


routes = [
    Route("/clickfind", start, methods=["POST"]),
    Route("/clickfind", status, methods=["GET"]),
    Route("/clickfind/cancel", cancel, methods=["POST"]),
]
