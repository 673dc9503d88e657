"""The studio's web application: the routes of every tool under ``/api``, the ``/ws`` socket and the page.

:func:`create_app` builds a Starlette application around one
:class:`~retrokit.studio.session.Session`. Each module named in
:data:`ROUTE_MODULES` exports ``routes`` (a list of Starlette routes), mounted
under ``/api``; a tool adds itself by adding its module's name there. Every
request passes the :class:`~retrokit.studio.security.Guard` first, and every
:class:`~retrokit.errors.RetrokitError` a route raises becomes a JSON error
``{"error": message, "kind": class name}`` with a 4xx status (see
docs/studio-api.md).

The socket sends one binary message per screen (:func:`pack_screen`) and JSON
text messages; the client sends JSON commands (see :mod:`retrokit.studio.play`).
"""

from __future__ import annotations

import asyncio
import contextlib
import importlib
import json
import struct
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import BaseRoute, Mount, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from retrokit import errors
from retrokit.studio.play import handle_message
from retrokit.studio.push import Screen, Subscriber, acknowledges
from retrokit.studio.security import Guard, session_of
from retrokit.studio.session import Session

ROUTE_MODULES: tuple[str, ...] = (
    "play", "states", "authoring", "search", "fields", "scenario", "clickfind", "ramview",
)
"""The modules of :mod:`retrokit.studio` whose ``routes`` are mounted under ``/api``."""

STATIC = Path(__file__).parent / "static"
MESSAGE_PERIOD = 0.05
"""Seconds between two messages of one type on a socket (20 a second at most): the newest one wins."""

SCREEN_HEADER = struct.Struct("<4sHHIB3x")
"""A screen message's header: b"RKS1", width, height, frame number, bytes per pixel (3: RGB), 3 zero bytes."""
SCREEN_MAGIC = b"RKS1"

#: The HTTP status of each kind of error; any other RetrokitError is a 400.
_STATUS: tuple[tuple[type[errors.RetrokitError], int], ...] = (
    (errors.AccessDeniedError, 403),
    (errors.PlantedLinkError, 403),
    (errors.UnknownNameError, 404),
    (errors.FileConflictError, 409),
    (errors.RequestTooLargeError, 413),
)


def pack_screen(screen: Screen) -> bytes:
    """The binary WebSocket message of one screen: :data:`SCREEN_HEADER`, then the rows of RGB pixels."""
    height, width, depth = screen.pixels.shape
    return SCREEN_HEADER.pack(SCREEN_MAGIC, width, height, screen.frame, depth) + screen.pixels.tobytes()


def error_response(exc: BaseException) -> JSONResponse:
    """The JSON error of an exception, with its status."""
    status = next((code for kind, code in _STATUS if isinstance(exc, kind)), 400)
    return JSONResponse({"error": str(exc), "kind": type(exc).__name__}, status_code=status)


def create_app(session: Session, *, token: str, port: int) -> Starlette:
    """The studio's application for ``session``, guarded by ``token`` (the server listens on ``port``).

    The session's thread starts with the first page or request, and the session is closed when the app shuts down.
    """
    routes: list[BaseRoute] = []
    for name in ROUTE_MODULES:
        routes.extend(importlib.import_module(f"retrokit.studio.{name}").routes)

    @contextlib.asynccontextmanager
    async def lifespan(_app: Starlette) -> AsyncIterator[None]:
        # The emulator thread starts with the first page or request, not here: a studio nobody opened stays idle.
        try:
            yield
        finally:
            await asyncio.to_thread(session.close)

    async def retrokit_error(_request: Request, exc: Exception) -> Response:
        return error_response(exc)

    async def http_error(_request: Request, exc: Exception) -> Response:
        assert isinstance(exc, HTTPException)
        return JSONResponse({"error": f"{exc.detail}.", "kind": "HTTPException"}, status_code=exc.status_code)

    app = Starlette(
        routes=[
            Mount("/api", routes=routes),
            WebSocketRoute("/ws", socket),
            Mount("/", StaticFiles(directory=STATIC, html=True), name="static"),
        ],
        exception_handlers={errors.RetrokitError: retrokit_error, HTTPException: http_error},
        lifespan=lifespan,
    )
    app.state.session = session
    app.state.token = token
    app.state.port = port
    app.add_middleware(Guard, token=token, port=port)
    return app


async def socket(websocket: WebSocket) -> None:
    """``/ws``: screens and messages out, commands in, until the page goes."""
    session = session_of(websocket)
    await websocket.accept()
    try:
        acks = acknowledges(websocket.query_params.get("ack"))
    except errors.InvalidArgumentError as exc:  # told, then refused: the same URL would be refused again
        await websocket.send_text(json.dumps({"type": "error", "error": str(exc), "kind": type(exc).__name__}))
        await websocket.close(code=1008)
        return
    subscriber = Subscriber(asyncio.get_running_loop(), acknowledges=acks)
    session.subscribe(subscriber)
    sender = asyncio.create_task(_send(websocket, subscriber))
    try:
        while True:
            text = await websocket.receive_text()
            try:
                message = json.loads(text)
                if isinstance(message, dict) and message.get("type") == "ack":  # the page handled this many
                    subscriber.ack(message.get("received"))
                    continue
                reply = await handle_message(session, message)
            except (errors.RetrokitError, ValueError, RecursionError) as exc:
                kind = type(exc).__name__ if isinstance(exc, errors.RetrokitError) else "InvalidArgumentError"
                text = str(exc) if isinstance(exc, errors.RetrokitError) else f"Expected a JSON message; {exc}."
                subscriber.offer_message({"type": "error", "error": text, "kind": kind})
            else:
                if reply is not None:
                    subscriber.offer_message(reply)
    except (WebSocketDisconnect, RuntimeError, KeyError):  # a closed socket, or a binary message it does not read
        pass
    finally:
        sender.cancel()
        session.unsubscribe(subscriber)


async def _send(websocket: WebSocket, subscriber: Subscriber) -> None:
    """Send what the session offers: the newest screen, and each type's newest message at most 20 times a second."""
    sent_at: dict[str, float] = {}
    loop = asyncio.get_running_loop()
    try:
        while True:
            await subscriber.wait()
            now = loop.time()
            later = []
            for kind, message in list(subscriber.messages.items()):
                if now - sent_at.get(kind, -1.0) < MESSAGE_PERIOD:
                    later.append(kind)
                    continue
                if not subscriber.may_send():  # the page's ack wakes us: by then a newer one may replace it
                    break
                subscriber.messages.pop(kind, None)
                sent_at[kind] = now
                subscriber.sent += 1
                await websocket.send_text(json.dumps(message, default=_plain))
            if subscriber.screen is not None and subscriber.may_send():  # after the messages: the status first
                screen, subscriber.screen = subscriber.screen, None
                subscriber.sent += 1
                await websocket.send_bytes(pack_screen(screen))
            if later:  # come back for them when their period is over
                loop.call_later(MESSAGE_PERIOD, subscriber.wake)
    except (WebSocketDisconnect, RuntimeError, OSError):  # the page went (uvicorn's ClientDisconnected is an OSError)
        pass


def _plain(value: Any) -> Any:
    """JSON for numpy numbers and paths a tool may publish."""
    if hasattr(value, "item"):
        return value.item()
    return str(value)
