"""Validate and New game: ``check_game``'s report as JSON, a game made from a ROM as ``retrokit new`` does, switching games.

Validation runs ``retrokit.testing.check_game`` on a worker thread, never on
the emulator's: it opens emulators of its own, so the session plays on while
it runs, and its progress is published to the page as ``validate`` messages.
New game is ``retrokit.data.newgame.new_game`` (its ROM read by that module's
guarded reader); the session can then switch to the new game, or to any other.
"""

from __future__ import annotations

import asyncio
import threading
from typing import Any

from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from retrokit.errors import AccessDeniedError, FileConflictError, InvalidArgumentError, shown
from retrokit.studio.security import expect, json_body, session_of
from retrokit.studio.session import Session

MAX_VALIDATE_FRAMES = 100_000
_validating = threading.Lock()  # one validation at a time: each one runs emulators of its own


def validate(session: Session, frames: int | None) -> dict[str, Any]:
    """Check the session's game (on the caller's thread); publish progress; return the report as plain data.

    Raises:
        FileConflictError: A validation is already running.
    """
    from retrokit.testing import check_game

    if not _validating.acquire(blocking=False):
        raise FileConflictError(
            "Expected no validation under way; one is running. Wait for its report, then ask again."
        )
    try:
        game = session.search.game

        def progress(stage: str, detail: str) -> None:
            session.publish({"type": "validate", "game": game.name, "stage": stage, "detail": detail})

        report = check_game(game, frames=frames, progress=progress)
    finally:
        _validating.release()
    result = report.to_dict()
    session.publish({"type": "validate", "game": game.name, "stage": "done", "detail": "",
                     "passed": result["passed"], "counts": result["counts"]})
    return result


def open_game(session: Session, game: str, state: str | None) -> dict[str, Any]:
    """Play ``game`` from ``state`` (its default, by default) instead of the session's game (on the thread)."""
    from retrokit.ramsearch import RamSearch
    from retrokit.studio.play import info

    session.replace_search(RamSearch(game, state))
    return info(session)


def _new_game(rom: str, name: str, system: str | None) -> dict[str, Any]:
    from retrokit.data.newgame import new_game

    made = new_game(rom, name, system=system)
    return {"game": made.game.name, "folder": str(made.folder), "rom": str(made.rom), "sha1": made.sha1,
            "told_by": made.told_by}


# --- routes ---------------------------------------------------------------------------------------------


async def validate_route(request: Request) -> Response:
    """``POST /api/validate`` ``{"frames": N}``: the game's check report, as ``retrokit validate --json`` writes it."""
    body = await json_body(request)
    frames = expect(body, "frames", int, None)
    if frames is not None and not 1 <= frames <= MAX_VALIDATE_FRAMES:
        raise InvalidArgumentError(f"Expected 'frames' from 1 to {MAX_VALIDATE_FRAMES:,}, got {frames}.")
    return JSONResponse(await in_daemon(validate, session_of(request), frames))


async def in_daemon(fn: Any, *args: Any) -> Any:
    """``fn(*args)`` on a daemon thread: Ctrl-C ends the studio at once, not after a validation's tens of seconds.

    ``asyncio.to_thread``'s threads are joined when the interpreter exits, so
    the studio waited for the validation to end before it stopped.
    """
    loop = asyncio.get_running_loop()
    future = loop.create_future()

    def settle(result: Any, exc: BaseException | None) -> None:
        if not future.done():
            future.set_exception(exc) if exc is not None else future.set_result(result)

    def run() -> None:
        try:
            result, exc = fn(*args), None
        except BaseException as error:  # noqa: BLE001 - handed to the awaiting request
            result, exc = None, error
        try:
            loop.call_soon_threadsafe(settle, result, exc)
        except RuntimeError:  # the loop closed: the studio is stopping, nobody waits for it
            pass

    threading.Thread(target=run, name="retrokit-studio-job", daemon=True).start()
    return await future


async def new_game_route(request: Request) -> Response:
    """``POST /api/newgame`` ``{"rom": PATH, "name": "Name-System", "system": null, "open": true}``."""
    body = await json_body(request)
    rom, name = expect(body, "rom", str), expect(body, "name", str)
    system = expect(body, "system", str, None)
    if "\0" in rom:
        raise InvalidArgumentError("Expected a ROM path without a NUL character.")
    made = await asyncio.to_thread(_new_game, rom, name, system)
    session = session_of(request)
    if expect(body, "open", bool, True):
        made["info"] = await session.call(open_game, made["game"], None)
    return JSONResponse(made)


async def open_route(request: Request) -> Response:
    """``POST /api/game`` ``{"game": NAME, "state": null}``: play another game."""
    from retrokit.data.names import check_state_name

    body = await json_body(request)
    game, state = expect(body, "game", str), expect(body, "state", str, None)
    if not game or game.startswith(".") or any(c in game for c in "/\\\0"):
        raise AccessDeniedError(
            f"Expected a game's name, such as Dasher-Genesis (retrokit games lists them); got {shown(game)}, "
            "a path. The studio opens games by name only."
        )
    if state is not None:
        check_state_name(state)
    return JSONResponse(await session_of(request).call(open_game, game, state))


routes = [
    Route("/validate", validate_route, methods=["POST"]),
    Route("/newgame", new_game_route, methods=["POST"]),
    Route("/game", open_route, methods=["POST"]),
]
